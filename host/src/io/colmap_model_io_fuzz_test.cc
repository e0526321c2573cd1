// Fuzz-style tests of the COLMAP model reader on a small model: every truncation, every
// single-byte change and many random changes of each file must either read or throw
// InputError, never crash, hang, throw anything else or allocate more than the files
// could justify. This executable counts allocations through its own operator new.

#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "small_colmap_model.h"
#include "tessera/errors.h"
#include "tessera/io/colmap_model_io.h"
#include "tessera/io/file_io.h"
#include "test_support.h"

namespace {
std::atomic<size_t> largest_allocation{0};
}  // namespace

// Kept out of line: inlined, GCC would pair `new` expressions with the free() inside and
// warn of a mismatch (-Wmismatched-new-delete).
__attribute__((noinline)) void* operator new(size_t size) {
  size_t largest = largest_allocation.load(std::memory_order_relaxed);
  while (size > largest && !largest_allocation.compare_exchange_weak(largest, size)) {
  }
  if (void* memory = std::malloc(size > 0 ? size : 1)) return memory;
  throw std::bad_alloc();
}
__attribute__((noinline)) void operator delete(void* memory) noexcept { std::free(memory); }
__attribute__((noinline)) void operator delete(void* memory, size_t) noexcept { std::free(memory); }

namespace tessera {
namespace {

namespace fs = std::filesystem;

// Far above what a model of a few kilobytes needs, far below what a corrupt count
// (up to 2^64 records) would ask for.
constexpr size_t kMaxAllocationBytes = size_t{1} << 20;

// A model folder whose files the test rewrites one at a time.
class CorruptModel {
 public:
  explicit CorruptModel(ColmapModelFormat format)
      : extension_(format == ColmapModelFormat::kBinary ? ".bin" : ".txt") {
    WriteColmapModel(testing::SmallColmapModel(), dir_.path(), format);
  }
  fs::path File(const std::string& name) const { return dir_.path() / (name + extension_); }

  // Reads the model with `name` holding `bytes`; fails the test on anything but success
  // or InputError, or on a large allocation. Returns whether the reader refused it.
  bool Refuses(const std::string& name, const std::string& bytes, const std::string& what) {
    WriteFileAtomically(File(name), bytes);
    largest_allocation = 0;
    bool refused = false;
    try {
      ReadColmapModel(dir_.path());
    } catch (const InputError&) {
      refused = true;
    } catch (const std::exception& error) {
      ADD_FAILURE() << name << extension_ << " " << what << ": " << error.what();
    }
    EXPECT_LE(largest_allocation.load(), kMaxAllocationBytes) << name << extension_ << " " << what;
    return refused;
  }

 private:
  testing::TemporaryDir dir_;
  std::string extension_;
};

const std::vector<std::string>& FileNames() {
  static const std::vector<std::string> names = {"cameras", "images", "points3D"};
  return names;
}

TEST(ColmapModelFuzz, EveryTruncationOfEachFileIsRefused) {
  for (const auto format : {ColmapModelFormat::kBinary, ColmapModelFormat::kText}) {
    CorruptModel model(format);
    for (const std::string& name : FileNames()) {
      const std::string bytes = ReadFileContents(model.File(name));
      ASSERT_GT(bytes.size(), 20u);
      int refused = 0;
      for (size_t length = 0; length < bytes.size(); ++length) {
        refused += model.Refuses(name, bytes.substr(0, length), "cut to " + std::to_string(length));
      }
      EXPECT_FALSE(model.Refuses(name, bytes, "restored"));
      EXPECT_GT(largest_allocation.load(), 0u) << "operator new is not counting";
      if (format == ColmapModelFormat::kBinary) {
        // A binary file is a count and fixed records: every cut is seen.
        EXPECT_EQ(refused, static_cast<int>(bytes.size())) << name;
      } else {
        // A text file cut at a line end is a shorter valid file (or dangling references).
        EXPECT_GT(refused, 0) << name;
      }
    }
  }
}

// Every byte set to 0x00, 0x7f and 0xff and inverted, one at a time: each change reads
// or is refused with InputError (Refuses fails the test on anything else). A binary
// file's leading record count is checked against the records that follow, so every
// change of it is refused; changes of coordinates and comments read.
TEST(ColmapModelFuzz, EverySingleByteChangeReadsOrIsRefused) {
  for (const auto format : {ColmapModelFormat::kBinary, ColmapModelFormat::kText}) {
    CorruptModel model(format);
    for (const std::string& name : FileNames()) {
      const std::string bytes = ReadFileContents(model.File(name));
      int num_changes = 0, num_refused = 0, num_count_changes = 0, num_count_refused = 0;
      for (size_t offset = 0; offset < bytes.size(); ++offset) {
        std::vector<std::pair<char, std::string>> changes;
        for (const unsigned char value : {0x00, 0x7f, 0xff}) {
          changes.emplace_back(static_cast<char>(value), "= " + std::to_string(value));
        }
        changes.emplace_back(static_cast<char>(~bytes[offset]), "inverted");
        for (const auto& [value, what] : changes) {
          if (value == bytes[offset]) continue;  // no change
          std::string corrupt = bytes;
          corrupt[offset] = value;
          const bool refused =
              model.Refuses(name, corrupt, "byte " + std::to_string(offset) + " " + what);
          ++num_changes;
          num_refused += refused;
          if (format == ColmapModelFormat::kBinary && offset < sizeof(uint64_t)) {
            ++num_count_changes;
            num_count_refused += refused;
          }
        }
      }
      const std::string file = model.File(name).filename().string();
      EXPECT_FALSE(model.Refuses(name, bytes, "restored")) << file;
      EXPECT_GT(num_refused, 0) << file;
      EXPECT_LT(num_refused, num_changes) << file << ": no change read";
      if (format == ColmapModelFormat::kBinary) {
        EXPECT_GE(num_count_changes, 3 * static_cast<int>(sizeof(uint64_t))) << file;
        EXPECT_EQ(num_count_refused, num_count_changes) << file;
      }
    }
  }
}

// Up to eight random bytes changed, and one file in four cut short as well: counts,
// ids, lengths and number syntax all get hit, most of them in a way that is refused.
TEST(ColmapModelFuzz, RandomCorruptionOfEveryFile) {
  std::mt19937 rng(2024);
  int num_refused = 0, num_cases = 0;
  for (const auto format : {ColmapModelFormat::kBinary, ColmapModelFormat::kText}) {
    CorruptModel model(format);
    for (const std::string& name : FileNames()) {
      const std::string bytes = ReadFileContents(model.File(name));
      for (int trial = 0; trial < 300; ++trial) {
        std::string corrupt = bytes;
        const int num_changes = 1 + static_cast<int>(rng() % 8);
        for (int k = 0; k < num_changes; ++k) {
          corrupt[rng() % corrupt.size()] = static_cast<char>(rng() % 256);
        }
        if (rng() % 4 == 0) corrupt.resize(rng() % corrupt.size());
        num_refused += model.Refuses(name, corrupt, "trial " + std::to_string(trial));
        ++num_cases;
      }
      model.Refuses(name, bytes, "restored");
    }
  }
  EXPECT_EQ(num_cases, 1800);
  EXPECT_GT(num_refused, 900);
}

}  // namespace
}  // namespace tessera
