// AKAZE keypoints with binary MLDB descriptors (OpenCV), as a third party would write
// a Tessera detector: one file, the SDK headers, its options listed once
// (tessera/option_list.h), and TESSERA_PLUGIN_OPTIONS and TESSERA_PLUGIN at the end.

#include <algorithm>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "tessera/sdk.h"

namespace {

struct AkazeOptions {
  // OpenCV's detector response threshold: larger keeps fewer, stronger keypoints.
  double threshold = 0.001;
  int max_num_features = 8192;
  // Detect on a copy downscaled (area averaging) so that its longer side is at most this.
  int max_image_size = 2000;
};

// The options, listed once: read by the constructor and described by
// TESSERA_PLUGIN_OPTIONS below (`tessera plugins akaze`).
template <typename Visit>
void VisitAkazeOptions(AkazeOptions& o, const Visit& visit) {
  visit("threshold", o.threshold, 1e-6, 1.0,
        "detector response threshold; larger keeps fewer, stronger keypoints");
  visit("max_num_features", o.max_num_features, 1, 1000000,
        "keep at most this many keypoints, the strongest");
  visit("max_image_size", o.max_image_size, 16, 100000,
        "detect on a copy downscaled so that its longer side is at most this");
}

class AkazeDetector : public tessera::Detector {
 public:
  explicit AkazeDetector(const nlohmann::json& options) {
    tessera::OptionReader reader(options);
    AkazeOptions parsed;
    VisitAkazeOptions(parsed, tessera::option_list::Reader(&reader));
    threshold_ = parsed.threshold;
    max_num_features_ = parsed.max_num_features;
    max_image_size_ = parsed.max_image_size;
    reader.Finish();
    effective_options_ = reader.Effective();
  }

  tessera::FeatureSet Detect(const tessera::ImageView& image) const override {
    const cv::Mat full(image.height, image.width, CV_8UC1, const_cast<uint8_t*>(image.data),
                       image.stride);
    const double scale =
        std::min(1.0, static_cast<double>(max_image_size_) / std::max(image.width, image.height));
    cv::Mat work = full;
    if (scale < 1.0) cv::resize(full, work, cv::Size(), scale, scale, cv::INTER_AREA);

    // One detector per call: Detect runs on several threads at once.
    auto akaze =
        cv::AKAZE::create(cv::AKAZE::DESCRIPTOR_MLDB, 0, 3, static_cast<float>(threshold_));
    std::vector<cv::KeyPoint> keypoints;
    cv::Mat descriptors;
    akaze->detectAndCompute(work, cv::noArray(), keypoints, descriptors);

    std::vector<int> order(keypoints.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
    std::stable_sort(order.begin(), order.end(),
                     [&](int a, int b) { return keypoints[a].response > keypoints[b].response; });
    if (order.size() > static_cast<size_t>(max_num_features_)) order.resize(max_num_features_);

    tessera::FeatureSet features;
    features.descriptors.metric = tessera::DescriptorMetric::kHamming;
    features.descriptors.data.resize(static_cast<Eigen::Index>(order.size()), descriptors.cols);
    const double to_full = 1.0 / scale;
    for (size_t k = 0; k < order.size(); ++k) {
      const cv::KeyPoint& kp = keypoints[order[k]];
      // OpenCV puts pixel centres at integers, Tessera (like COLMAP) at +0.5.
      features.keypoints.emplace_back(static_cast<float>((kp.pt.x + 0.5) * to_full),
                                      static_cast<float>((kp.pt.y + 0.5) * to_full),
                                      static_cast<float>(kp.size / 2 * to_full),
                                      static_cast<float>(kp.angle * CV_PI / 180.0));
      std::copy_n(descriptors.ptr<uint8_t>(order[k]), descriptors.cols,
                  features.descriptors.data.row(static_cast<Eigen::Index>(k)).data());
    }
    return features;
  }

  tessera::DescriptorMetric Metric() const override { return tessera::DescriptorMetric::kHamming; }

 private:
  double threshold_;
  int max_num_features_;
  int max_image_size_;
};

}  // namespace

TESSERA_PLUGIN_OPTIONS(AkazeOptions, VisitAkazeOptions)
TESSERA_PLUGIN(detector, AkazeDetector, "akaze", "1.0.0",
               "AKAZE keypoints with binary MLDB descriptors (OpenCV), an out-of-tree example")
