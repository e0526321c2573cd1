#pragma once

// Helpers shared by the matcher plugins' tests: descriptor sets with known
// correspondences (l2 like SIFT, binary like ORB), hand-made rows, and recall and
// precision against the truth.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <random>
#include <utility>
#include <vector>

#include "tessera/features.h"

namespace tessera::testing {

// Two descriptor sets with known correspondences: set 2 holds a perturbed copy of every
// row of set 1, shuffled, plus unrelated distractor rows.
struct SyntheticPair {
  FeatureDescriptors descriptors1;
  FeatureDescriptors descriptors2;
  std::vector<int> truth;  // truth[i]: the row of set 2 that copies row i of set 1
};

inline SyntheticPair MakeL2Pair(int num_points, int num_distractors, double noise_sigma,
                                uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> uniform(0, 255);
  std::normal_distribution<double> noise(0, noise_sigma);
  const int dim = 128;
  SyntheticPair pair;
  pair.descriptors1.data.resize(num_points, dim);
  pair.descriptors2.data.resize(num_points + num_distractors, dim);
  std::vector<int> rows(num_points + num_distractors);
  std::iota(rows.begin(), rows.end(), 0);
  std::shuffle(rows.begin(), rows.end(), rng);
  for (int i = 0; i < num_points; ++i) {
    for (int d = 0; d < dim; ++d) pair.descriptors1.data(i, d) = static_cast<uint8_t>(uniform(rng));
  }
  for (int k = 0; k < num_points + num_distractors; ++k) {
    for (int d = 0; d < dim; ++d) {
      const int value =
          k < num_points ? pair.descriptors1.data(k, d) + std::lround(noise(rng)) : uniform(rng);
      pair.descriptors2.data(rows[k], d) = static_cast<uint8_t>(std::clamp(value, 0, 255));
    }
  }
  pair.truth.assign(rows.begin(), rows.begin() + num_points);
  return pair;
}

inline SyntheticPair MakeHammingPair(int num_points, int num_distractors, int num_flips,
                                     uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> uniform(0, 255);
  const int bytes = 32;
  SyntheticPair pair;
  pair.descriptors1.metric = pair.descriptors2.metric = DescriptorMetric::kHamming;
  pair.descriptors1.data.resize(num_points, bytes);
  pair.descriptors2.data.resize(num_points + num_distractors, bytes);
  std::vector<int> rows(num_points + num_distractors);
  std::iota(rows.begin(), rows.end(), 0);
  std::shuffle(rows.begin(), rows.end(), rng);
  for (int i = 0; i < num_points; ++i) {
    for (int b = 0; b < bytes; ++b)
      pair.descriptors1.data(i, b) = static_cast<uint8_t>(uniform(rng));
  }
  std::vector<int> bits(bytes * 8);
  std::iota(bits.begin(), bits.end(), 0);
  for (int k = 0; k < num_points + num_distractors; ++k) {
    if (k < num_points) {
      pair.descriptors2.data.row(rows[k]) = pair.descriptors1.data.row(k);
      std::shuffle(bits.begin(), bits.end(), rng);  // flip exactly num_flips distinct bits
      for (int f = 0; f < num_flips; ++f) {
        pair.descriptors2.data(rows[k], bits[f] / 8) ^= static_cast<uint8_t>(1 << (bits[f] % 8));
      }
    } else {
      for (int b = 0; b < bytes; ++b) {
        pair.descriptors2.data(rows[k], b) = static_cast<uint8_t>(uniform(rng));
      }
    }
  }
  pair.truth.assign(rows.begin(), rows.begin() + num_points);
  return pair;
}

struct Quality {
  double recall = 0;
  double precision = 0;
};

inline Quality Evaluate(const FeatureMatches& matches, const std::vector<int>& truth) {
  int correct = 0;
  for (const FeatureMatch& match : matches) {
    correct += truth.at(match.point2D_idx1) == static_cast<int>(match.point2D_idx2);
  }
  Quality quality;
  quality.recall = static_cast<double>(correct) / truth.size();
  quality.precision = matches.empty() ? 0 : static_cast<double>(correct) / matches.size();
  return quality;
}

inline FeatureDescriptors L2Rows(const std::vector<std::vector<int>>& rows) {
  FeatureDescriptors descriptors;
  descriptors.data.resize(rows.size(), 128);
  for (size_t i = 0; i < rows.size(); ++i) {
    for (int d = 0; d < 128; ++d) descriptors.data(i, d) = static_cast<uint8_t>(rows[i][d]);
  }
  return descriptors;
}

// A 128-d row of constant value with `delta` added at dimension `at`.
inline std::vector<int> Row(int value, int at = 0, int delta = 0) {
  std::vector<int> row(128, value);
  row[at] += delta;
  return row;
}

inline FeatureMatches MatchesOf(std::vector<std::pair<int, int>> pairs) {
  FeatureMatches matches;
  for (const auto& [i, j] : pairs) {
    FeatureMatch match;
    match.point2D_idx1 = i;
    match.point2D_idx2 = j;
    matches.push_back(match);
  }
  return matches;
}

}  // namespace tessera::testing
