// The window's one checked read (checked_read.h): what a user can type into a path field
// is a message, never an exception out of a frame.

#include "gui/checked_read.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <fstream>
#include <ios>

#include "test_support.h"

namespace tessera::gui {
namespace {
namespace fs = std::filesystem;

TEST(CheckedRead, AFolderIsAMessageNamingIt) {
  tessera::testing::TemporaryDir dir;
  std::string error;
  EXPECT_FALSE(ReadTextFile(dir.path(), "the manifest", &error).has_value());
  EXPECT_EQ(error, dir.path().string() + ": the manifest is a folder, not a file");
  EXPECT_FALSE(ReadTextFile("/", "the manifest", &error).has_value());
  EXPECT_EQ(error, "/: the manifest is a folder, not a file");
}

TEST(CheckedRead, MissingFilePipeAndTooLargeAreMessages) {
  tessera::testing::TemporaryDir dir;
  std::string error;
  EXPECT_FALSE(ReadTextFile(dir.path() / "none.json", "the manifest", &error).has_value());
  EXPECT_EQ(error, (dir.path() / "none.json").string() + ": no such file (the manifest)");
  // A pipe would block the window on open: refused before it is opened.
  const fs::path fifo = dir.path() / "fifo";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_FALSE(ReadTextFile(fifo, "the manifest", &error).has_value());
  EXPECT_EQ(error, fifo.string() + ": the manifest is not a regular file (a device or a pipe)");
  const fs::path large = dir.path() / "large.json";
  std::ofstream(large) << std::string(100, 'x');
  EXPECT_FALSE(ReadTextFile(large, "the manifest", &error, 99).has_value());
  EXPECT_EQ(error, large.string() + ": the manifest is too large (100 bytes; at most 99)");
  const std::optional<std::string> text = ReadTextFile(large, "the manifest", &error, 100);
  ASSERT_TRUE(text.has_value()) << error;
  EXPECT_EQ(*text, std::string(100, 'x'));
}

TEST(CheckedRead, WhatAReaderThrowsIsAMessageNamingTheFile) {
  std::string error;
  // The exception libstdc++ throws when a stream reads a folder (issue 52's crash).
  EXPECT_FALSE(CheckedRead(
      "/some/folder",
      [] { throw std::ios_base::failure("basic_filebuf::underflow error reading the file"); },
      &error));
  EXPECT_EQ(error.rfind("/some/folder: basic_filebuf::underflow", 0), 0u) << error;
  EXPECT_FALSE(CheckedRead(
      "/x", [] { throw 7; }, &error));
  EXPECT_EQ(error, "/x: cannot be read");
  error.clear();
  EXPECT_TRUE(CheckedRead(
      "/x", [] {}, &error));
  EXPECT_EQ(error, "");
}

}  // namespace
}  // namespace tessera::gui
