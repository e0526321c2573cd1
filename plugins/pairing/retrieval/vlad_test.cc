#include "vlad.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "tessera/errors.h"

namespace tessera::retrieval {
namespace {

TEST(RetrievalVlad, LargestScaleFeaturesAreTakenFirst) {
  FeatureKeypoints keypoints = {
      {0, 0, 2.f, 0.f}, {0, 0, 5.f, 0.f}, {0, 0, 1.f, 0.f}, {0, 0, 5.f, 0.f}, {0, 0, 3.f, 0.f}};
  EXPECT_EQ(LargestScaleFeatures(keypoints, 3), (std::vector<size_t>{1, 3, 4}));
  EXPECT_EQ(LargestScaleFeatures(keypoints, 10), (std::vector<size_t>{1, 3, 4, 0, 2}));
  EXPECT_TRUE(LargestScaleFeatures({}, 10).empty());
}

TEST(RetrievalVlad, RootSiftIsSquareRootOfL1Normalised) {
  FeatureDescriptors descriptors;
  descriptors.data.resize(2, 4);
  descriptors.data << 1, 3, 0, 12, 0, 0, 0, 0;
  const std::vector<float> root = ToRootSift(descriptors, {0, 1});
  ASSERT_EQ(root.size(), 8u);
  EXPECT_FLOAT_EQ(root[0], 0.25f);
  EXPECT_FLOAT_EQ(root[1], std::sqrt(3.f / 16));
  EXPECT_FLOAT_EQ(root[2], 0.f);
  EXPECT_FLOAT_EQ(root[3], std::sqrt(12.f / 16));
  for (int i = 4; i < 8; ++i) EXPECT_EQ(root[i], 0.f);  // an all-zero row stays zero
}

TEST(RetrievalVlad, EncodesWithIntraAndPowerNormalisation) {
  Codebook codebook;
  codebook.descriptor_dimension = 2;
  codebook.num_centers = 2;
  codebook.centers = {0, 0, 10, 0};
  const VladEncoder encoder(codebook);
  EXPECT_EQ(encoder.Dimension(), 4u);
  // Both near centre 0: residual sum (3, 2) -> intra (3, 2)/sqrt(13) -> signed square
  // root -> L2: (sqrt(3/5), sqrt(2/5), 0, 0).
  std::vector<float> vlad = encoder.Encode({1, 1, 2, 1});
  ASSERT_EQ(vlad.size(), 4u);
  EXPECT_NEAR(vlad[0], std::sqrt(0.6), 1e-6);
  EXPECT_NEAR(vlad[1], std::sqrt(0.4), 1e-6);
  EXPECT_EQ(vlad[2], 0.f);
  EXPECT_EQ(vlad[3], 0.f);
  // One near each centre, residuals (0, 4) and (-1, 0): each block becomes a unit
  // vector, so every non-zero entry is +-1/sqrt(2).
  vlad = encoder.Encode({0, 4, 9, 0});
  EXPECT_NEAR(vlad[0], 0, 1e-7);
  EXPECT_NEAR(vlad[1], 1 / std::sqrt(2.), 1e-6);
  EXPECT_NEAR(vlad[2], -1 / std::sqrt(2.), 1e-6);
  EXPECT_NEAR(vlad[3], 0, 1e-7);
  EXPECT_EQ(encoder.Encode({}), std::vector<float>(4, 0.f));
}

std::vector<float> Blobs(int num_per_blob, std::mt19937& random) {
  // Three well-separated blobs in 4-D around (0..), (10..), (-10..).
  std::normal_distribution<float> noise(0.f, 0.5f);
  std::vector<float> samples;
  for (const float centre : {0.f, 10.f, -10.f}) {
    for (int i = 0; i < num_per_blob; ++i) {
      for (int j = 0; j < 4; ++j) samples.push_back(centre + noise(random));
    }
  }
  return samples;
}

TEST(RetrievalVlad, KMeansFindsBlobsAndIsThreadCountIndependent) {
  std::mt19937 random(5);
  const std::vector<float> samples = Blobs(400, random);
  KMeansOptions options;
  options.num_centers = 6;
  options.num_threads = 1;
  const Codebook one = TrainCodebook(samples, 4, options);
  ASSERT_EQ(one.centers.size(), 24u);
  // Every blob has a centre near its mean, and every centre lies in a blob.
  const auto distance_to = [](const float* centre, float blob) {
    double squared = 0;
    for (int j = 0; j < 4; ++j) squared += (centre[j] - blob) * (centre[j] - blob);
    return std::sqrt(squared);
  };
  for (const float blob : {0.f, 10.f, -10.f}) {
    double nearest = 1e9;
    for (int c = 0; c < 6; ++c) nearest = std::min(nearest, distance_to(&one.centers[4 * c], blob));
    EXPECT_LT(nearest, 0.5) << blob;
  }
  for (int c = 0; c < 6; ++c) {
    double nearest = 1e9;
    for (const float blob : {0.f, 10.f, -10.f}) {
      nearest = std::min(nearest, distance_to(&one.centers[4 * c], blob));
    }
    EXPECT_LT(nearest, 1.5) << c;
  }
  options.num_threads = 2;
  EXPECT_EQ(TrainCodebook(samples, 4, options).centers, one.centers);
  options.num_threads = 1;
  EXPECT_EQ(TrainCodebook(samples, 4, options).centers, one.centers);  // and repeatable
  options.num_centers = 2000;
  EXPECT_THROW(TrainCodebook(samples, 4, options), InputError);
}

}  // namespace
}  // namespace tessera::retrieval
