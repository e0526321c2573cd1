#include "temporary_names.h"

#include <sys/random.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <thread>

namespace tessera {
namespace {

constexpr size_t kRandomDigits = 16;

uint64_t SplitMix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

// 64 random bits; without the kernel's, a mix of a process-wide counter, the clock and
// the thread (distinct per call in this process either way).
uint64_t RandomBits() {
  static std::atomic<uint64_t> counter{0};
  const uint64_t count = counter.fetch_add(1);
  uint64_t bits = 0;
  if (getrandom(&bits, sizeof(bits), GRND_NONBLOCK) == static_cast<ssize_t>(sizeof(bits))) {
    return bits;
  }
  const uint64_t now =
      static_cast<uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count());
  const uint64_t thread = std::hash<std::thread::id>()(std::this_thread::get_id());
  return SplitMix64(now ^ SplitMix64(thread) ^ SplitMix64(count));
}

bool AllOf(std::string_view text, std::string_view characters) {
  return !text.empty() && text.find_first_not_of(characters) == std::string_view::npos;
}

}  // namespace

std::string NewTemporaryFileName(const std::string& name) {
  char random[kRandomDigits + 1];
  std::snprintf(random, sizeof(random), "%016llx", static_cast<unsigned long long>(RandomBits()));
  return "." + name + std::string(kTemporaryToken) + std::to_string(static_cast<long>(getpid())) +
         "-" + random;
}

std::optional<TemporaryFileName> ParseTemporaryFileName(std::string_view name) {
  const size_t token = name.rfind(kTemporaryToken);
  if (name.size() < 2 || name[0] != '.' || token == std::string_view::npos || token < 2) {
    return std::nullopt;
  }
  const std::string_view rest = name.substr(token + kTemporaryToken.size());
  const size_t dash = rest.find('-');
  if (dash == std::string_view::npos) return std::nullopt;
  const std::string_view pid = rest.substr(0, dash);
  const std::string_view random = rest.substr(dash + 1);
  if (!AllOf(pid, "0123456789") || pid.size() > 9 || pid[0] == '0' ||
      random.size() != kRandomDigits || !AllOf(random, "0123456789abcdef")) {
    return std::nullopt;
  }
  TemporaryFileName parsed;
  parsed.target = std::string(name.substr(1, token - 1));
  parsed.pid = std::stol(std::string(pid));
  return parsed;
}

}  // namespace tessera
