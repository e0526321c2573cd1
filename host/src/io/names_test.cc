#include "names.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "tessera/errors.h"
#include "test_support.h"

namespace tessera {
namespace {

TEST(ImageNames, FineNamesPass) {
  for (const std::string name : {"a.jpg", "sub/dir/a.jpg", "a b.jpg", "..a.jpg", "a../b.jpg",
                                 "./a.jpg", "caf\xc3\xa9.jpg"}) {
    EXPECT_EQ(ImageNameProblem(name), "") << name;
    EXPECT_NO_THROW(CheckImageName(name, "m/images.bin: image 1"));
  }
}

TEST(ImageNames, EachProblemIsNamed) {
  using namespace std::string_literals;
  const std::pair<std::string, std::string> cases[] = {
      {"", "is empty"},
      {"/etc/passwd", "is an absolute path"},
      {"../x.jpg", "has a '..' component"},
      {"a/../../x.jpg", "has a '..' component"},
      {"a/..", "has a '..' component"},
      {"..", "has a '..' component"},
      {"a\nb.jpg", "contains a line break"},
      {"a\rb.jpg", "contains a line break"},
      {"a\tb.jpg", "contains the control character \\t"},
      {"a\x1b[2Jb.jpg", "contains the control character \\x1b"},
      {"a\x7f.jpg", "contains the control character \\x7f"},
      {"a\0b.jpg"s, "contains the control character \\0"},
  };
  for (const auto& [name, problem] : cases) {
    EXPECT_NE(ImageNameProblem(name).find(problem), std::string::npos)
        << EscapeControlCharacters(name) << ": " << ImageNameProblem(name);
  }
}

TEST(ImageNames, CheckThrowsOneLineNamingWhereAndName) {
  try {
    CheckImageName("x\ny/../../z.jpg", "db.db: image 7");
    FAIL() << "no throw";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()),
              "db.db: image 7: the image name 'x\\ny/../../z.jpg' has a '..' component, which "
              "leads out of the image folder.");
  }
}

TEST(ImageNames, EscapesEveryControlCharacter) {
  using namespace std::string_literals;
  EXPECT_EQ(EscapeControlCharacters("a\n\r\t\0\x01\x7f z"s), "a\\n\\r\\t\\0\\x01\\x7f z");
  EXPECT_EQ(EscapeControlCharacters("plain 'text' $x"), "plain 'text' $x");
  EXPECT_TRUE(HasControlCharacter("a\nb"));
  EXPECT_TRUE(HasControlCharacter("a\0b"s));
  EXPECT_FALSE(HasControlCharacter("a b$`'\"\\"));
}

TEST(ReadBackPaths, OnlyRelativeNormalPathsPass) {
  using namespace std::string_literals;
  for (const std::string path : {"model.ply", "sparse/0/images.bin", "..a", "a../b", "a b"}) {
    EXPECT_EQ(RelativePathProblem(path), "") << path;
  }
  const std::pair<std::string, std::string> cases[] = {
      {"", "is empty"},
      {"/etc/passwd", "is an absolute path"},
      {"../victim.txt", "has a '..' component"},
      {"sparse/0/../../../x", "has a '..' component"},
      {"./a", "not in normal form"},
      {"a//b", "not in normal form"},
      {"sparse/", "not in normal form"},
      {"a/./b", "not in normal form"},
      {"..\\victim.txt", "has a backslash"},
      {"a\nb", "control character \\n"},
      {"a\0b"s, "control character \\0"},
  };
  for (const auto& [path, problem] : cases) {
    EXPECT_NE(RelativePathProblem(path).find(problem), std::string::npos)
        << EscapeControlCharacters(path) << ": " << RelativePathProblem(path);
  }
}

TEST(ReadBackPaths, ALinkOnTheWayIsFoundAndRefused) {
  const testing::TemporaryDir dir;
  std::filesystem::create_directories(dir.path() / "elsewhere/0");
  std::filesystem::create_directories(dir.path() / "out/real/0");
  std::filesystem::create_directory_symlink(dir.path() / "elsewhere", dir.path() / "out/sparse");
  const std::filesystem::path out = dir.path() / "out";
  EXPECT_EQ(LinkOnTheWay(out, "sparse/0/images.bin"), out / "sparse");
  EXPECT_EQ(LinkOnTheWay(out, "real/0/images.bin"), std::filesystem::path());
  EXPECT_EQ(LinkOnTheWay(out, "sparse"), std::filesystem::path());  // the entry itself
  try {
    CheckPathBelow(out, "sparse/0/images.bin", "L.json");
    FAIL() << "no error";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what())
                  .rfind("L.json: the path 'sparse/0/images.bin' lies through " +
                             (out / "sparse").string() + ", a symbolic link",
                         0),
              0u)
        << error.what();
  }
  EXPECT_THROW(CheckPathBelow(out, "../x", "L.json"), InputError);
  EXPECT_NO_THROW(CheckPathBelow(out, "real/0/images.bin", "L.json"));
}

}  // namespace
}  // namespace tessera
