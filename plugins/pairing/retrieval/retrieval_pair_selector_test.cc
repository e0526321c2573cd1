#include "retrieval_pair_selector.h"

#include <gtest/gtest.h>

#include <atomic>
#include <fstream>
#include <random>
#include <set>

#include "codebook.h"
#include "test_support.h"

namespace tessera::retrieval {
namespace {

// Features held in memory, handed out as the workspace would; counts the reads.
class InMemoryFeatureReader : public FeatureReader {
 public:
  explicit InMemoryFeatureReader(std::vector<FeatureSet> images,
                                 DescriptorMetric metric = DescriptorMetric::kL2)
      : images_(std::move(images)), metric_(metric) {}
  FeatureKeypoints ReadKeypoints(size_t index) const override {
    ++reads_;
    return images_.at(index).keypoints;
  }
  FeatureDescriptors ReadDescriptors(size_t index) const override {
    ++reads_;
    return images_.at(index).descriptors;
  }
  DescriptorMetric Metric() const override { return metric_; }
  int DescriptorDimension() const override { return 128; }
  size_t reads() const { return reads_; }

 private:
  std::vector<FeatureSet> images_;
  DescriptorMetric metric_;
  mutable std::atomic<size_t> reads_{0};
};

// `num_scenes` scenes of `per_scene` images, listed interleaved (scene = index %
// num_scenes) so that neighbours in the list are never of the same scene. Each scene
// has 200 SIFT-like "landmark" descriptors; each of its images sees 150 of them, with
// pixel noise, at random scales.
std::vector<FeatureSet> SyntheticScenes(int num_scenes, int per_scene, uint32_t seed) {
  std::mt19937 random(seed);
  std::vector<std::vector<std::vector<int>>> landmarks(num_scenes);
  for (auto& scene : landmarks) {
    for (int l = 0; l < 200; ++l) {
      std::vector<int> descriptor(128);
      for (int& value : descriptor)
        value = random() % 4 == 0 ? static_cast<int>(random() % 120) : 0;
      scene.push_back(descriptor);
    }
  }
  std::vector<FeatureSet> images(num_scenes * per_scene);
  for (size_t i = 0; i < images.size(); ++i) {
    const auto& scene = landmarks[i % num_scenes];
    std::vector<int> visible(200);
    for (int l = 0; l < 200; ++l) visible[l] = l;
    std::shuffle(visible.begin(), visible.end(), random);
    visible.resize(150);
    FeatureSet& features = images[i];
    features.descriptors.data.resize(150, 128);
    for (int f = 0; f < 150; ++f) {
      features.keypoints.emplace_back(static_cast<float>(random() % 1000),
                                      static_cast<float>(random() % 1000),
                                      1.f + static_cast<float>(random() % 100) / 10, 0.f);
      for (int j = 0; j < 128; ++j) {
        const int value = scene[visible[f]][j] + static_cast<int>(random() % 7) - 3;
        features.descriptors.data(f, j) = static_cast<uint8_t>(std::clamp(value, 0, 255));
      }
    }
  }
  return images;
}

PairSelectionInput Input(size_t n, const FeatureReader* reader, int num_threads = 1) {
  PairSelectionInput input;
  for (size_t i = 0; i < n; ++i) {
    PairSelectionImage image;
    image.image_id = static_cast<image_t>(i + 1);
    image.name = "img" + std::to_string(i) + ".jpg";
    input.images.push_back(image);
  }
  input.features = reader;
  input.num_threads = num_threads;
  return input;
}

// Pairs of images of the same scene (index % num_scenes), ascending.
std::vector<ImageIndexPair> SameScenePairs(size_t n, size_t num_scenes) {
  std::vector<ImageIndexPair> pairs;
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i + 1; j < n; ++j) {
      if (i % num_scenes == j % num_scenes) pairs.emplace_back(i, j);
    }
  }
  return pairs;
}

TEST(RetrievalPairSelector, PairsEachImageWithItsSceneTrainedOnTheRun) {
  const InMemoryFeatureReader reader(SyntheticScenes(3, 5, 11));
  auto selector = testing::LoadBundledPlugin<PairSelector>(
      "pair_selector", "retrieval", {{"num_neighbors", 4}, {"codebook_size", 16}});
  const auto pairs = testing::Unguarded(selector).SelectPairs(Input(15, &reader));
  EXPECT_EQ(pairs, SameScenePairs(15, 3));
  EXPECT_EQ(pairs.size(), 30u);
  // Two passes (training sample, then VLAD), keypoints and descriptors each.
  EXPECT_EQ(reader.reads(), 4u * 15);
  EXPECT_EQ(testing::Unguarded(selector).EffectiveOptions(),
            (nlohmann::json{{"num_neighbors", 4},
                            {"codebook", ""},
                            {"codebook_size", 16},
                            {"max_features_per_image", 2000},
                            {"training_descriptors", 100000},
                            {"seed", 1}}));
}

