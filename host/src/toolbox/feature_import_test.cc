#include "toolbox/feature_import.h"

#include <gtest/gtest.h>

#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <string>

#include "pipeline/extract_stage.h"  // IsImportedFeatures
#include "test_support.h"
#include "toolbox/import_test_support.h"

namespace tessera {
namespace {

using testing::ExpectInputError;
using testing::WriteText;

TEST(ParseFeatureFile, ReadsColmapsTextFormat) {
  const testing::TemporaryDir dir;
  const auto file = dir.path() / "a.jpg.txt";
  WriteText(file,
            "3 4\n"
            "10.5 20.25 2 0 1 2 3 4\n"
            "1 1 1.5 1.5707963 0 0 0 255\n"
            "  30\t40 1 -0.5 0.5 0.25 0.125 1e-3  \n"
            "\n");
  const ImportedFeatures features = ParseFeatureFile(file, "a.jpg");
  EXPECT_EQ(features.name, "a.jpg");
  ASSERT_EQ(features.keypoints.size(), 3u);
  ASSERT_EQ(features.descriptors.rows(), 3);
  ASSERT_EQ(features.descriptors.cols(), 4);
  EXPECT_FLOAT_EQ(features.keypoints[0].x, 10.5f);
  EXPECT_FLOAT_EQ(features.keypoints[0].y, 20.25f);
  EXPECT_NEAR(features.keypoints[0].ComputeScale(), 2, 1e-6);
  EXPECT_NEAR(features.keypoints[1].ComputeOrientation(), 1.5707963, 1e-6);
  EXPECT_NEAR(features.keypoints[2].ComputeOrientation(), -0.5, 1e-6);
  EXPECT_FLOAT_EQ(features.descriptors(1, 3), 255);
  EXPECT_FLOAT_EQ(features.descriptors(2, 3), 1e-3f);
  EXPECT_EQ(features.Where(2), file.string() + ":4");
  EXPECT_FALSE(AllBytes(features.descriptors));
  EXPECT_TRUE(AllBytes(features.descriptors.topRows(2)));
}

TEST(ParseFeatureFile, ReadsAnImageWithoutKeypoints) {
  const testing::TemporaryDir dir;
  WriteText(dir.path() / "a.txt", "0 128\n");
  const ImportedFeatures features = ParseFeatureFile(dir.path() / "a.txt", "a");
  EXPECT_TRUE(features.keypoints.empty());
  EXPECT_EQ(features.descriptors.cols(), 128);
}

// Each bad input is one InputError naming the file and line.
TEST(ParseFeatureFile, RefusesEachBadInputNamingFileAndLine) {
  const testing::TemporaryDir dir;
  const auto file = dir.path() / "a.jpg.txt";
  const std::string f = file.string();
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"", f + ":1: empty file"},
      {"2\n1 2 1 0 5\n", f + ":1: the first line must be `N D`"},
      {"2 0\n", f + ":1: the first line must be `N D`"},
      {"-1 4\n", f + ":1: the first line must be `N D`"},
      {"2 2 7\n", f + ":1: the first line must be `N D`"},
      {"2 2\n1 2 1 0 5 6\n", f + ":3: truncated: the header announces 2 keypoints, the file "
                                 "ends after 1"},
      {"2 2\n1 2 1 0 5 6\n1 2 1 0 5\n", f + ":3: 5 values; 6 expected"},
      {"1 2\n1 2 1 0 5 6 7\n", f + ":2: 7 values; 6 expected"},
      {"1 2\n1 two 1 0 5 6\n", f + ":2: 'two' is not a number"},
      {"1 2\nnan 2 1 0 5 6\n", f + ":2: keypoint coordinates (nan, 2.000000) are not finite"},
      {"1 2\n1 inf 1 0 5 6\n", f + ":2: keypoint coordinates"},
      {"1 2\n1 2 -1 0 5 6\n", f + ":2: scale -1.000000 and orientation 0.000000 must be finite"},
      {"1 2\n1 2 1 nan 5 6\n", f + ":2: scale 1.000000 and orientation nan must be finite"},
      {"1 2\n1 2 1 0 5 nan\n", f + ":2: descriptor value 2 is not finite"},
      {"1 2\n1 2 1 0 5 6\n1 2 1 0 5 6\n", f + ":3: more lines than the header's 1 keypoints"},
      {"2 2\n\n1 2 1 0 5 6\n", f + ":2: 0 values; 6 expected"},
  };
  for (const auto& [text, message] : cases) {
    WriteText(file, text);
    ExpectInputError([&] { ParseFeatureFile(file, "a.jpg"); }, message);
  }
  ExpectInputError([&] { ParseFeatureFile(dir.path() / "none.txt", "none"); },
                   (dir.path() / "none.txt").string() + ": cannot be read");
}

