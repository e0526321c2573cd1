#include "image/image_masks.h"

#include <xxhash.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>

#include "tessera/errors.h"
#include "tessera/io/file_io.h"

namespace tessera {

std::filesystem::path FindMaskFile(const std::filesystem::path& mask_dir, const std::string& name) {
  std::error_code error;
  const std::filesystem::path colmap = mask_dir / (name + ".png");
  if (std::filesystem::is_regular_file(colmap, error)) return colmap;
  std::filesystem::path replaced = mask_dir / name;
  replaced.replace_extension(".png");
  if (std::filesystem::is_regular_file(replaced, error)) return replaced;
  return {};
}

ImageMasks FindImageMasks(const std::filesystem::path& mask_dir,
                          const std::vector<std::string>& image_names) {
  std::error_code error;
  if (!std::filesystem::is_directory(mask_dir, error)) {
    throw InputError(mask_dir.string() + ": no such mask folder");
  }
  ImageMasks masks;
  masks.folder = mask_dir;
  XXH3_state_t* state = XXH3_createState();
  XXH3_128bits_reset(state);
  for (const std::string& name : image_names) {
    const std::filesystem::path file = FindMaskFile(mask_dir, name);
    if (file.empty()) {
      masks.missing.push_back(name);
      continue;
    }
    masks.files[name] = file;
    const std::string bytes = ReadFileContents(file);
    XXH3_128bits_update(state, name.data(), name.size() + 1);  // with its terminating 0
    XXH3_128bits_update(state, bytes.data(), bytes.size());
  }
  const XXH128_hash_t hash = XXH3_128bits_digest(state);
  XXH3_freeState(state);
  char hex[33];
  std::snprintf(hex, sizeof(hex), "%016llx%016llx", static_cast<unsigned long long>(hash.high64),
                static_cast<unsigned long long>(hash.low64));
  masks.digest = hex;
  return masks;
}

std::optional<cv::Mat> ReadMask(const std::filesystem::path& file, int width, int height,
                                std::string* problem) {
  cv::Mat mask;
  try {
    mask = cv::imread(file.string(), cv::IMREAD_GRAYSCALE);
  } catch (const cv::Exception&) {
    mask.release();
  }
  if (mask.empty()) {
    *problem = "its mask " + file.string() + " cannot be decoded";
    return std::nullopt;
  }
  if (mask.cols != width || mask.rows != height) {
    *problem = "its mask " + file.string() + " is " + std::to_string(mask.cols) + "x" +
               std::to_string(mask.rows) + ", the image " + std::to_string(width) + "x" +
               std::to_string(height);
    return std::nullopt;
  }
  return mask;
}

size_t RemoveMaskedFeatures(const cv::Mat& mask, FeatureSet* features) {
  const size_t n = features->keypoints.size();
  std::vector<Eigen::Index> kept;
  kept.reserve(n);
  for (size_t i = 0; i < n; ++i) {
    // Origin at the top-left pixel's corner: pixel (floor x, floor y) holds the point.
    const auto clamp = [](float v, int size) {
      return std::clamp(static_cast<int>(std::floor(v)), 0, size - 1);
    };
    const int col = clamp(features->keypoints[i].x, mask.cols);
    const int row = clamp(features->keypoints[i].y, mask.rows);
    if (mask.at<uint8_t>(row, col) != 0) kept.push_back(static_cast<Eigen::Index>(i));
  }
  if (kept.size() == n) return 0;
  FeatureKeypoints keypoints;
  keypoints.reserve(kept.size());
  FeatureDescriptors::Matrix descriptors(static_cast<Eigen::Index>(kept.size()),
                                         features->descriptors.dimension());
  for (size_t k = 0; k < kept.size(); ++k) {
    keypoints.push_back(features->keypoints[kept[k]]);
    if (features->descriptors.size() > 0) {
      descriptors.row(static_cast<Eigen::Index>(k)) = features->descriptors.data.row(kept[k]);
    }
  }
  features->keypoints = std::move(keypoints);
  if (features->descriptors.size() > 0) features->descriptors.data = std::move(descriptors);
  return n - kept.size();
}

}  // namespace tessera
