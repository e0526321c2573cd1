#include <gtest/gtest.h>

#include <string>

#include "bench/colmap_rows.h"

namespace tessera {
namespace {

TEST(ParseColmapVersion, ReadsTheVersionsCOLMAPPrints) {
  const auto v38 =
      ParseColmapVersion("COLMAP 3.8 -- Structure-from-Motion and Multi-View Stereo\n");
  ASSERT_TRUE(v38.has_value());
  EXPECT_EQ(v38->text, "3.8");
  EXPECT_EQ(v38->major, 3);
  EXPECT_EQ(v38->minor, 8);
  const auto v4 = ParseColmapVersion("\n  COLMAP 4.2.0.dev0 (Commit abc on 2025-01-01)\n");
  ASSERT_TRUE(v4.has_value());
  EXPECT_EQ(v4->text, "4.2.0.dev0");
  EXPECT_EQ(v4->major, 4);
  EXPECT_EQ(v4->minor, 2);
  // The first "COLMAP <digits>.<digits>": a word COLMAP without a version is passed over.
  const auto later = ParseColmapVersion("Usage of COLMAP commands\nCOLMAP 3.9.1\n");
  ASSERT_TRUE(later.has_value());
  EXPECT_EQ(later->text, "3.9.1");
  EXPECT_FALSE(ParseColmapVersion("hello\n").has_value());
  EXPECT_FALSE(ParseColmapVersion("COLMAP x.y\n").has_value());
  EXPECT_FALSE(ParseColmapVersion("COLMAP 3\n").has_value());
  EXPECT_FALSE(ParseColmapVersion("").has_value());
}

// std::regex ran out of stack on this line (issue 60): read by hand, kept short.
TEST(ParseColmapVersion, ALongVersionLineIsReadAndCut) {
  const std::string line = "COLMAP 3.8" + std::string(30000, 'x') + "\n";
  const auto version = ParseColmapVersion(line);
  ASSERT_TRUE(version.has_value());
  EXPECT_EQ(version->major, 3);
  EXPECT_LT(version->text.size(), 100u);
  EXPECT_EQ(version->text.rfind("3.8xxx", 0), 0u);
  const std::string spaces = "COLMAP " + std::string(1000000, ' ') + "3.8\n";
  EXPECT_FALSE(ParseColmapVersion(spaces).has_value());
}

// A version is never a path: its label is one file name, unique among the bench's rows.
TEST(AssignColmapLabels, LabelsAreFileNamesAndUnique) {
  std::vector<ColmapBinary> binaries(3);
  binaries[0].version = *ParseColmapVersion("COLMAP 3.8/../../outside/pwn\n");
  binaries[1].version = *ParseColmapVersion("COLMAP 3.8\n");
  binaries[2].version = *ParseColmapVersion("COLMAP 3.8\n");
  binaries[2].has_global_mapper = true;
  AssignColmapLabels(&binaries, {"colmap-3.8-incremental"});
  EXPECT_EQ(binaries[0].label, "colmap-3.8_.._.._outside_pwn");
  EXPECT_EQ(binaries[1].label, "colmap-3.8-2");
  EXPECT_EQ(binaries[2].label, "colmap-3.8-3");
  EXPECT_EQ(ColmapRowNames(binaries[2]),
            (std::vector<std::string>{"colmap-3.8-3-global", "colmap-3.8-3-incremental"}));
}

}  // namespace
}  // namespace tessera
