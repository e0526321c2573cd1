#pragma once

// FLANN indexes kept on disk, so that the processes of one workspace (the extraction
// and matching shards of a Slurm run, a later run) build each image's index once.
//
// A file holds one index, saved by FLANN, behind a header:
//   "TESSERA-FLANN-IDX\n" (18 bytes), the payload's size (8 bytes, little endian) and
//   its XXH3-128 hash (16 bytes), then the payload.
// It is named by a hash of the descriptors it indexes and of everything the index was
// built with (`build`: index type, parameters, seed, FLANN version, distance kernel), so
// that no file is ever used for other descriptors or other options. A file that is
// missing, truncated, corrupt or of another shape is not used: the caller builds the
// index and writes the file again. Files are written under a temporary name and renamed,
// so that readers in other processes never see half a file.

#include <unistd.h>
#include <xxhash.h>

#include <atomic>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include "tessera/features.h"

namespace tessera::flann_index_files {

// The key of an image's descriptors: XXH3-128 over their shape, metric and bytes.
struct DescriptorsKey {
  uint64_t low = 0;
  uint64_t high = 0;
  bool operator==(const DescriptorsKey& other) const {
    return low == other.low && high == other.high;
  }
  bool operator!=(const DescriptorsKey& other) const { return !(*this == other); }
};

inline DescriptorsKey KeyOf(const FeatureDescriptors& descriptors) {
  const int64_t shape[3] = {static_cast<int64_t>(descriptors.size()),
                            static_cast<int64_t>(descriptors.dimension()),
                            static_cast<int64_t>(descriptors.metric)};
  XXH3_state_t* state = XXH3_createState();
  if (state == nullptr) throw std::bad_alloc();
  XXH3_128bits_reset(state);
  XXH3_128bits_update(state, shape, sizeof(shape));
  XXH3_128bits_update(state, descriptors.data.data(), static_cast<size_t>(descriptors.data.size()));
  const XXH128_hash_t hash = XXH3_128bits_digest(state);
  XXH3_freeState(state);
  return {hash.low64, hash.high64};
}

class IndexFiles {
 public:
  static constexpr char kMagic[] = "TESSERA-FLANN-IDX\n";
  static constexpr size_t kMagicSize = sizeof(kMagic) - 1;
  static constexpr size_t kHeaderSize = kMagicSize + 8 + 16;

  IndexFiles() = default;  // no folder: nothing is kept
  IndexFiles(std::filesystem::path folder, std::string build)
      : folder_(std::move(folder)), build_(std::move(build)) {}

  bool enabled() const { return !folder_.empty(); }

  // FOLDER/<32 hex digits>.flann
  std::filesystem::path FileOf(const DescriptorsKey& key) const {
    XXH3_state_t* state = XXH3_createState();
    if (state == nullptr) throw std::bad_alloc();
    XXH3_128bits_reset(state);
    XXH3_128bits_update(state, build_.data(), build_.size());
    XXH3_128bits_update(state, &key.low, sizeof(key.low));
    XXH3_128bits_update(state, &key.high, sizeof(key.high));
    const XXH128_hash_t hash = XXH3_128bits_digest(state);
    XXH3_freeState(state);
    char name[40];
    std::snprintf(name, sizeof(name), "%016llx%016llx.flann",
                  static_cast<unsigned long long>(hash.high64),
                  static_cast<unsigned long long>(hash.low64));
    return folder_ / name;
  }

  bool Exists(const DescriptorsKey& key) const {
    std::error_code error;
    return std::filesystem::is_regular_file(FileOf(key), error);
  }

  // Loads the file of `key` into `index` (made over the same descriptors, not built);
  // false, leaving `index` to be built, when there is no usable file.
  template <typename Index>
  bool Load(const DescriptorsKey& key, Index* index) const {
    const std::vector<char> payload = ReadPayload(FileOf(key));
    if (payload.empty()) return false;
    FILE* stream = fmemopen(const_cast<char*>(payload.data()), payload.size(), "rb");
    if (stream == nullptr) return false;
    bool loaded = false;
    try {
      index->loadIndex(stream);  // checks the index type and the number of descriptors
      loaded = true;
    } catch (const std::exception&) {
      loaded = false;
    }
    std::fclose(stream);
    return loaded;
  }

