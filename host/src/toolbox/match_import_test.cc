#include "toolbox/match_import.h"

#include <gtest/gtest.h>

#include <string>

#include "test_support.h"
#include "toolbox/import_test_support.h"

namespace tessera {
namespace {

using testing::ExpectInputError;
using testing::WriteText;

TEST(ParsePairsFile, ReadsOnePairPerLine) {
  const testing::TemporaryDir dir;
  const auto file = dir.path() / "pairs.txt";
  WriteText(file, "# from retrieval\na.jpg b.jpg\n\n  b.jpg\tc.jpg \n");
  const std::vector<ImportedPair> pairs = ParsePairsFile(file);
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_EQ(pairs[1].name1, "b.jpg");
  EXPECT_EQ(pairs[1].name2, "c.jpg");
  EXPECT_EQ(pairs[1].where, file.string() + ":4");
  EXPECT_TRUE(pairs[0].matches.empty());
  WriteText(file, "a.jpg b.jpg\na.jpg b.jpg c.jpg\n");
  ExpectInputError([&] { ParsePairsFile(file); },
                   file.string() + ":2: 3 values; a line of a pairs file is `name1 name2`");
  WriteText(file, "\n# nothing\n");
  ExpectInputError([&] { ParsePairsFile(file); }, file.string() + ": no image pairs in the file");
  ExpectInputError([&] { ParsePairsFile(dir.path() / "none.txt"); }, "none.txt: cannot be read");
}

TEST(ParseRawMatchesFile, ReadsBlocksSeparatedByBlankLines) {
  const testing::TemporaryDir dir;
  const auto file = dir.path() / "matches.txt";
  WriteText(file, "a.jpg b.jpg\n0 1\n2 3\n\nb.jpg c.jpg\n\na.jpg c.jpg\n5 4\n");
  const std::vector<ImportedPair> pairs = ParseRawMatchesFile(file);
  ASSERT_EQ(pairs.size(), 3u);
  EXPECT_EQ(pairs[0].matches, (FeatureMatches{{0, 1}, {2, 3}}));
  EXPECT_EQ(pairs[0].match_lines, (std::vector<size_t>{2, 3}));
  EXPECT_TRUE(pairs[1].matches.empty());
  EXPECT_EQ(pairs[2].where, file.string() + ":7");
  EXPECT_EQ(pairs[2].matches, (FeatureMatches{{5, 4}}));

  const std::vector<std::pair<std::string, std::string>> cases = {
      {"a.jpg b.jpg\n0 1\n-1 2\n", ":3: '-1 2' is not two keypoint indices"},
      {"a.jpg b.jpg\n0 x\n", ":2: '0 x' is not two keypoint indices"},
      {"a.jpg b.jpg\n0 1.5\n", ":2: '0 1.5' is not two keypoint indices"},
      {"a.jpg b.jpg\n0 99999999999\n", ":2: '0 99999999999' is not two keypoint indices"},
      {"a.jpg b.jpg\n0 1 2\n", ":2: 3 values; a match is `idx1 idx2`"},
      {"a.jpg\n0 1\n", ":1: 1 values; a block starts with `name1 name2`"},
      {"a.jpg b.jpg\n0 1\nb.jpg c.jpg\n", ":3: 'b.jpg c.jpg' is not two keypoint indices"},
      {"\n\n", ": no image pairs in the file"},
  };
  for (const auto& [text, message] : cases) {
    WriteText(file, text);
    ExpectInputError([&] { ParseRawMatchesFile(file); }, file.string() + message);
  }
}

// Three images with imported features, and raw matches between them.
class ImportMatchesTest : public ::testing::Test {
 protected:
  ImportMatchesTest() : fixture_(dir_.path(), 3) { fixture_.Import(fixture_.Features(8)); }

  MatchImportSummary Import(const std::string& text, bool verified) {
    const auto file = dir_.path() / "matches.txt";
    WriteText(file, text);
    return ImportMatches(*fixture_.workspace, settings_, MatchImportType::kRaw,
                         ParseRawMatchesFile(file), file.string(), verified);
  }
  std::string File() const { return (dir_.path() / "matches.txt").string(); }
  Database& database() { return fixture_.workspace->database(); }
  image_t Id(const std::string& name) { return database().ReadImageWithName(name)->image_id; }

  testing::TemporaryDir dir_;
  testing::ImportFixture fixture_;
  MatchSettings settings_;  // raw matches need no matcher
};

TEST_F(ImportMatchesTest, StoresVerifiedMatchesAsTheirOwnInliersAndSelectsTheirPairs) {
  const MatchImportSummary summary =
      Import("1.png 0.png\n0 1\n2 3\n4 5\n\n1.png 2.png\n7 7\n", /*verified=*/true);
  EXPECT_EQ(summary.num_pairs, 2u);
  EXPECT_EQ(summary.num_matched, 2u);
  EXPECT_EQ(summary.num_verified, 2u);
  EXPECT_EQ(summary.num_matches, 4u);
  EXPECT_EQ(summary.num_inliers, 4u);
  // Given as (1, 0): read back in that order.
  EXPECT_EQ(database().ReadMatches(Id("1.png"), Id("0.png")),
            (FeatureMatches{{0, 1}, {2, 3}, {4, 5}}));
  const TwoViewGeometry geometry = database().ReadTwoViewGeometry(Id("1.png"), Id("0.png"));
  EXPECT_EQ(geometry.config, TwoViewGeometry::UNCALIBRATED);
  EXPECT_EQ(geometry.inlier_matches.size(), 3u);
  const auto selected = database().ReadSelectedPairs();
  ASSERT_TRUE(selected);
  EXPECT_EQ(selected->size(), 2u);

  // The same file again: nothing to do. Then verified by Tessera: verified again.
  EXPECT_EQ(Import("1.png 0.png\n0 1\n2 3\n4 5\n\n1.png 2.png\n7 7\n", true).num_reused, 2u);
  const MatchImportSummary checked = Import("1.png 0.png\n0 1\n2 3\n4 5\n", /*verified=*/false);
  EXPECT_EQ(checked.num_matched, 1u);
  // Three made-up matches are too few for any model: the pair is degenerate.
  EXPECT_EQ(database().ReadTwoViewGeometry(Id("0.png"), Id("1.png")).config,
            TwoViewGeometry::DEGENERATE);
  EXPECT_EQ(checked.num_verified, 0u);
}

TEST_F(ImportMatchesTest, RefusesEachBadPairNamingFileAndLine) {
  const std::string ws = database().path().string();
  ExpectInputError([&] { Import("0.png 9.png\n0 1\n", true); },
                   File() + ":1: no image '9.png' in workspace " + ws);
  ExpectInputError(
      [&] { Import("0.png 1.png\n0 1\n\n0.png 2.png\n3 20\n", true); },
      File() + ":5: keypoint index 20 of '2.png' is out of range: it has 20 keypoints");
  ExpectInputError([&] { Import("0.png 1.png\n20 1\n", true); },
                   File() + ":2: keypoint index 20 of '0.png' is out of range");
  ExpectInputError([&] { Import("0.png 0.png\n0 1\n", true); },
                   File() + ":1: a pair of image '0.png' with itself");
  ExpectInputError([&] { Import("0.png 1.png\n0 1\n\n1.png 0.png\n0 1\n", true); },
                   File() + ":4: the pair is given twice (first at " + File() + ":1)");
  EXPECT_EQ(database().NumMatchedPairs(), 0u);  // nothing written
}

}  // namespace
}  // namespace tessera
