// SIFT keypoints and descriptors from OpenCV, converted to COLMAP's conventions:
// keypoints with the top-left pixel's centre at (0.5, 0.5), descriptors as uint8 rows
// scaled by 512 (RootSIFT by default), so that they are interchangeable with the
// features COLMAP writes to its database.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
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

constexpr int kDescriptorDimension = 128;

// OpenCV 4.6 doubles the image with INTER_LINEAR before the first octave, which puts
// upsampled pixel j at original position j / 2 - 0.25 while SIFT reports j / 2: every
// keypoint is 0.25 px too far right and down (opencv/opencv#23123; OpenCV 4.8 adds
// `enable_precise_upscale` for this). Measured on symmetric blobs: 0.24 to 0.29 px.
constexpr double kOpenCvUpscaleBias = 0.25;

struct SiftOptions {
  // Keep at most this many keypoints, the strongest by DoG response.
  int max_num_features = 8192;
  // Downscale (area averaging) so that the longer side is at most this many pixels.
  int max_image_size = 3200;
  // OpenCV's contrast threshold; 0.02 equals COLMAP's peak threshold of 0.02 / 3.
  double contrast_threshold = 0.02;
  // Largest ratio of principal curvatures of a kept DoG extremum (COLMAP: 10).
  double edge_threshold = 10;
  // DoG layers per octave (COLMAP's octave_resolution).
  int num_octave_layers = 3;
  // Blur of the first octave's base image.
  double sigma = 1.6;
  // RootSIFT descriptors (L1-normalise, then square root), as COLMAP's default.
  bool root_sift = true;
  // Detection that adapts to weak texture: an image with fewer keypoints than this is
  // detected again with the contrast threshold halved, down to min_contrast_threshold.
  // 0: off.
  int min_num_features = 0;
  double min_contrast_threshold = 0.0025;
};

// The options, listed once: read, checked and described (`tessera plugins sift`) from here.
template <typename Visit>
void VisitSiftOptions(SiftOptions& o, const Visit& visit) {
  visit("max_num_features", o.max_num_features, 1, 1000000,
        "keep at most this many keypoints, the strongest by DoG response");
  visit("max_image_size", o.max_image_size, 16, 100000,
        "if the longer side is larger, detect on a copy downscaled with area averaging to this "
        "size; keypoints are still reported in full-resolution pixels");
  visit("contrast_threshold", o.contrast_threshold, 0.0, 1.0,
        "OpenCV's contrast threshold: a DoG extremum is kept when |D| >= contrast_threshold / "
        "num_octave_layers, with D on the [0, 1] grey scale");
  visit("edge_threshold", o.edge_threshold, 1.0, 1000.0,
        "largest ratio of principal curvatures of a kept extremum; smaller rejects more edge "
        "responses");
  visit("num_octave_layers", o.num_octave_layers, 1, 10,
        "DoG layers per octave, COLMAP's octave_resolution");
  visit("sigma", o.sigma, 0.5, 10.0, "Gaussian blur of the base of the first octave");
  visit("root_sift", o.root_sift,
        "RootSIFT descriptors (COLMAP's default, L1_ROOT normalisation); false gives "
        "L2-normalised SIFT");
  visit("min_num_features", o.min_num_features, 0, 1000000,
        "detection that adapts to weak texture: an image with fewer keypoints than this is "
        "detected again with the contrast threshold halved, until it has enough or the "
        "threshold reaches min_contrast_threshold; 0: off");
  visit("min_contrast_threshold", o.min_contrast_threshold, 1e-6, 1.0,
        "the floor of that adaptation; only with min_num_features above 0");
}

class SiftDetector : public Detector {
 public:
  explicit SiftDetector(const nlohmann::json& options) {
    OptionReader reader(options);
    VisitSiftOptions(options_, option_list::Reader(&reader));
    reader.Finish();
    effective_options_ = reader.Effective();
    if (options_.min_num_features == 0) {
      // Off: the features are those of a detector without the option, and so is the
      // record of the options that produced them.
      if (reader.Has("min_contrast_threshold")) {
        throw OptionError("min_contrast_threshold", "is used only with min_num_features above 0");
      }
      effective_options_.erase("min_num_features");
      effective_options_.erase("min_contrast_threshold");
    }
  }

