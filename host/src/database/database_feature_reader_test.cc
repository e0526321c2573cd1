#include "database/database_feature_reader.h"

#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include "test_support.h"

namespace tessera {
namespace {

TEST(DatabaseFeatureReader, ReadsEachImageByIndexFromManyThreads) {
  testing::TemporaryDir dir;
  Database database(dir.path() / "database.db");
  database.WriteCamera(Camera::Create(kInvalidCameraId, CameraModelId::kPinhole, 500, 640, 480));
  std::vector<image_t> ids;
  for (int i = 0; i < 3; ++i) {
    Image image;
    image.name = "image" + std::to_string(i) + ".jpg";
    image.camera_id = 1;
    const image_t id = database.WriteImage(image);
    FeatureKeypoints keypoints(static_cast<size_t>(10 + i));
    for (size_t k = 0; k < keypoints.size(); ++k) {
      keypoints[k].x = static_cast<float>(i * 100 + k);
    }
    database.WriteKeypoints(id, keypoints);
    FeatureDescriptors descriptors;
    descriptors.data.setConstant(10 + i, 32, static_cast<uint8_t>(i + 1));
    database.WriteDescriptors(id, descriptors);
    ids.push_back(id);
  }
  // The reader's order is the selector's (capture order), not the ids'.
  const DatabaseFeatureReader reader(&database, {ids[2], ids[0], ids[1]},
                                     DescriptorMetric::kHamming, 32);
  EXPECT_EQ(reader.Metric(), DescriptorMetric::kHamming);
  EXPECT_EQ(reader.DescriptorDimension(), 32);
  EXPECT_THROW(reader.ReadKeypoints(3), std::out_of_range);

  std::vector<std::thread> threads;
  std::atomic<int> failures{0};
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&] {
      for (int round = 0; round < 20; ++round) {
        for (size_t index = 0; index < 3; ++index) {
          const int i = static_cast<int>((index + 2) % 3);  // image written i-th
          const FeatureKeypoints keypoints = reader.ReadKeypoints(index);
          const FeatureDescriptors descriptors = reader.ReadDescriptors(index);
          if (keypoints.size() != static_cast<size_t>(10 + i) || keypoints[1].x != i * 100 + 1 ||
              descriptors.data.rows() != 10 + i || descriptors.data(0, 0) != i + 1 ||
              descriptors.metric != DescriptorMetric::kHamming) {
            ++failures;
          }
        }
      }
    });
  }
  for (auto& thread : threads) thread.join();
  EXPECT_EQ(failures, 0);
}

}  // namespace
}  // namespace tessera
