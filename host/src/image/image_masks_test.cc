#include "image/image_masks.h"

#include <gtest/gtest.h>

#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "tessera/errors.h"
#include "test_support.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

void WriteMask(const fs::path& file, int width, int height, int value) {
  fs::create_directories(file.parent_path());
  cv::imwrite(file.string(), cv::Mat(height, width, CV_8UC1, cv::Scalar(value)));
}

TEST(ImageMasks, FoundByNameAsColmapThenWithThePngExtension) {
  const testing::TemporaryDir dir;
  WriteMask(dir.path() / "a" / "b.jpg.png", 4, 4, 255);  // COLMAP's name
  WriteMask(dir.path() / "c.png", 4, 4, 255);            // the extension replaced
  WriteMask(dir.path() / "d.jpg.png", 4, 4, 255);
  WriteMask(dir.path() / "d.png", 4, 4, 0);  // both: COLMAP's wins
  EXPECT_EQ(FindMaskFile(dir.path(), "a/b.jpg"), dir.path() / "a" / "b.jpg.png");
  EXPECT_EQ(FindMaskFile(dir.path(), "c.jpg"), dir.path() / "c.png");
  EXPECT_EQ(FindMaskFile(dir.path(), "d.jpg"), dir.path() / "d.jpg.png");
  EXPECT_TRUE(FindMaskFile(dir.path(), "e.jpg").empty());
  EXPECT_TRUE(FindMaskFile(dir.path(), "b.jpg").empty());  // not in the sub-folder

  const ImageMasks masks = FindImageMasks(dir.path(), {"a/b.jpg", "c.jpg", "e.jpg"});
  EXPECT_EQ(masks.files.size(), 2u);
  EXPECT_EQ(masks.missing, std::vector<std::string>{"e.jpg"});
  EXPECT_EQ(masks.digest.size(), 32u);
  // A changed mask changes the digest; the same masks give the same one.
  EXPECT_EQ(FindImageMasks(dir.path(), {"a/b.jpg", "c.jpg", "e.jpg"}).digest, masks.digest);
  WriteMask(dir.path() / "c.png", 4, 4, 0);
  EXPECT_NE(FindImageMasks(dir.path(), {"a/b.jpg", "c.jpg", "e.jpg"}).digest, masks.digest);

  EXPECT_THROW(FindImageMasks(dir.path() / "nothing", {"c.jpg"}), InputError);
}

TEST(ImageMasks, AMaskOfTheWrongSizeOrUndecodableIsRefusedWithTheReason) {
  const testing::TemporaryDir dir;
  WriteMask(dir.path() / "m.png", 40, 30, 255);
  std::string problem;
  EXPECT_TRUE(ReadMask(dir.path() / "m.png", 40, 30, &problem).has_value());
  EXPECT_FALSE(ReadMask(dir.path() / "m.png", 30, 40, &problem).has_value());
  EXPECT_EQ(problem, "its mask " + (dir.path() / "m.png").string() + " is 40x30, the image 30x40");
  std::ofstream(dir.path() / "bad.png") << "not a PNG";
  EXPECT_FALSE(ReadMask(dir.path() / "bad.png", 40, 30, &problem).has_value());
  EXPECT_NE(problem.find("cannot be decoded"), std::string::npos);
}

TEST(ImageMasks, KeypointsOnBlackPixelsAreRemovedWithTheirDescriptors) {
  cv::Mat mask(10, 20, CV_8UC1, cv::Scalar(255));
  mask(cv::Rect(10, 0, 10, 10)).setTo(0);  // the right half is black
  FeatureSet features;
  features.keypoints = {{0.5f, 0.5f}, {9.99f, 5}, {10.0f, 5}, {19.5f, 9.5f}, {-3, 4}, {25, 4}};
  features.descriptors.data.resize(6, 2);
  for (int i = 0; i < 6; ++i) features.descriptors.data.row(i).setConstant(static_cast<uint8_t>(i));
  EXPECT_EQ(RemoveMaskedFeatures(mask, &features), 3u);  // x 10, 19.5 and 25 (clamped)
  ASSERT_EQ(features.keypoints.size(), 3u);
  ASSERT_EQ(features.descriptors.size(), 3);
  EXPECT_EQ(features.keypoints[0].x, 0.5f);
  EXPECT_EQ(features.keypoints[1].x, 9.99f);
  EXPECT_EQ(features.keypoints[2].x, -3.0f);
  EXPECT_EQ(features.descriptors.data(0, 0), 0);
  EXPECT_EQ(features.descriptors.data(1, 1), 1);
  EXPECT_EQ(features.descriptors.data(2, 0), 4);

  cv::Mat white(10, 20, CV_8UC1, cv::Scalar(1));  // any non-zero value keeps
  EXPECT_EQ(RemoveMaskedFeatures(white, &features), 0u);
  EXPECT_EQ(features.keypoints.size(), 3u);
}

}  // namespace
}  // namespace tessera
