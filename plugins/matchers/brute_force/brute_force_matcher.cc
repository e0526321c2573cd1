// Exact nearest neighbours by brute force (cv::BFMatcher), filtered by Lowe's ratio
// test, an optional absolute distance threshold and a mutual-best (cross) check.
// O(n1 n2 d) per pair; the reference against which approximate matchers are judged.

#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <string>

#include "tessera/sdk.h"

namespace tessera {

struct BruteForceMatchOptions {
  // Lowe's ratio test: keep a match if best < ratio * second-best distance (not squared).
  double ratio = 0.8;
  // Keep a match a -> b only if a is also b's nearest neighbour.
  bool cross_check = true;
  // Largest distance of a kept match: Euclidean in uint8 descriptor units for l2, bits for
  // hamming. 0 turns the threshold off.
  double max_distance = 0;
};

namespace {

// Nearest neighbours of each query row among the train rows; -1 where there is none.
struct Neighbors {
  std::vector<int> best;
  std::vector<int> second;
  std::vector<float> best_distance;
  std::vector<float> second_distance;
};

cv::Mat WrapDescriptors(const FeatureDescriptors& descriptors) {
  // cv::Mat does not copy here and we never write through it.
  cv::Mat bytes(static_cast<int>(descriptors.size()), static_cast<int>(descriptors.dimension()),
                CV_8U, const_cast<uint8_t*>(descriptors.data.data()));
  if (descriptors.metric == DescriptorMetric::kHamming) return bytes;
  cv::Mat floats;
  bytes.convertTo(floats, CV_32F);  // BFMatcher's NORM_L2 needs float descriptors
  return floats;
}

Neighbors FindNeighbors(const cv::BFMatcher& matcher, const cv::Mat& query, const cv::Mat& train,
                        int k) {
  std::vector<std::vector<cv::DMatch>> knn;
  matcher.knnMatch(query, train, knn, k);
  Neighbors neighbors;
  neighbors.best.assign(query.rows, -1);
  neighbors.second.assign(query.rows, -1);
  neighbors.best_distance.assign(query.rows, 0);
  neighbors.second_distance.assign(query.rows, 0);
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
    options_.ratio = reader.Get<double>("ratio", options_.ratio);
    if (!(options_.ratio > 0 && options_.ratio <= 1)) {
      throw OptionError(reader.KeyPath("ratio"), "= " + nlohmann::json(options_.ratio).dump() +
                                                     " is out of range; must be in (0, 1]");
    }
    options_.cross_check = reader.GetBool("cross_check", options_.cross_check);
    options_.max_distance = reader.Get<double>("max_distance", options_.max_distance, 0.0, 1e9);
    reader.Finish();
    effective_options_ = reader.Effective();
  }

  FeatureMatches Match(const FeatureDescriptors& descriptors1,
                       const FeatureDescriptors& descriptors2) const override {
    // An image without features has nothing to match, whatever its declared metric.
    if (descriptors1.size() == 0 || descriptors2.size() == 0) return {};
    CheckCompatible(descriptors1, descriptors2);

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
      const Neighbors forward = FindNeighbors(matcher, mat1, mat2, 2);
      Neighbors backward;
      if (options_.cross_check) backward = FindNeighbors(matcher, mat2, mat1, 1);
      matches = SelectMatches(forward, backward, descriptors2.size());
    });
    return matches;
  }

 private:
  static void CheckCompatible(const FeatureDescriptors& descriptors1,
                              const FeatureDescriptors& descriptors2) {
    if (descriptors1.metric != descriptors2.metric) {
      throw InputError(std::string("Cannot match ") + DescriptorMetricName(descriptors1.metric) +
                       " descriptors against " + DescriptorMetricName(descriptors2.metric) +
                       " descriptors: both images must be described by the same detector.");
    }
    if (descriptors1.dimension() != descriptors2.dimension()) {
      throw InputError("Cannot match descriptors of " + std::to_string(descriptors1.dimension()) +
                       " bytes against descriptors of " + std::to_string(descriptors2.dimension()) +
                       " bytes: both images must be described by the same detector.");
    }
  }

  // a -> b matches that pass the ratio test, the distance threshold and, when asked,
  // the cross check; in ascending order of the first index.
  FeatureMatches SelectMatches(const Neighbors& forward, const Neighbors& backward,
                               Eigen::Index num_train) const {
    FeatureMatches matches;
    for (size_t i = 0; i < forward.best.size(); ++i) {
      const int j = forward.best[i];
      if (j < 0) continue;
      if (options_.max_distance > 0 && forward.best_distance[i] > options_.max_distance) continue;
      if (forward.second[i] >= 0) {
        // Strict, so that two equally close neighbours (ambiguous) always fail.
        if (!(forward.best_distance[i] < options_.ratio * forward.second_distance[i])) continue;
      } else if (num_train > 1) {
        continue;  // cannot happen for an exact search; kept for symmetry with approximate ones
      }
      // With a single candidate there is no second neighbour and the ratio test passes.
      if (options_.cross_check && backward.best[j] != static_cast<int>(i)) continue;
      FeatureMatch match;
      match.point2D_idx1 = static_cast<point2D_t>(i);
      match.point2D_idx2 = static_cast<point2D_t>(j);
      matches.push_back(match);
    }
    return matches;
  }

  BruteForceMatchOptions options_;
};

}  // namespace tessera

TESSERA_PLUGIN(matcher, tessera::BruteForceMatcher, "brute_force", "1.0.0",
               "Exact nearest neighbours (OpenCV BFMatcher) with ratio test and cross check")
