// ORB keypoints and 256-bit binary descriptors from OpenCV, with keypoints in
// COLMAP's convention (the top-left pixel's centre at (0.5, 0.5)). Much faster than
// SIFT and less distinctive; its descriptors are compared by Hamming distance.

#include <algorithm>
#include <cmath>
#include <cstring>
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "tessera/adaptive_threshold.h"
#include "tessera/keypoint_selection.h"
#include "tessera/scaled_image.h"
#include "tessera/sdk.h"

namespace tessera {
namespace {

constexpr int kDescriptorBytes = 32;

struct OrbOptions {
  // Keep at most this many keypoints, the strongest by Harris response.
  int max_num_features = 8192;
  // Downscale (area averaging) so that the longer side is at most this many pixels.
  int max_image_size = 3200;
  // Ratio between the sizes of neighbouring pyramid levels.
  double scale_factor = 1.2;
  // Number of pyramid levels.
  int num_levels = 8;
  // FAST threshold: least grey-level difference between a corner and its ring.
  int fast_threshold = 20;
  // Border in pixels, at each level, where no keypoint is detected.
  int edge_threshold = 31;
  // Detection that adapts to weak texture: an image with fewer keypoints than this is
  // detected again with the FAST threshold halved, down to min_fast_threshold. 0: off.
  int min_num_features = 0;
  int min_fast_threshold = 2;
};

// The options, listed once: read, checked and described (`tessera plugins orb`) from here.
template <typename Visit>
void VisitOrbOptions(OrbOptions& o, const Visit& visit) {
  visit("max_num_features", o.max_num_features, 1, 1000000,
        "keep at most this many keypoints; ORB shares this quota among pyramid levels, then the "
        "strongest are kept");
  visit("max_image_size", o.max_image_size, 16, 100000,
        "if the longer side is larger, detect on a copy downscaled with area averaging to this "
        "size; keypoints are still reported in full-resolution pixels");
  visit("scale_factor", o.scale_factor, 1.01, 4.0,
        "size ratio between neighbouring pyramid levels");
  visit("num_levels", o.num_levels, 1, 32, "number of pyramid levels");
  visit("fast_threshold", o.fast_threshold, 1, 255,
        "FAST threshold: least grey-level difference between a corner and its ring of pixels");
  visit("edge_threshold", o.edge_threshold, 0, 256,
        "border in pixels, at each level, where no keypoint is detected; should be about the "
        "patch size, 31");
  visit("min_num_features", o.min_num_features, 0, 1000000,
        "detection that adapts to weak texture: an image with fewer keypoints than this is "
        "detected again with the FAST threshold halved, until it has enough or the threshold "
        "reaches min_fast_threshold; 0: off");
  visit("min_fast_threshold", o.min_fast_threshold, 1, 255,
        "the floor of that adaptation; only with min_num_features above 0");
}

// Where a keypoint of OpenCV's ORB lies, in pixels of the image ORB was given, in
// COLMAP's convention. ORB finds corners at whole pixels x_l of a pyramid level made by
// cv::resize, whose pixel centres sit at (x_l + 0.5) * width / level_width - 0.5 in the
// image, but it reports x_l * scale_factor^level: up to a few pixels off at coarse
// levels, and not symmetric under a flip of the image.
cv::Point2d OrbKeypointPosition(const cv::KeyPoint& kp, const cv::Size& image_size,
                                float scale_factor) {
  // The level's scale and size exactly as OpenCV 4.6 computes them (in float).
  const float level_scale =
      static_cast<float>(std::pow(static_cast<double>(scale_factor), kp.octave));
  const float inverse_scale = 1.f / level_scale;
  const int level_width = cvRound(image_size.width * inverse_scale);
  const int level_height = cvRound(image_size.height * inverse_scale);
  return {(kp.pt.x / level_scale + 0.5) * image_size.width / level_width,
          (kp.pt.y / level_scale + 0.5) * image_size.height / level_height};
}

class OrbDetector : public Detector {
 public:
  explicit OrbDetector(const nlohmann::json& options) {
    OptionReader reader(options);
    VisitOrbOptions(options_, option_list::Reader(&reader));
    reader.Finish();
    effective_options_ = reader.Effective();
    if (options_.min_num_features == 0) {
      // Off: the features are those of a detector without the option, and so is the
      // record of the options that produced them.
      if (reader.Has("min_fast_threshold")) {
        throw OptionError("min_fast_threshold", "is used only with min_num_features above 0");
      }
      effective_options_.erase("min_num_features");
      effective_options_.erase("min_fast_threshold");
    }
  }

  FeatureSet Detect(const ImageView& view) const override {
    const ScaledImage scaled = ScaleToMaxSize(view, options_.max_image_size, "orb");

    std::vector<cv::KeyPoint> cv_keypoints;
    cv::Mat cv_descriptors;
    DetectWithAdaptiveThreshold(
        static_cast<size_t>(options_.min_num_features), options_.fast_threshold,
        options_.min_fast_threshold,
        [&](int threshold) {
          DetectAt(scaled.image, threshold, &cv_keypoints, &cv_descriptors);
          return cv_keypoints.size();
        },
        log(), "FAST threshold", "min_fast_threshold");
    // ORB fills its quota level by level and may keep ties beyond it.
    const std::vector<int> order = StrongestFirst(cv_keypoints, options_.max_num_features);

    FeatureSet features;
    features.keypoints.reserve(order.size());
    features.descriptors.metric = DescriptorMetric::kHamming;
    features.descriptors.data.resize(static_cast<Eigen::Index>(order.size()), kDescriptorBytes);
    const double mean_scale = (scaled.scale_x + scaled.scale_y) / 2;
    const float scale_factor = static_cast<float>(options_.scale_factor);
    for (size_t row = 0; row < order.size(); ++row) {
      const cv::KeyPoint& kp = cv_keypoints[order[row]];
      const cv::Point2d position = OrbKeypointPosition(kp, scaled.image.size(), scale_factor);
      features.keypoints.emplace_back(static_cast<float>(position.x * scaled.scale_x),
                                      static_cast<float>(position.y * scaled.scale_y),
                                      static_cast<float>(kp.size / 2 * mean_scale),
                                      static_cast<float>(kp.angle * CV_PI / 180));
      std::memcpy(features.descriptors.data.row(static_cast<Eigen::Index>(row)).data(),
                  cv_descriptors.ptr<uint8_t>(order[row]), kDescriptorBytes);
    }
    return features;
  }

  DescriptorMetric Metric() const override { return DescriptorMetric::kHamming; }

 private:
  // ORB on `image` at the FAST threshold `threshold`.
  void DetectAt(const cv::Mat& image, int threshold, std::vector<cv::KeyPoint>* keypoints,
                cv::Mat* descriptors) const {
    // A detector per call: sharing one cv::ORB across threads is not documented as safe.
    const cv::Ptr<cv::ORB> orb = cv::ORB::create(
        options_.max_num_features, static_cast<float>(options_.scale_factor), options_.num_levels,
        options_.edge_threshold, /*firstLevel=*/0, /*WTA_K=*/2, cv::ORB::HARRIS_SCORE,
        /*patchSize=*/31, threshold);
    keypoints->clear();
    orb->detectAndCompute(image, cv::noArray(), *keypoints, *descriptors);
  }

  OrbOptions options_;
};

}  // namespace
}  // namespace tessera

TESSERA_PLUGIN_OPTIONS(tessera::OrbOptions, tessera::VisitOrbOptions)
TESSERA_PLUGIN(detector, tessera::OrbDetector, "orb", "1.0.0",
               "ORB keypoints and 256-bit binary descriptors from OpenCV")
