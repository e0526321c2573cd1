#include "tessera/io/point_colors.h"

#include <Eigen/Core>
#include <algorithm>
#include <atomic>
#include <exception>
#include <map>
#include <mutex>
#include <opencv2/core.hpp>
#include <string>
#include <thread>
#include <utility>

#include "keypoint_color_sampler.h"
#include "tessera/errors.h"
#include "tessera/io/image_io.h"

namespace tessera {
namespace {

// Bilinear colour at a keypoint position, clamped to the image; keypoints follow
// COLMAP's convention that the centre of the top-left pixel is (0.5, 0.5).
Eigen::Vector3d InterpolateRgb(const cv::Mat& image, const Eigen::Vector2d& xy) {
  const double x = std::clamp(xy.x() - 0.5, 0.0, image.cols - 1.0);
  const double y = std::clamp(xy.y() - 0.5, 0.0, image.rows - 1.0);
  const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  const int x1 = std::min(x0 + 1, image.cols - 1), y1 = std::min(y0 + 1, image.rows - 1);
  const double wx = x - x0, wy = y - y0;
  Eigen::Vector3d rgb = Eigen::Vector3d::Zero();
  const auto add = [&](int row, int col, double weight) {
    const cv::Vec3b& bgr = image.at<cv::Vec3b>(row, col);
    rgb += weight * Eigen::Vector3d(bgr[2], bgr[1], bgr[0]);
  };
  add(y0, x0, (1 - wx) * (1 - wy));
  add(y0, x1, wx * (1 - wy));
  add(y1, x0, (1 - wx) * wy);
  add(y1, x1, wx * wy);
  return rgb;
}

// The colour samples of one image's observations, or why it has none.
struct ImageSamples {
  std::vector<std::pair<point3D_t, Eigen::Vector3d>> samples;
  std::string warning;
};

// The bgr image's size against its camera's: empty when they agree, else the warning.
std::string SizeProblem(const std::filesystem::path& path, const cv::Mat& bgr, const Image& image,
                        const std::map<camera_t, Camera>& cameras) {
  const auto camera_it = cameras.find(image.camera_id);
  if (camera_it == cameras.end() || (static_cast<size_t>(bgr.cols) == camera_it->second.width &&
                                     static_cast<size_t>(bgr.rows) == camera_it->second.height)) {
    return "";
  }
  return path.string() + ": the image is " + std::to_string(bgr.cols) + "x" +
         std::to_string(bgr.rows) + " but its camera " + std::to_string(image.camera_id) + " is " +
         std::to_string(camera_it->second.width) + "x" + std::to_string(camera_it->second.height) +
         "; colours cannot be sampled";
}

ImageSamples SampleImage(const std::filesystem::path& image_dir, const Image& image,
                         const Reconstruction& reconstruction,
                         const KeypointColorSampler* sampler) {
  ImageSamples result;
  const std::vector<Eigen::Vector3d>* presampled =
      sampler != nullptr ? sampler->Samples(image) : nullptr;
  if (presampled != nullptr) {
    for (size_t idx = 0; idx < image.points2D.size(); ++idx) {
      const Point2D& point2D = image.points2D[idx];
      if (point2D.HasPoint3D() && reconstruction.points3D.count(point2D.point3D_id) > 0) {
        result.samples.emplace_back(point2D.point3D_id, (*presampled)[idx]);
      }
    }
    return result;
  }
  const std::filesystem::path path = image_dir / image.name;
  cv::Mat bgr;
  try {
    bgr = ReadColorImage(path);
  } catch (const InputError& error) {
    result.warning = error.what();
    return result;
  }
  result.warning = SizeProblem(path, bgr, image, reconstruction.cameras);
  if (!result.warning.empty()) return result;
  for (const Point2D& point2D : image.points2D) {
    if (!point2D.HasPoint3D() || reconstruction.points3D.count(point2D.point3D_id) == 0) {
      continue;
    }
    result.samples.emplace_back(point2D.point3D_id, InterpolateRgb(bgr, point2D.xy));
  }
  return result;
}

// SampleImage for each image, on up to `num_threads` threads (0: one per core; decoding
// is most of the time); results in the order of `images`.
std::vector<ImageSamples> SampleImages(const std::filesystem::path& image_dir,
                                       const std::vector<const Image*>& images,
                                       const Reconstruction& reconstruction, int num_threads,
                                       const KeypointColorSampler* sampler) {
  std::vector<ImageSamples> results(images.size());
  std::atomic<size_t> next{0};
  std::exception_ptr failure;
  std::mutex failure_mutex;
  const auto work = [&] {
    for (size_t k = next++; k < images.size(); k = next++) {
      try {
        results[k] = SampleImage(image_dir, *images[k], reconstruction, sampler);
      } catch (...) {
        const std::lock_guard<std::mutex> lock(failure_mutex);
        if (!failure) failure = std::current_exception();
      }
    }
  };
  const size_t max_threads = num_threads > 0 ? static_cast<size_t>(num_threads)
                                             : std::max(1u, std::thread::hardware_concurrency());
  std::vector<std::thread> threads;
  for (size_t t = 1; t < std::min(images.size(), max_threads); ++t) threads.emplace_back(work);
  work();
  for (std::thread& thread : threads) thread.join();
  if (failure) std::rethrow_exception(failure);
  return results;
}

}  // namespace

std::vector<std::string> ColorPointsFromImages(const std::filesystem::path& image_dir,
                                               Reconstruction* reconstruction, int num_threads) {
  return ColorPointsFromImages(image_dir, reconstruction, num_threads, nullptr);
}

std::vector<std::string> ColorPointsFromImages(const std::filesystem::path& image_dir,
                                               Reconstruction* reconstruction, int num_threads,
                                               const KeypointColorSampler* sampler) {
  std::vector<const Image*> images;
  for (const auto& [image_id, image] : reconstruction->images) {
    if (image.registered &&
        std::any_of(image.points2D.begin(), image.points2D.end(),
                    [](const Point2D& point2D) { return point2D.HasPoint3D(); })) {
      images.push_back(&image);
    }
  }
  // Summed in image order, as one thread would: the colours do not depend on the threads.
  std::vector<std::string> warnings;
  std::map<point3D_t, std::pair<Eigen::Vector3d, int>> sums;
  for (const ImageSamples& image_samples :
       SampleImages(image_dir, images, *reconstruction, num_threads, sampler)) {
    if (!image_samples.warning.empty()) warnings.push_back(image_samples.warning);
    for (const auto& [point3D_id, rgb] : image_samples.samples) {
      // Eigen leaves a default-constructed vector uninitialised: start from zero.
      auto [it, inserted] = sums.try_emplace(point3D_id, Eigen::Vector3d::Zero(), 0);
      it->second.first += rgb;
      ++it->second.second;
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

KeypointColorSampler::KeypointColorSampler(std::filesystem::path image_dir,
                                           const std::map<image_t, Image>& images,
                                           const std::map<camera_t, Camera>& cameras,
                                           size_t max_bytes)
    : image_dir_(std::move(image_dir)),
      images_(images),
      cameras_(cameras),
      max_bytes_(max_bytes),
      thread_([this] { Run(); }) {}

KeypointColorSampler::~KeypointColorSampler() { Stop(); }

void KeypointColorSampler::Stop() {
  stop_ = true;
  Wait();
}

void KeypointColorSampler::Wait() {
  if (thread_.joinable()) thread_.join();
}

const std::vector<Eigen::Vector3d>* KeypointColorSampler::Samples(const Image& image) const {
  const auto it = samples_.find(image.image_id);
  if (it == samples_.end()) return nullptr;
  const std::vector<Point2D>& sampled = images_.at(image.image_id).points2D;
  if (sampled.size() != image.points2D.size()) return nullptr;
  for (size_t idx = 0; idx < sampled.size(); ++idx) {
    if (sampled[idx].xy != image.points2D[idx].xy) return nullptr;
  }
  return &it->second;
}

void KeypointColorSampler::Run() {
  size_t num_bytes = 0;
  for (const auto& [image_id, image] : images_) {
    const size_t image_bytes = image.points2D.size() * sizeof(Eigen::Vector3d);
    if (stop_ || num_bytes + image_bytes > max_bytes_) return;
    if (image.points2D.empty()) continue;
    const std::filesystem::path path = image_dir_ / image.name;
    try {
      const cv::Mat bgr = ReadColorImage(path);
      if (!SizeProblem(path, bgr, image, cameras_).empty()) continue;
      std::vector<Eigen::Vector3d> rgb;
      rgb.reserve(image.points2D.size());
      for (const Point2D& point2D : image.points2D) rgb.push_back(InterpolateRgb(bgr, point2D.xy));
      samples_.emplace(image_id, std::move(rgb));
      num_bytes += image_bytes;
    } catch (...) {
      // Unreadable now: ColorPointsFromImages reads it again and names it if it still is.
    }
  }
}

}  // namespace tessera
