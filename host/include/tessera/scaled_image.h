#pragma once

// For detectors built on OpenCV (header only): the image a detector works on, downscaled
// to its max_image_size, and the factors that bring keypoints back to full resolution.
// The SDK itself does not depend on OpenCV and sdk.h does not include this header: a
// plugin that includes it links OpenCV (core and imgproc) itself.

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "tessera/errors.h"
#include "tessera/image_view.h"

namespace tessera {

struct ScaledImage {
  cv::Mat image;
  double scale_x = 1;  // full-resolution pixels per working pixel, horizontally
  double scale_y = 1;  // and vertically
};

// `view` scaled by area averaging so that its longer side is at most `max_image_size`
// pixels; the view itself, not copied, when it is small enough already. `detector` names
// the plugin in the InputError about an empty or malformed view.
inline ScaledImage ScaleToMaxSize(const ImageView& view, int max_image_size,
                                  const std::string& detector) {
  if (view.data == nullptr || view.width <= 0 || view.height <= 0 ||
      view.stride < static_cast<size_t>(view.width)) {
    throw InputError(detector + ": cannot detect features in an empty or malformed image view (" +
                     std::to_string(view.width) + "x" + std::to_string(view.height) + ")");
  }
  // The view is only read: OpenCV's Mat has no const-data constructor.
  const cv::Mat full(view.height, view.width, CV_8UC1, const_cast<uint8_t*>(view.data),
                     view.stride);
  ScaledImage scaled;
  const int long_side = std::max(view.width, view.height);
  if (long_side <= max_image_size) {
    scaled.image = full;
    return scaled;
  }
  const double factor = static_cast<double>(max_image_size) / long_side;
  const int width = std::max(1, static_cast<int>(std::lround(view.width * factor)));
  const int height = std::max(1, static_cast<int>(std::lround(view.height * factor)));
  cv::resize(full, scaled.image, cv::Size(width, height), 0, 0, cv::INTER_AREA);
  scaled.scale_x = static_cast<double>(view.width) / width;
  scaled.scale_y = static_cast<double>(view.height) / height;
  return scaled;
}

}  // namespace tessera
