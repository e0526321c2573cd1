// Exact nearest neighbours by brute force (cv::BFMatcher), filtered by Lowe's ratio
// test, an optional absolute distance threshold and a mutual-best (cross) check.
// O(n1 n2 d) per pair; the reference against which approximate matchers are judged.

#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <string>

#include "tessera/match_filter.h"
#include "tessera/sdk.h"

namespace tessera {
namespace {

cv::Mat WrapDescriptors(const FeatureDescriptors& descriptors) {
  // cv::Mat does not copy here and we never write through it.
  cv::Mat bytes(static_cast<int>(descriptors.size()), static_cast<int>(descriptors.dimension()),
                CV_8U, const_cast<uint8_t*>(descriptors.data.data()));
  if (descriptors.metric == DescriptorMetric::kHamming) return bytes;
  cv::Mat floats;
  bytes.convertTo(floats, CV_32F);  // BFMatcher's NORM_L2 needs float descriptors
  return floats;
}

NearestNeighbors FindNeighbors(const cv::BFMatcher& matcher, const cv::Mat& query,
                               const cv::Mat& train, int k) {
  std::vector<std::vector<cv::DMatch>> knn;
  matcher.knnMatch(query, train, knn, k);
  NearestNeighbors neighbors(static_cast<size_t>(query.rows));
  for (const std::vector<cv::DMatch>& row : knn) {
    if (row.empty()) continue;
    const int query_idx = row[0].queryIdx;
    neighbors.best[query_idx] = row[0].trainIdx;
    neighbors.best_distance[query_idx] = row[0].distance;
    if (row.size() > 1) {
      neighbors.second[query_idx] = row[1].trainIdx;
      neighbors.second_distance[query_idx] = row[1].distance;
    }
  }
  return neighbors;
}

}  // namespace

class BruteForceMatcher : public Matcher {
 public:
  explicit BruteForceMatcher(const nlohmann::json& options) {
    OptionReader reader(options);
    options_ = ReadMatchFilterOptions(reader);
    reader.Finish();
    effective_options_ = reader.Effective();
  }

  FeatureMatches Match(const FeatureDescriptors& descriptors1,
                       const FeatureDescriptors& descriptors2) const override {
    // An image without features has nothing to match, whatever its declared metric.
    if (descriptors1.size() == 0 || descriptors2.size() == 0) return {};
    CheckDescriptorsMatchable(descriptors1, descriptors2);

    FeatureMatches matches;
    // The host runs pairs in parallel, so this call must stay on its thread. OpenCV runs
    // a parallel_for_ nested in another one inline; a one-stripe loop runs inline too. So
    // BFMatcher's own parallel_for_ inside this one does not fan out to OpenCV's pool.
    cv::parallel_for_(cv::Range(0, 1), [&](const cv::Range&) {
      const cv::Mat mat1 = WrapDescriptors(descriptors1);
      const cv::Mat mat2 = WrapDescriptors(descriptors2);
      const cv::BFMatcher matcher(
          descriptors1.metric == DescriptorMetric::kHamming ? cv::NORM_HAMMING : cv::NORM_L2,
          /*crossCheck=*/false);
      const NearestNeighbors forward = FindNeighbors(matcher, mat1, mat2, 2);
      NearestNeighbors backward;
      if (options_.cross_check) backward = FindNeighbors(matcher, mat2, mat1, 1);
      matches = FilterMatches(options_, forward, backward, descriptors2.size());
    });
    return matches;
  }

 private:
  // Ratio test, distance threshold and cross check: this matcher's only options.
  MatchFilterOptions options_;
};

}  // namespace tessera

// Its options are the match filter's alone.
TESSERA_PLUGIN_OPTIONS(tessera::MatchFilterOptions, tessera::VisitMatchFilterOptions)
TESSERA_PLUGIN(matcher, tessera::BruteForceMatcher, "brute_force", "1.0.0",
               "Exact nearest neighbours (OpenCV BFMatcher) with ratio test and cross check")
