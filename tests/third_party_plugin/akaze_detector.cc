// AKAZE keypoints with binary MLDB descriptors (OpenCV), as a third party would write
// a Tessera detector: one file, the SDK headers, and TESSERA_PLUGIN at the end.

#include <algorithm>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "tessera/sdk.h"

namespace {

class AkazeDetector : public tessera::Detector {
 public:
  explicit AkazeDetector(const nlohmann::json& options) {
    tessera::OptionReader reader(options);
    threshold_ = reader.Get<double>("threshold", 0.001, 1e-6, 1.0);
    max_num_features_ = reader.Get<int>("max_num_features", 8192, 1, 1000000);
    max_image_size_ = reader.Get<int>("max_image_size", 2000, 16, 100000);
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

TESSERA_PLUGIN(detector, AkazeDetector, "akaze", "1.0.0",
               "AKAZE keypoints with binary MLDB descriptors (OpenCV), an out-of-tree example")
