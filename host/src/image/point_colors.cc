#include "image/point_colors.h"

#include <Eigen/Core>
#include <map>
#include <opencv2/core.hpp>

#include "image/image_io.h"
#include "tessera/errors.h"

namespace tessera {
namespace {

// Bilinear sample of a BGR image at a keypoint position; keypoints follow COLMAP's
// convention that the centre of the top-left pixel is (0.5, 0.5).
bool SampleBgr(const cv::Mat& image, const Eigen::Vector2d& xy, Eigen::Vector3d* rgb) {
  const double x = xy.x() - 0.5;
  const double y = xy.y() - 0.5;
  if (x < 0 || y < 0 || x > image.cols - 1 || y > image.rows - 1) return false;
  const int x0 = std::min(static_cast<int>(x), image.cols - 2 < 0 ? 0 : image.cols - 2);
  const int y0 = std::min(static_cast<int>(y), image.rows - 2 < 0 ? 0 : image.rows - 2);
  const int x1 = std::min(x0 + 1, image.cols - 1);
  const int y1 = std::min(y0 + 1, image.rows - 1);
  const double fx = x - x0;
  const double fy = y - y0;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  const auto add = [&](int px, int py, double weight) {
    const cv::Vec3b& bgr = image.at<cv::Vec3b>(py, px);
    sum += weight * Eigen::Vector3d(bgr[2], bgr[1], bgr[0]);
  };
  add(x0, y0, (1 - fx) * (1 - fy));
  add(x1, y0, fx * (1 - fy));
  add(x0, y1, (1 - fx) * fy);
  add(x1, y1, fx * fy);
  *rgb = sum;
  return true;
}

}  // namespace

std::vector<std::string> ColorPointsFromImages(const std::filesystem::path& image_dir,
                                               Reconstruction* reconstruction) {
  std::vector<std::string> warnings;
  std::map<point3D_t, std::pair<Eigen::Vector3d, int>> sums;
  for (const auto& [image_id, image] : reconstruction->images) {
    cv::Mat bgr;
    try {
      bgr = ReadColorImage(image_dir / image.name);
    } catch (const InputError& error) {
      warnings.push_back(std::string(error.what()) + "; its points are coloured from the others");
      continue;
    }
    for (const Point2D& point2D : image.points2D) {
      if (!point2D.HasPoint3D()) continue;
      Eigen::Vector3d rgb;
      if (!SampleBgr(bgr, point2D.xy, &rgb)) continue;
      // Eigen leaves a default-constructed vector uninitialised: start from zero.
      auto [it, inserted] =
          sums.try_emplace(point2D.point3D_id, Eigen::Vector3d::Zero(), 0);
      auto& [sum, count] = it->second;
      sum += rgb;
      ++count;
    }
  }
  for (const auto& [point3D_id, sum_count] : sums) {
    const auto it = reconstruction->points3D.find(point3D_id);
    if (it == reconstruction->points3D.end() || sum_count.second == 0) continue;
    const Eigen::Vector3d mean = sum_count.first / sum_count.second;
    for (int c = 0; c < 3; ++c) {
      it->second.color[c] = static_cast<uint8_t>(std::clamp(std::round(mean[c]), 0.0, 255.0));
    }
  }
  return warnings;
}

}  // namespace tessera
