#include "tessera/io/point_colors.h"

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include "io/keypoint_color_sampler.h"
#include "test_support.h"

namespace tessera {
namespace {

// On one thread and on three (each image on its own): the same colours and warnings.
TEST(ColorPointsFromImages, MeanOfTheTrackColoursAndAWarningForAMissingImage) {
  testing::TemporaryDir dir;
  // Left half red, right half blue, in image a; all green in image b.
  cv::Mat a(40, 40, CV_8UC3, cv::Scalar(0, 0, 255));
  a(cv::Rect(20, 0, 20, 40)).setTo(cv::Scalar(255, 0, 0));
  cv::Mat b(40, 40, CV_8UC3, cv::Scalar(0, 255, 0));
  ASSERT_TRUE(cv::imwrite((dir.path() / "a.png").string(), a));
  ASSERT_TRUE(cv::imwrite((dir.path() / "b.png").string(), b));

  for (const int num_threads : {1, 3}) {
    SCOPED_TRACE("num_threads " + std::to_string(num_threads));
    Reconstruction rec;
    const auto add_image = [&](image_t image_id, const std::string& name) {
      Image image;
      image.image_id = image_id;
      image.name = name;
      image.registered = true;
      image.points2D.resize(2);
      image.points2D[0].xy = Eigen::Vector2d(5.5, 10.5);   // red in a
      image.points2D[1].xy = Eigen::Vector2d(30.5, 10.5);  // blue in a
      image.points2D[0].point3D_id = 1;
      if (image_id != 2) image.points2D[1].point3D_id = 2;
      rec.images[image_id] = image;
    };
    add_image(1, "a.png");
    add_image(2, "b.png");
    add_image(3, "missing.png");
    rec.points3D[1].track = {{1, 0}, {2, 0}, {3, 0}};
    rec.points3D[2].track = {{1, 1}, {3, 1}};

    const std::vector<std::string> warnings = ColorPointsFromImages(dir.path(), &rec, num_threads);
    ASSERT_EQ(warnings.size(), 1u);
    EXPECT_NE(warnings[0].find("missing.png"), std::string::npos) << warnings[0];
    // Point 1: red in a and green in b.
    EXPECT_EQ(rec.points3D[1].color, (Eigen::Matrix<uint8_t, 3, 1>(128, 128, 0)));
    // Point 2: blue in a only.
    EXPECT_EQ(rec.points3D[2].color, (Eigen::Matrix<uint8_t, 3, 1>(0, 0, 255)));
  }
}

// Two images of one camera: a left half red and right half blue; b all green. Keypoint 0
// of each image at (5.5, 10.5), keypoint 1 at (30.5, 10.5).
struct TwoImages {
  explicit TwoImages(const std::filesystem::path& dir) {
    cv::Mat a(40, 40, CV_8UC3, cv::Scalar(0, 0, 255));
    a(cv::Rect(20, 0, 20, 40)).setTo(cv::Scalar(255, 0, 0));
    const cv::Mat b(40, 40, CV_8UC3, cv::Scalar(0, 255, 0));
    EXPECT_TRUE(cv::imwrite((dir / "a.png").string(), a));
    EXPECT_TRUE(cv::imwrite((dir / "b.png").string(), b));
    cameras[1].camera_id = 1;
    cameras[1].width = 40;
    cameras[1].height = 40;
    for (const auto& [image_id, name] :
         {std::pair<image_t, std::string>{1, "a.png"}, {2, "b.png"}}) {
      Image& image = images[image_id];
      image.image_id = image_id;
      image.camera_id = 1;
      image.name = name;
      image.points2D.resize(2);
      image.points2D[0].xy = Eigen::Vector2d(5.5, 10.5);
      image.points2D[1].xy = Eigen::Vector2d(30.5, 10.5);
    }
  }

