#include "tessera/io/point_colors.h"

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

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

}  // namespace
}  // namespace tessera