TEST(RetrievalPairSelector, FewNeighboursGiveSymmetricUniqueOrderedPairs) {
  const InMemoryFeatureReader reader(SyntheticScenes(4, 6, 12));
  auto selector = testing::LoadBundledPlugin<PairSelector>(
      "pair_selector", "retrieval", {{"num_neighbors", 1}, {"codebook_size", 8}});
  const auto pairs = testing::Unguarded(selector).SelectPairs(Input(24, &reader));
  // Each image adds one pair; mutual nearest neighbours share one.
  EXPECT_GE(pairs.size(), 12u);
  EXPECT_LE(pairs.size(), 24u);
  EXPECT_TRUE(std::is_sorted(pairs.begin(), pairs.end()));
  std::set<size_t> covered;
  for (const auto& [first, second] : pairs) {
    EXPECT_LT(first, second);
    EXPECT_EQ(first % 4, second % 4) << first << " " << second;  // same scene
    covered.insert(first);
    covered.insert(second);
  }
  EXPECT_EQ(covered.size(), 24u);
  EXPECT_EQ(std::set<ImageIndexPair>(pairs.begin(), pairs.end()).size(), pairs.size());
}

TEST(RetrievalPairSelector, SameResultForEveryThreadCount) {
  const InMemoryFeatureReader reader(SyntheticScenes(3, 7, 13));
  const RetrievalPairSelector selector({{"num_neighbors", 3}, {"codebook_size", 32}});
  const Codebook one = selector.TrainOnInput(Input(21, &reader, 1), false);
  const Codebook two = selector.TrainOnInput(Input(21, &reader, 2), false);
  EXPECT_EQ(one.centers, two.centers);
  EXPECT_EQ(selector.GlobalDescriptors(Input(21, &reader, 1), one),
            selector.GlobalDescriptors(Input(21, &reader, 2), one));
  EXPECT_EQ(selector.SelectPairs(Input(21, &reader, 1)),
            selector.SelectPairs(Input(21, &reader, 2)));
  // Unit-length vectors; an image is most similar to itself.
  const std::vector<float> vectors = selector.GlobalDescriptors(Input(21, &reader, 1), one);
  const size_t length = vectors.size() / 21;
  double squared = 0;
  for (size_t j = 0; j < length; ++j) squared += vectors[j] * vectors[j];
  EXPECT_NEAR(squared, 1, 1e-5);
}

TEST(RetrievalPairSelector, EnoughNeighboursGiveAllPairsWithoutReading) {
  const InMemoryFeatureReader reader(SyntheticScenes(2, 3, 14));
  auto selector = testing::LoadBundledPlugin<PairSelector>("pair_selector", "retrieval",
                                                           {{"num_neighbors", 5}});
  const auto pairs = testing::Unguarded(selector).SelectPairs(Input(6, &reader));
  EXPECT_EQ(pairs.size(), 15u);
  EXPECT_EQ(pairs.front(), ImageIndexPair(0, 1));
  EXPECT_EQ(pairs.back(), ImageIndexPair(4, 5));
  EXPECT_EQ(reader.reads(), 0u);
  auto large = testing::LoadBundledPlugin<PairSelector>("pair_selector", "retrieval",
                                                        {{"num_neighbors", 1000}});
  EXPECT_EQ(testing::Unguarded(large).SelectPairs(Input(6, nullptr)).size(), 15u);
  EXPECT_TRUE(testing::Unguarded(large).SelectPairs(Input(1, nullptr)).empty());
  EXPECT_TRUE(testing::Unguarded(large).SelectPairs(Input(0, nullptr)).empty());
}