TEST(EncodeDescriptors, StoresBytesAsTheyAreAndUnitFloatsScaledBy256About128) {
  DescriptorValues bytes(2, 3);
  bytes << 0, 17, 255, 3, 4, 5;
  EXPECT_TRUE(AllBytes(bytes));
  const FeatureDescriptors stored = EncodeDescriptors(bytes, DescriptorEncoding::kBytes);
  EXPECT_EQ(stored.metric, DescriptorMetric::kL2);
  EXPECT_EQ(stored.data(0, 1), 17);
  EXPECT_EQ(stored.data(0, 2), 255);
  EXPECT_EQ(stored.data(1, 0), 3);

  DescriptorValues unit(1, 4);
  unit << 0.1f, -0.1f, 0.0f, 0.0f;  // scaled to (0.707, -0.707): clipped at both ends
  const FeatureDescriptors clipped = EncodeDescriptors(unit, DescriptorEncoding::kUnitFloat);
  EXPECT_EQ(clipped.data(0, 0), 255);
  EXPECT_EQ(clipped.data(0, 1), 0);
  EXPECT_EQ(clipped.data(0, 2), 128);

  // Learned-like descriptors: L2 distances of the stored rows are 256 times those of the
  // unit vectors, so nearest neighbours and ratio tests keep their answers.
  std::mt19937 random(7);
  std::normal_distribution<float> normal;
  DescriptorValues values(20, 128);
  for (Eigen::Index i = 0; i < values.size(); ++i) values.data()[i] = 3 * normal(random);
  EXPECT_FALSE(AllBytes(values));
  const FeatureDescriptors encoded = EncodeDescriptors(values, DescriptorEncoding::kUnitFloat);
  for (Eigen::Index r = 1; r < values.rows(); ++r) {
    const Eigen::VectorXf a = values.row(0).normalized(), b = values.row(r).normalized();
    const double unit_distance = (a - b).norm();
    const double stored_distance =
        (encoded.data.row(0).cast<double>() - encoded.data.row(r).cast<double>()).norm();
    EXPECT_NEAR(stored_distance / unit_distance, 256, 256 * 0.01) << r;
  }
}

TEST(ImportFeatures, IngestsTheImagesAndStoresTheFeaturesThenKeepsOrReplacesThem) {
  const testing::TemporaryDir dir;
  testing::ImportFixture fixture(dir.path(), 3);
  const FeatureImportSummary first = fixture.Import(fixture.Features(/*dimension=*/8));
  EXPECT_EQ(first.num_images, 3u);
  EXPECT_EQ(first.num_imported, 3u);
  EXPECT_EQ(first.num_features, 3u * testing::ImportFixture::kNumKeypoints);
  EXPECT_EQ(first.encoding, "unit_float");
  Database& database = fixture.workspace->database();
  EXPECT_EQ(database.NumImages(), 3u);
  EXPECT_EQ(database.DescriptorWidths(), std::vector<int64_t>{8});
  const auto provenance = database.ReadStageProvenance(Database::kFeaturesStage);
  ASSERT_TRUE(provenance);
  EXPECT_TRUE(IsImportedFeatures(*provenance));
  EXPECT_EQ(provenance->value("descriptors", ""), "unit_float");
  const image_t id0 = database.ReadImageWithName("0.png")->image_id;
  const image_t id1 = database.ReadImageWithName("1.png")->image_id;
  EXPECT_FLOAT_EQ(database.ReadKeypoints(id0)[1].x, fixture.Features(8)[0].keypoints[1].x);

  // The same again: nothing written. One image changed: its pairs go.
  const FeatureImportSummary again = fixture.Import(fixture.Features(8));
  EXPECT_EQ(again.num_reused, 3u);
  EXPECT_EQ(again.num_imported, 0u);
  database.WriteMatches(id0, id1, {{0, 1}});
  std::vector<ImportedFeatures> changed = fixture.Features(8);
  changed[0].keypoints[0].x += 1;
  const FeatureImportSummary replaced = fixture.Import({changed[0]});
  EXPECT_EQ(replaced.num_imported, 1u);
  EXPECT_EQ(replaced.num_replaced, 1u);
  EXPECT_EQ(replaced.num_images, 3u);  // the others keep their features and stay
  EXPECT_FALSE(database.ExistsMatches(id0, id1));
}