  // The model: point 1 seen by keypoint 0 of both images, point 2 by keypoint 1 of a.
  Reconstruction Model() const {
    Reconstruction model;
    model.cameras = cameras;
    model.images = images;
    for (auto& [image_id, image] : model.images) image.registered = true;
    model.images[1].points2D[0].point3D_id = 1;
    model.images[2].points2D[0].point3D_id = 1;
    model.images[1].points2D[1].point3D_id = 2;
    model.points3D[1].track = {{1, 0}, {2, 0}};
    model.points3D[2].track = {{1, 1}};
    return model;
  }

  std::map<camera_t, Camera> cameras;
  std::map<image_t, Image> images;
};

// The images are gone once sampled: the model is coloured from the samples alone, as it
// would have been from the files.
TEST(KeypointColorSampler, ColoursAModelWithoutReadingTheImagesAgain) {
  testing::TemporaryDir dir;
  const TwoImages scene(dir.path());
  KeypointColorSampler sampler(dir.path(), scene.images, scene.cameras, size_t{1} << 20);
  sampler.Wait();
  EXPECT_EQ(sampler.num_sampled(), 2u);
  std::filesystem::remove(dir.path() / "a.png");
  std::filesystem::remove(dir.path() / "b.png");
  Reconstruction model = scene.Model();
  EXPECT_TRUE(ColorPointsFromImages(dir.path(), &model, 1, &sampler).empty());
  EXPECT_EQ(model.points3D[1].color, (Eigen::Matrix<uint8_t, 3, 1>(128, 128, 0)));
  EXPECT_EQ(model.points3D[2].color, (Eigen::Matrix<uint8_t, 3, 1>(0, 0, 255)));
}

// Over the budget, or with other keypoints than those sampled, an image is read again:
// here it is gone, and named.
TEST(KeypointColorSampler, ReadsAgainWhatItDidNotSampleOrSampledOtherwise) {
  testing::TemporaryDir dir;
  const TwoImages scene(dir.path());
  // Room for image a's samples only.
  KeypointColorSampler sampler(dir.path(), scene.images, scene.cameras,
                               2 * sizeof(Eigen::Vector3d));
  sampler.Wait();
  EXPECT_EQ(sampler.num_sampled(), 1u);
  std::filesystem::remove(dir.path() / "b.png");
  Reconstruction model = scene.Model();
  std::vector<std::string> warnings = ColorPointsFromImages(dir.path(), &model, 1, &sampler);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("b.png"), std::string::npos) << warnings[0];
  EXPECT_EQ(model.points3D[1].color, (Eigen::Matrix<uint8_t, 3, 1>(255, 0, 0)));  // a alone

  model = scene.Model();
  model.images[1].points2D[1].xy.x() += 1;  // not the keypoints sampled
  std::filesystem::remove(dir.path() / "a.png");
  warnings = ColorPointsFromImages(dir.path(), &model, 1, &sampler);
  ASSERT_EQ(warnings.size(), 2u);
  EXPECT_NE(warnings[0].find("a.png"), std::string::npos) << warnings[0];
}

TEST(KeypointColorSampler, AnUnreadableImageIsLeftOutAndStopEndsTheThreadEarly) {
  testing::TemporaryDir dir;
  TwoImages scene(dir.path());
  scene.images[2].name = "missing.png";
  KeypointColorSampler sampler(dir.path(), scene.images, scene.cameras, size_t{1} << 20);
  sampler.Wait();
  sampler.Stop();  // after Wait, and twice: nothing left to stop
  EXPECT_NE(sampler.Samples(scene.images.at(1)), nullptr);
  EXPECT_EQ(sampler.Samples(scene.images.at(2)), nullptr);
  // Stopped at once: at most the image it had begun.
  KeypointColorSampler stopped(dir.path(), scene.images, scene.cameras, size_t{1} << 20);
  stopped.Stop();
  EXPECT_LE(stopped.num_sampled(), 1u);
}

}  // namespace
}  // namespace tessera
