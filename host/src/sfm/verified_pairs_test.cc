#include "tessera/sfm/verified_pairs.h"

#include <gtest/gtest.h>

namespace tessera {
namespace {

MapperInput::Pair MakePair(image_t image_id1, image_t image_id2, int config, size_t num_inliers) {
  MapperInput::Pair pair;
  pair.image_id1 = image_id1;
  pair.image_id2 = image_id2;
  pair.geometry.config = config;
  pair.geometry.inlier_matches.resize(num_inliers);
  return pair;
}

TEST(VerifiedPairs, OnlyConfigurationsOfOnePointPerMatchAreVerified) {
  const std::vector<int> verified = {TwoViewGeometry::CALIBRATED, TwoViewGeometry::UNCALIBRATED,
                                     TwoViewGeometry::PLANAR, TwoViewGeometry::PANORAMIC,
                                     TwoViewGeometry::PLANAR_OR_PANORAMIC};
  const std::vector<int> not_verified = {TwoViewGeometry::UNDEFINED, TwoViewGeometry::DEGENERATE,
                                         TwoViewGeometry::WATERMARK, TwoViewGeometry::MULTIPLE};
  for (const int config : verified) {
    TwoViewGeometry geometry;
    geometry.config = config;
    EXPECT_TRUE(IsVerified(geometry)) << config;
  }
  for (const int config : not_verified) {
    TwoViewGeometry geometry;
    geometry.config = config;
    EXPECT_FALSE(IsVerified(geometry)) << config;
  }
}

TEST(VerifiedPairs, KeepsVerifiedPairsWithEnoughInliersBetweenTwoInputImages) {
  MapperInput input;
  for (image_t image_id = 1; image_id <= 3; ++image_id) input.images[image_id].image_id = image_id;
  input.pairs = {MakePair(1, 2, TwoViewGeometry::UNCALIBRATED, 15),
                 MakePair(1, 3, TwoViewGeometry::UNCALIBRATED, 14),  // too few inliers
                 MakePair(2, 3, TwoViewGeometry::DEGENERATE, 100),   // not verified
                 MakePair(2, 2, TwoViewGeometry::CALIBRATED, 100),   // an image with itself
                 MakePair(3, 4, TwoViewGeometry::CALIBRATED, 100),   // image 4 is not input
                 MakePair(3, 2, TwoViewGeometry::PLANAR, 40)};
  const std::vector<const MapperInput::Pair*> pairs = VerifiedPairs(input, 15);
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_EQ(pairs[0], &input.pairs[0]);
  EXPECT_EQ(pairs[1], &input.pairs[5]);
}

TEST(VerifiedPairs, StrongPairsHoldAShareOfTheirWeakerImagesStrongestPair) {
  // Image 1's strongest pair has 100 inliers, image 3's 50, image 4's 10.
  const std::vector<MapperInput::Pair> all = {
      MakePair(1, 2, TwoViewGeometry::UNCALIBRATED, 100),
      MakePair(1, 3, TwoViewGeometry::UNCALIBRATED, 10),  // 0.2 of image 3's 50: kept
      MakePair(2, 3, TwoViewGeometry::UNCALIBRATED, 50),
      MakePair(1, 4, TwoViewGeometry::UNCALIBRATED, 9),   // image 4's strongest: kept
      MakePair(3, 4, TwoViewGeometry::UNCALIBRATED, 8),   // image 4 the weaker: 8 >= 0.2 x 9
      MakePair(2, 4, TwoViewGeometry::UNCALIBRATED, 1)};  // 1 < 0.2 x 9
  std::vector<const MapperInput::Pair*> pairs;
  for (const MapperInput::Pair& pair : all) pairs.push_back(&pair);
  const std::vector<const MapperInput::Pair*> strong = StrongPairs(pairs, 0.2);
  ASSERT_EQ(strong.size(), 5u);
  EXPECT_EQ(strong[0], &all[0]);
  EXPECT_EQ(strong[1], &all[1]);
  EXPECT_EQ(strong[2], &all[2]);
  EXPECT_EQ(strong[3], &all[3]);
  EXPECT_EQ(strong[4], &all[4]);
  EXPECT_EQ(StrongPairs(pairs, 0.0).size(), all.size());
  EXPECT_EQ(StrongPairs(pairs, 1.0).size(), 3u);  // each image's strongest
}

}  // namespace
}  // namespace tessera