TEST(ImportFeatures, StoresWholeNumbersAsBytes) {
  const testing::TemporaryDir dir;
  testing::ImportFixture fixture(dir.path(), 2);
  std::vector<ImportedFeatures> features = fixture.Features(128);
  for (ImportedFeatures& image : features) {
    image.descriptors = (image.descriptors.array().abs() * 40).round().min(255.0f).matrix();
  }
  EXPECT_EQ(fixture.Import(features).encoding, "uint8");
  const Database& database = fixture.workspace->database();
  const FeatureDescriptors stored = database.ReadDescriptors(
      database.ReadImageWithName("1.png")->image_id, DescriptorMetric::kL2);
  EXPECT_EQ(stored.data(3, 5), static_cast<uint8_t>(features[1].descriptors(3, 5)));
  // Fractional values after whole numbers: refused, one kind per workspace.
  ExpectInputError([&] { fixture.Import(fixture.Features(128)); },
                   "descriptors with fractional values, where the workspace holds imported "
                   "descriptors of whole numbers");
}

TEST(ImportFeatures, RefusesBadInputBeforeWritingAnything) {
  const testing::TemporaryDir dir;
  testing::ImportFixture fixture(dir.path(), 3);
  std::vector<ImportedFeatures> mixed = fixture.Features(8);
  mixed[2].descriptors = DescriptorValues::Ones(mixed[2].descriptors.rows(), 16);
  ExpectInputError([&] { fixture.Import(mixed); },
                   "features['2.png']: descriptors of width 16, where features['0.png'] has "
                   "width 8; every image's descriptors must have one width");

  std::vector<ImportedFeatures> outside = fixture.Features(8);
  outside[1].keypoints[4].x = 80.5f;
  ExpectInputError([&] { fixture.Import(outside); },
                   "features['1.png'] row 4: keypoint (80.500000, ");

  std::vector<ImportedFeatures> nan = fixture.Features(8);
  nan[0].keypoints[2].y = std::nanf("");
  ExpectInputError([&] { fixture.Import(nan); }, "features['0.png'] row 2: keypoint coordinates");

  std::vector<ImportedFeatures> unknown = fixture.Features(8);
  unknown[0].name = "9.png";
  ExpectInputError([&] { fixture.Import(unknown); },
                   "the features given: features for '9.png', which is no image of");
  EXPECT_EQ(fixture.workspace->database().NumImages(), 0u);
  EXPECT_FALSE(fixture.workspace->database().ReadStageProvenance(Database::kFeaturesStage));

  // Once imported, another width is refused against the workspace's.
  fixture.Import(fixture.Features(8));
  ExpectInputError([&] { fixture.Import(fixture.Features(16)); },
                   "descriptors of width 16, where " +
                       fixture.workspace->database().path().string() +
                       " (imported before) has width 8");
}

TEST(ImportFeatures, RefusesAWorkspaceHoldingADetectorsFeatures) {
  const testing::TemporaryDir dir;
  testing::ImportFixture fixture(dir.path(), 2);
  Database& database = fixture.workspace->database();
  fixture.Import(fixture.Features(8));
  database.WriteStageProvenance(Database::kFeaturesStage, {{"plugin", "sift"}, {"metric", "l2"}});
  ExpectInputError([&] { fixture.Import(fixture.Features(8)); },
                   "the workspace holds features of detector 'sift'; import into a new "
                   "workspace");
}

TEST(FeatureFolderSource, NamesEachImageByItsFileWithoutTxt) {
  const testing::TemporaryDir dir;
  WriteText(dir.path() / "b.jpg.txt", "0 4\n");
  WriteText(dir.path() / "sub" / "a.png.txt", "0 4\n");
  WriteText(dir.path() / "notes.md", "-");
  const FeatureSource source = FeatureFolderSource(dir.path());
  EXPECT_EQ(source.names, (std::vector<std::string>{"b.jpg", "sub/a.png"}));
  EXPECT_EQ(source.load("sub/a.png").source, (dir.path() / "sub" / "a.png.txt").string());
  ExpectInputError([&] { FeatureFolderSource(dir.path() / "none"); }, "no such folder");
}

}  // namespace
}  // namespace tessera