  FeatureSet Detect(const ImageView& view) const override {
    const ScaledImage scaled = ScaleToMaxSize(view, options_.max_image_size, "sift");

    std::vector<cv::KeyPoint> cv_keypoints;
    cv::Mat cv_descriptors;
    DetectWithAdaptiveThreshold(
        static_cast<size_t>(options_.min_num_features), options_.contrast_threshold,
        options_.min_contrast_threshold,
        [&](double threshold) {
          DetectAt(scaled.image, threshold, &cv_keypoints, &cv_descriptors);
          return cv_keypoints.size();
        },
        log(), "contrast threshold", "min_contrast_threshold");
    // OpenCV keeps every keypoint whose response ties with the last one kept.
    const std::vector<int> order = StrongestFirst(cv_keypoints, options_.max_num_features);

    FeatureSet features;
    features.keypoints.reserve(order.size());
    features.descriptors.metric = DescriptorMetric::kL2;
    features.descriptors.data.resize(static_cast<Eigen::Index>(order.size()), kDescriptorDimension);
    const double mean_scale = (scaled.scale_x + scaled.scale_y) / 2;
    Eigen::RowVectorXf descriptor(kDescriptorDimension);
    for (size_t row = 0; row < order.size(); ++row) {
      const cv::KeyPoint& kp = cv_keypoints[order[row]];
      // OpenCV puts pixel centres at integers, COLMAP at half-integers.
      const double x = kp.pt.x - kOpenCvUpscaleBias + 0.5;
      const double y = kp.pt.y - kOpenCvUpscaleBias + 0.5;
      features.keypoints.emplace_back(
          static_cast<float>(x * scaled.scale_x), static_cast<float>(y * scaled.scale_y),
          static_cast<float>(kp.size / 2 * mean_scale), static_cast<float>(kp.angle * CV_PI / 180));
      const float* values = cv_descriptors.ptr<float>(order[row]);
      for (int col = 0; col < kDescriptorDimension; ++col) descriptor(col) = values[col];
      features.descriptors.data.row(static_cast<Eigen::Index>(row)) = ToUnsignedByte(descriptor);
    }
    return features;
  }

  DescriptorMetric Metric() const override { return DescriptorMetric::kL2; }

 private:
  // SIFT on `image` at the contrast threshold `threshold`.
  void DetectAt(const cv::Mat& image, double threshold, std::vector<cv::KeyPoint>* keypoints,
                cv::Mat* descriptors) const {
    // A detector per call: sharing one cv::SIFT across threads is not documented as safe.
    const cv::Ptr<cv::SIFT> sift =
        cv::SIFT::create(options_.max_num_features, options_.num_octave_layers, threshold,
                         options_.edge_threshold, options_.sigma);
    keypoints->clear();
    sift->detectAndCompute(image, cv::noArray(), *keypoints, *descriptors);
  }

  // COLMAP's conversion: normalise (L2, or L1 then square root for RootSIFT), then
  // 512 times the value, rounded and clamped to [0, 255].
  Eigen::Matrix<uint8_t, 1, kDescriptorDimension> ToUnsignedByte(
      Eigen::RowVectorXf descriptor) const {
    if (options_.root_sift) {
      const float l1 = descriptor.lpNorm<1>();
      if (l1 > 0) descriptor = (descriptor / l1).cwiseSqrt();
    } else {
      const float l2 = descriptor.norm();
      if (l2 > 0) descriptor /= l2;
    }
    Eigen::Matrix<uint8_t, 1, kDescriptorDimension> bytes;
    for (int col = 0; col < kDescriptorDimension; ++col) {
      const float value = std::round(512.0f * descriptor(col));
      bytes(col) = static_cast<uint8_t>(std::clamp(value, 0.0f, 255.0f));
    }
    return bytes;
  }

  SiftOptions options_;
};

}  // namespace
}  // namespace tessera

TESSERA_PLUGIN_OPTIONS(tessera::SiftOptions, tessera::VisitSiftOptions)
TESSERA_PLUGIN(detector, tessera::SiftDetector, "sift", "1.0.0",
               "SIFT keypoints and (Root)SIFT descriptors from OpenCV, in COLMAP's conventions")