  // Writes the index of `key`. Throws std::runtime_error naming the file when it cannot.
  template <typename Index>
  void Save(const DescriptorsKey& key, Index& index) const {
    char* buffer = nullptr;
    size_t size = 0;
    FILE* stream = open_memstream(&buffer, &size);
    if (stream == nullptr) throw std::bad_alloc();
    try {
      index.saveIndex(stream);
    } catch (...) {
      std::fclose(stream);
      std::free(buffer);
      throw;
    }
    std::fclose(stream);
    const std::unique_ptr<char, decltype(&std::free)> payload(buffer, &std::free);
    const std::filesystem::path file = FileOf(key);
    std::error_code error;
    std::filesystem::create_directories(folder_, error);
    // Unique among the threads, processes and hosts that may write it at once.
    static std::atomic<uint64_t> counter{0};
    char host[256] = {};
    ::gethostname(host, sizeof(host) - 1);
    std::ostringstream suffix;
    suffix << ".tmp-" << host << '-' << ::getpid() << '-' << counter++;
    const std::filesystem::path temporary = file.string() + suffix.str();
    {
      std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
      const XXH128_hash_t hash = XXH3_128bits(payload.get(), size);
      char header[kHeaderSize];
      std::memcpy(header, kMagic, kMagicSize);
      PutLittleEndian(static_cast<uint64_t>(size), header + kMagicSize);
      PutLittleEndian(hash.low64, header + kMagicSize + 8);
      PutLittleEndian(hash.high64, header + kMagicSize + 16);
      out.write(header, static_cast<std::streamsize>(kHeaderSize));
      out.write(payload.get(), static_cast<std::streamsize>(size));
      out.close();
      if (!out) {
        const std::string reason = std::strerror(errno);
        std::filesystem::remove(temporary, error);
        throw std::runtime_error(file.string() + ": cannot write a search index (" + reason + ")");
      }
    }
    std::filesystem::rename(temporary, file, error);
    if (error) {
      std::filesystem::remove(temporary, error);
      throw std::runtime_error(file.string() + ": cannot write a search index (" + error.message() +
                               ")");
    }
  }

 private:
  static void PutLittleEndian(uint64_t value, char* out) {
    for (int b = 0; b < 8; ++b) out[b] = static_cast<char>((value >> (8 * b)) & 0xff);
  }
  static uint64_t GetLittleEndian(const char* in) {
    uint64_t value = 0;
    for (int b = 7; b >= 0; --b) value = (value << 8) | static_cast<unsigned char>(in[b]);
    return value;
  }

  // The checked payload of `file`; empty when it is missing or not whole.
  static std::vector<char> ReadPayload(const std::filesystem::path& file) {
    std::ifstream in(file, std::ios::binary);
    if (!in) return {};
    char header[kHeaderSize];
    if (!in.read(header, static_cast<std::streamsize>(kHeaderSize)) ||
        std::memcmp(header, kMagic, kMagicSize) != 0) {
      return {};
    }
    const uint64_t size = GetLittleEndian(header + kMagicSize);
    std::error_code error;
    const uintmax_t file_size = std::filesystem::file_size(file, error);
    if (error || file_size != kHeaderSize + size || size == 0) return {};
    std::vector<char> payload(static_cast<size_t>(size));
    if (!in.read(payload.data(), static_cast<std::streamsize>(size))) return {};
    const XXH128_hash_t hash = XXH3_128bits(payload.data(), payload.size());
    if (hash.low64 != GetLittleEndian(header + kMagicSize + 8) ||
        hash.high64 != GetLittleEndian(header + kMagicSize + 16)) {
      return {};
    }
    return payload;
  }

  std::filesystem::path folder_;
  std::string build_;
};

}  // namespace tessera::flann_index_files
