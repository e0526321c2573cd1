// Exact nearest neighbours (OpenCV BFMatcher, L2 for float-like descriptors, Hamming for
// binary ones) kept only when Lowe's ratio test passes in BOTH directions: a -> b must be
// distinctive among image 2's descriptors and b -> a among image 1's, and each must be
// the other's nearest neighbour. Stricter than a one-sided ratio test with cross check
// on repetitive texture (windows, tiles), where a descriptor of image 2 can be the
// mutual best of a row of image 1 yet have a near twin in image 1. As a third party
// would write a Tessera matcher: one file, the SDK headers (match_filter.h for the
// shared options and filter), and TESSERA_PLUGIN at the end.
//
// Options: ratio (0.8), cross_check (true; implied by symmetric), max_distance (0: off),
// symmetric (true; false gives the one-sided test of the bundled brute_force matcher).

#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <vector>

#include "tessera/match_filter.h"
#include "tessera/sdk.h"

namespace {

// Rows of `descriptors` as a cv::Mat BFMatcher can read: bytes for Hamming, floats for L2.
cv::Mat ToMat(const tessera::FeatureDescriptors& descriptors) {
  const cv::Mat bytes(static_cast<int>(descriptors.size()),
                      static_cast<int>(descriptors.dimension()), CV_8U,
                      const_cast<uint8_t*>(descriptors.data.data()));  // read only
  if (descriptors.metric == tessera::DescriptorMetric::kHamming) return bytes;
  cv::Mat floats;
  bytes.convertTo(floats, CV_32F);
  return floats;
}

// The two nearest train rows of each query row.
tessera::NearestNeighbors TwoNearest(const cv::BFMatcher& matcher, const cv::Mat& query,
                                     const cv::Mat& train) {
  std::vector<std::vector<cv::DMatch>> knn;
  matcher.knnMatch(query, train, knn, 2);
  tessera::NearestNeighbors neighbors(static_cast<size_t>(query.rows));
  for (const std::vector<cv::DMatch>& row : knn) {
    if (row.empty()) continue;
    const size_t i = static_cast<size_t>(row[0].queryIdx);
    neighbors.best[i] = row[0].trainIdx;
    neighbors.best_distance[i] = row[0].distance;
    if (row.size() > 1) {
      neighbors.second[i] = row[1].trainIdx;
      neighbors.second_distance[i] = row[1].distance;
    }
  }
  return neighbors;
}

class SymmetricRatioMatcher : public tessera::Matcher {
 public:
  explicit SymmetricRatioMatcher(const nlohmann::json& options) {
    tessera::OptionReader reader(options);
    filter_ = tessera::ReadMatchFilterOptions(reader);
    symmetric_ = reader.GetBool("symmetric", true);
    reader.Finish();
    if (symmetric_ && !filter_.cross_check) {
      throw tessera::OptionError(reader.KeyPath("cross_check"),
                                 "= false contradicts symmetric = true, which requires mutual "
                                 "nearest neighbours; set symmetric to false as well");
    }
    effective_options_ = reader.Effective();
  }

  tessera::FeatureMatches Match(const tessera::FeatureDescriptors& descriptors1,
                                const tessera::FeatureDescriptors& descriptors2) const override {
    if (descriptors1.size() == 0 || descriptors2.size() == 0) return {};
    tessera::CheckDescriptorsMatchable(descriptors1, descriptors2);
    tessera::FeatureMatches matches;
    // The host matches pairs on its own threads: a one-stripe parallel_for_ runs inline,
    // and BFMatcher's parallel_for_ nested in it does too, so no OpenCV pool is woken.
    cv::parallel_for_(cv::Range(0, 1), [&](const cv::Range&) {
      const cv::Mat mat1 = ToMat(descriptors1);
      const cv::Mat mat2 = ToMat(descriptors2);
      const cv::BFMatcher matcher(descriptors1.metric == tessera::DescriptorMetric::kHamming
                                      ? cv::NORM_HAMMING
                                      : cv::NORM_L2);
      const tessera::NearestNeighbors forward = TwoNearest(matcher, mat1, mat2);
      tessera::NearestNeighbors backward;
      if (filter_.cross_check) backward = TwoNearest(matcher, mat2, mat1);
      for (const tessera::FeatureMatch& match :
           tessera::FilterMatches(filter_, forward, backward, descriptors2.size())) {
        // The cross check made a the nearest neighbour of b; symmetric also asks that
        // a be distinctive among image 1's rows.
        if (symmetric_ && !tessera::PassesRatioAndDistance(filter_, backward, match.point2D_idx2,
                                                           descriptors1.size())) {
          continue;
        }
        matches.push_back(match);
      }
    });
    return matches;
  }

 private:
  tessera::MatchFilterOptions filter_;
  bool symmetric_ = true;
};

}  // namespace

TESSERA_PLUGIN(matcher, SymmetricRatioMatcher, "symmetric_ratio", "1.0.0",
               "Exact nearest neighbours (OpenCV BFMatcher) with Lowe's ratio test in both "
               "directions, an out-of-tree example")
