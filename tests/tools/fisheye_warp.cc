// Warps photos taken with a known pinhole camera (K.txt) into the images an
// OPENCV_FISHEYE camera of the same size would have taken from the same place (tests of
// fisheye cameras): for every output pixel, the fisheye camera's ray is projected with K
// and the photo sampled there (bilinear).
// usage: tessera_test_fisheye IMAGE_DIR K.txt OUT_DIR fx fy cx cy k1 k2 k3 k4

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "tessera/camera.h"

int main(int argc, char** argv) {
  if (argc != 12) {
    std::fprintf(stderr, "usage: %s IMAGE_DIR K.txt OUT_DIR fx fy cx cy k1 k2 k3 k4\n", argv[0]);
    return 2;
  }
  double K[9];
  std::ifstream k_file(argv[2]);
  for (double& value : K) {
    if (!(k_file >> value)) {
      std::fprintf(stderr, "%s: expected 9 numbers\n", argv[2]);
      return 2;
    }
  }
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(argv[1])) {
    if (entry.path().extension() == ".jpg" || entry.path().extension() == ".png") {
      files.push_back(entry.path());
    }
  }
  std::sort(files.begin(), files.end());
  std::filesystem::create_directories(argv[3]);
  cv::Mat map_x, map_y;
  for (const auto& file : files) {
    const cv::Mat photo = cv::imread(file.string(), cv::IMREAD_COLOR);
    if (photo.empty()) {
      std::fprintf(stderr, "%s: cannot decode\n", file.c_str());
      return 1;
    }
    if (map_x.empty()) {
      tessera::Camera fisheye = tessera::Camera::Create(1, tessera::CameraModelId::kOpenCVFisheye,
                                                        1, photo.cols, photo.rows);
      for (int i = 0; i < 8; ++i) fisheye.params[i] = std::stod(argv[4 + i]);
      map_x.create(photo.rows, photo.cols, CV_32FC1);
      map_y.create(photo.rows, photo.cols, CV_32FC1);
      for (int row = 0; row < photo.rows; ++row) {
        for (int col = 0; col < photo.cols; ++col) {
          const Eigen::Vector2d uv = fisheye.CamFromImg(Eigen::Vector2d(col + 0.5, row + 0.5));
          map_x.at<float>(row, col) = static_cast<float>(K[0] * uv.x() + K[2] - 0.5);
          map_y.at<float>(row, col) = static_cast<float>(K[4] * uv.y() + K[5] - 0.5);
        }
      }
    }
    cv::Mat warped;
    cv::remap(photo, warped, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT,
              cv::Scalar::all(0));
    cv::imwrite((std::filesystem::path(argv[3]) / file.filename()).string(), warped,
                {cv::IMWRITE_JPEG_QUALITY, 95});
  }
  std::printf("%zu images warped\n", files.size());
  return 0;
}