TEST(RetrievalPairSelector, TrainedCodebookFileIsReadBackAndChecked) {
  testing::TemporaryDir dir;
  const InMemoryFeatureReader reader(SyntheticScenes(3, 5, 15));
  const auto file = dir.path() / "vocab.bin";
  auto trainer = testing::LoadBundledPlugin<PairSelector>("pair_selector", "retrieval",
                                                          {{"codebook_size", 24}, {"seed", 4}});
  testing::Unguarded(trainer).Train(Input(15, &reader), file);
  const Codebook codebook = ReadCodebook(file);
  EXPECT_EQ(codebook.num_centers, 24);
  EXPECT_EQ(codebook.descriptor_dimension, 128);
  // Deterministic: training again writes the same bytes.
  testing::Unguarded(trainer).Train(Input(15, &reader, 2), dir.path() / "again.bin");
  EXPECT_EQ(ReadCodebook(dir.path() / "again.bin").centers, codebook.centers);

  auto user = testing::LoadBundledPlugin<PairSelector>(
      "pair_selector", "retrieval", {{"num_neighbors", 4}, {"codebook", file.string()}});
  testing::Unguarded(user).CheckDescriptors(DescriptorMetric::kL2, 128);
  testing::Unguarded(user).CheckDescriptors(DescriptorMetric::kL2, 0);  // width not known yet
  EXPECT_EQ(testing::Unguarded(user).SelectPairs(Input(15, &reader)), SameScenePairs(15, 3));
  try {
    testing::Unguarded(user).CheckDescriptors(DescriptorMetric::kL2, 64);
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()),
              file.string() +
                  ": the retrieval codebook is for descriptors of 128 dimensions, "
                  "the detector's have 64");
  }
  // Too few descriptors for the centres asked for.
  auto greedy = testing::LoadBundledPlugin<PairSelector>("pair_selector", "retrieval",
                                                         {{"codebook_size", 5000}});
  EXPECT_THROW(testing::Unguarded(greedy).Train(Input(15, &reader), dir.path() / "x.bin"),
               InputError);
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "x.bin"));
}

TEST(RetrievalPairSelector, BadCodebookOptionsFailAtConstruction) {
  testing::TemporaryDir dir;
  const auto missing = dir.path() / "none.bin";
  try {
    testing::LoadBundledPlugin<PairSelector>("pair_selector", "retrieval",
                                             {{"codebook", missing.string()}});
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find(missing.string() + ": retrieval codebook not found"),
              std::string::npos)
        << error.what();
  }
  const auto corrupt = dir.path() / "corrupt.bin";
  std::ofstream(corrupt) << "TSRVLAD";
  try {
    testing::LoadBundledPlugin<PairSelector>("pair_selector", "retrieval",
                                             {{"codebook", corrupt.string()}});
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find(corrupt.string() + ": not a valid retrieval codebook"),
              std::string::npos)
        << error.what();
  }
  try {
    testing::LoadBundledPlugin<PairSelector>("pair_selector", "retrieval",
                                             {{"codebook", corrupt.string()}, {"codebook_size", 8}},
                                             "pipeline.pair_selector");
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what())
                  .find("pipeline.pair_selector.options.codebook_size: is for "
                        "a codebook trained on the run"),
              std::string::npos)
        << error.what();
  }
  try {
    testing::LoadBundledPlugin<PairSelector>("pair_selector", "retrieval", {{"num_neighbours", 3}},
                                             "pipeline.pair_selector");
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what())
                  .find("pipeline.pair_selector.options.num_neighbours: "
                        "unknown key; did you mean 'num_neighbors'?"),
              std::string::npos)
        << error.what();
  }
}

TEST(RetrievalPairSelector, RefusesBinaryDescriptorsAndMissingFeatures) {
  auto selector = testing::LoadBundledPlugin<PairSelector>("pair_selector", "retrieval",
                                                           {{"num_neighbors", 2}});
  try {
    testing::Unguarded(selector).CheckDescriptors(DescriptorMetric::kHamming, 32);
    FAIL() << "expected an error";
  } catch (const OptionError& error) {
    EXPECT_EQ(std::string(error.what()),
              "the retrieval pair selector needs real-valued (l2) descriptors such as SIFT for "
              "VLAD, not hamming (binary, e.g. ORB) ones: use a SIFT detector or another pair "
              "selector");
  }
  const InMemoryFeatureReader binary(SyntheticScenes(2, 3, 16), DescriptorMetric::kHamming);
  EXPECT_THROW(testing::Unguarded(selector).SelectPairs(Input(6, &binary)), OptionError);
  EXPECT_EQ(binary.reads(), 0u);
  EXPECT_THROW(testing::Unguarded(selector).SelectPairs(Input(6, nullptr)), InputError);
}

}  // namespace
}  // namespace tessera::retrieval
