#include "tessera/io/file_io.h"

#include <gtest/gtest.h>

#include <fstream>

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
