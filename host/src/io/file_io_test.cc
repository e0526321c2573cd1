#include "tessera/io/file_io.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <fstream>
#include <thread>
#include <vector>

#include "temporary_names.h"
#include "tessera/errors.h"
#include "tessera/io/image_io.h"
#include "test_support.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

size_t NumEntries(const fs::path& dir) {
  return static_cast<size_t>(std::distance(fs::directory_iterator(dir), fs::directory_iterator()));
}

TEST(WriteFileAtomically, WritesAndReplacesLeavingNoTemporaryFile) {
  testing::TemporaryDir dir;
  const fs::path path = dir.path() / "model.bin";
  WriteFileAtomically(path, std::string("a\0b", 3));
  EXPECT_EQ(ReadFileContents(path), std::string("a\0b", 3));
  WriteFileAtomically(path, "longer contents");
  EXPECT_EQ(ReadFileContents(path), "longer contents");
  WriteFileAtomically(path, "");
  EXPECT_EQ(fs::file_size(path), 0u);
  EXPECT_EQ(NumEntries(dir.path()), 1u);
}

// Issue 60 item 2: the temporary was .NAME.tmp-PID, one name for every thread of a
// process, and each write unlinked it first: two threads writing one file took each
// other's temporary away ("Cannot rename"), or renamed the other's half-written one.
TEST(WriteFileAtomically, ThreadsWritingOneFileEachUseTheirOwnTemporary) {
  testing::TemporaryDir dir;
  const fs::path path = dir.path() / "shared.json";
  constexpr int kThreads = 8;
  constexpr int kWrites = 200;
  std::atomic<int> failures{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      // Each thread's contents are long and of its own: a mix or a cut shows.
      const std::string contents(64 * 1024, static_cast<char>('a' + t));
      for (int k = 0; k < kWrites; ++k) {
        try {
          WriteFileAtomically(path, contents);
          WriteFileAtomically(dir.path() / ("own-" + std::to_string(t)), contents);
        } catch (const InputError&) {
          ++failures;
        }
      }
    });
  }
  for (std::thread& thread : threads) thread.join();
  EXPECT_EQ(failures.load(), 0);
  const std::string contents = ReadFileContents(path);
  ASSERT_EQ(contents.size(), 64u * 1024);
  EXPECT_EQ(contents, std::string(contents.size(), contents[0]));
  EXPECT_EQ(NumEntries(dir.path()), 1u + kThreads);  // no temporary left
}

// The temporary's name carries Tessera's token, the process and a random part, new for
// every write; names a user gives files are never read as one.
TEST(TemporaryFileNames, CarryTheTokenAndAreReadBackOnlyWhenExact) {
  const std::string first = NewTemporaryFileName("images.bin");
  const std::string second = NewTemporaryFileName("images.bin");
  EXPECT_NE(first, second);
  const std::string prefix = ".images.bin.tessera-tmp-" + std::to_string(getpid()) + "-";
  EXPECT_EQ(first.rfind(prefix, 0), 0u) << first;
  EXPECT_EQ(first.size(), prefix.size() + 16) << first;
  const auto parsed = ParseTemporaryFileName(first);
  ASSERT_TRUE(parsed.has_value()) << first;
  EXPECT_EQ(parsed->target, "images.bin");
  EXPECT_EQ(parsed->pid, static_cast<long>(getpid()));
  for (const char* name :
       {".notes.tmp-999999", ".draft.tmp-999998", "notes.tessera-tmp-1-0123456789abcdef",
        ".tessera-tmp-1-0123456789abcdef", ".a.tessera-tmp-1-0123456789abcde",
        ".a.tessera-tmp-1-0123456789abcdeF", ".a.tessera-tmp-1-0123456789abcdef0",
        ".a.tessera-tmp--0123456789abcdef", ".a.tessera-tmp-01-0123456789abcdef",
        ".a.tessera-tmp-x-0123456789abcdef", ".a.tessera-tmp-1234567890-0123456789abcdef"}) {
    EXPECT_FALSE(ParseTemporaryFileName(name).has_value()) << name;
  }
  EXPECT_TRUE(ParseTemporaryFileName(".a.tessera-tmp-1-0123456789abcdef").has_value());
}

TEST(WriteFileAtomically, MissingFolderIsAnInputErrorNamingTheFile) {
  testing::TemporaryDir dir;
  const fs::path path = dir.path() / "no_such_folder" / "points3D.ply";
  try {
    WriteFileAtomically(path, "x");
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find(path.string()), std::string::npos) << error.what();
  }
  EXPECT_EQ(NumEntries(dir.path()), 0u);
}

TEST(ReadFileContents, ReadsBytesAndNamesAFileItCannotOpen) {
  testing::TemporaryDir dir;
  WriteFileAtomically(dir.path() / "a", std::string("\0\xff\n", 3));
  EXPECT_EQ(ReadFileContents(dir.path() / "a"), std::string("\0\xff\n", 3));
  try {
    ReadFileContents(dir.path() / "b");
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()), "Cannot open " + (dir.path() / "b").string() + ".");
  }
}

// Issue 52 item 1: a folder where a file was expected (a path typed into the GUI's
// Manifest field) was the library's "basic_filebuf::underflow error reading the file:
// Is a directory", which closed the window; it is an InputError naming the folder.
TEST(ReadFileContents, AFolderIsAnInputErrorNamingIt) {
  testing::TemporaryDir dir;
  try {
    ReadFileContents(dir.path());
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()), dir.path().string() + " is a folder, not a file.");
  }
  EXPECT_FALSE(ReadFileBytes(dir.path()).has_value());
  WriteFileAtomically(dir.path() / "a", "abc");
  ASSERT_TRUE(ReadFileBytes(dir.path() / "a").has_value());
  EXPECT_EQ(ReadFileBytes(dir.path() / "a")->size(), 3u);
}

TEST(CreateFolder, CreatesParentsAndNamesAFolderItCannotCreate) {
  testing::TemporaryDir dir;
  CreateFolder(dir.path() / "a" / "b" / "c");
  EXPECT_TRUE(fs::is_directory(dir.path() / "a" / "b" / "c"));
  CreateFolder(dir.path() / "a");  // already there
  std::ofstream(dir.path() / "file") << "x";
  try {
    CreateFolder(dir.path() / "file" / "sub");
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what())
                  .find("Cannot create the folder " + (dir.path() / "file" / "sub").string()),
              std::string::npos)
        << error.what();
  }
}

}  // namespace
}  // namespace tessera
