#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "test_support.h"

namespace tessera {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kLatitude0 = 45.0, kLongitude0 = 7.0;

// A local east/north/up position in metres, turned into WGS84 degrees about
// (kLatitude0, kLongitude0) with the ellipsoid's radii of curvature there: exact to
// millimetres over the few hundred metres used here.
struct Local {
  double east, north;
  std::optional<double> up = 0.0;
};

GpsPosition ToGps(const Local& local) {
  constexpr double kA = 6378137.0, kE2 = 6.69437999014e-3;
  const double phi = kLatitude0 * kPi / 180;
  const double w = 1 - kE2 * std::sin(phi) * std::sin(phi);
  const double meridian = kA * (1 - kE2) / std::pow(w, 1.5);
  const double normal = kA / std::sqrt(w);
  GpsPosition gps;
  gps.latitude_deg = kLatitude0 + local.north / meridian * 180 / kPi;
  gps.longitude_deg = kLongitude0 + local.east / (normal * std::cos(phi)) * 180 / kPi;
  if (local.up) gps.altitude_m = 300 + *local.up;
  return gps;
}

// Images "img0.jpg"... in capture order; nullopt: no GPS.
PairSelectionInput Images(const std::vector<std::optional<Local>>& positions) {
  PairSelectionInput input;
  for (size_t i = 0; i < positions.size(); ++i) {
    PairSelectionImage image;
    image.image_id = static_cast<image_t>(i + 1);
    image.name = "img" + std::to_string(i) + ".jpg";
    if (positions[i]) image.metadata.gps = ToGps(*positions[i]);
    input.images.push_back(image);
  }
  return input;
}

// The expected pairs, from the local metres: each image with its k nearest within
// max_distance (ties by index), united, ascending.
std::vector<ImageIndexPair> Reference(const std::vector<Local>& local, size_t k,
                                      double max_distance, bool with_altitude) {
  std::set<ImageIndexPair> pairs;
  for (size_t a = 0; a < local.size(); ++a) {
    std::vector<std::pair<double, size_t>> candidates;
    for (size_t b = 0; b < local.size(); ++b) {
      if (b == a) continue;
      const double up = with_altitude ? *local[a].up - *local[b].up : 0.0;
      const double distance = std::sqrt(std::pow(local[a].east - local[b].east, 2) +
                                        std::pow(local[a].north - local[b].north, 2) + up * up);
      if (distance <= max_distance) candidates.emplace_back(distance, b);
    }
    std::sort(candidates.begin(), candidates.end());
    for (size_t c = 0; c < std::min(k, candidates.size()); ++c) {
      pairs.emplace(std::min(a, candidates[c].second), std::max(a, candidates[c].second));
    }
  }
  return {pairs.begin(), pairs.end()};
}

// 30 positions scattered over 200 m x 150 m with up to 20 m of height (a fixed LCG).
std::vector<Local> Scattered() {
  std::vector<Local> local;
  uint32_t state = 2024;
  const auto next = [&state] {
    state = state * 1664525u + 1013904223u;
    return (state >> 8) / static_cast<double>(1u << 24);
  };
  for (int i = 0; i < 30; ++i) {
    const double east = 200 * next(), north = 150 * next(), up = 20 * next();
    local.push_back({east, north, up});
  }
  return local;
}

std::vector<std::optional<Local>> AllTagged(const std::vector<Local>& local) {
  return {local.begin(), local.end()};
}

TEST(SpatialPairSelector, NearestNeighboursWithinTheDistance) {
  const std::vector<Local> local = Scattered();
  const PairSelectionInput input = Images(AllTagged(local));
  auto selector = testing::LoadBundledPlugin<PairSelector>(
      "pair_selector", "spatial", {{"num_neighbors", 3}, {"max_distance", 1000}});
  const auto pairs = testing::Unguarded(selector).SelectPairs(input);
  EXPECT_EQ(pairs, Reference(local, 3, 1000, true));
  // Each image has its 3 nearest, so at least 30 * 3 / 2 pairs and at most 30 * 3.
  EXPECT_GE(pairs.size(), 45u);
  EXPECT_LE(pairs.size(), 90u);
  EXPECT_EQ(testing::Unguarded(selector).SelectPairs(input), pairs);  // deterministic
}

TEST(SpatialPairSelector, DistanceCutOff) {
  const std::vector<Local> local = Scattered();
  const PairSelectionInput input = Images(AllTagged(local));
  auto selector = testing::LoadBundledPlugin<PairSelector>(
      "pair_selector", "spatial", {{"num_neighbors", 1000}, {"max_distance", 40}});
  const auto pairs = testing::Unguarded(selector).SelectPairs(input);
  // num_neighbors >= n: every pair within 40 m, and no other.
  const auto expected = Reference(local, 1000, 40, true);
  EXPECT_EQ(pairs, expected);
  EXPECT_GT(pairs.size(), 10u);
  EXPECT_LT(pairs.size(), 30u * 29 / 2);
  // A far-away image (5 km east) pairs with nobody.
  std::vector<std::optional<Local>> with_far = AllTagged(local);
  with_far.push_back(Local{5000, 0, 0});
  const auto far_pairs = testing::Unguarded(selector).SelectPairs(Images(with_far));
  EXPECT_EQ(far_pairs, expected);
}

TEST(SpatialPairSelector, GridNeighbours) {
  // A 4 x 3 grid, columns 10 m apart, rows at 0, 13 and 29 m north (no ties at the
  // second neighbour): with 2 neighbours each image pairs with its east and west
  // neighbours where it has both, else with its one row neighbour and the nearer row.
  std::vector<Local> local;
  for (const double north : {0.0, 13.0, 29.0}) {
    for (int column = 0; column < 4; ++column) local.push_back({10.0 * column, north, 0.0});
  }
  auto selector =
      testing::LoadBundledPlugin<PairSelector>("pair_selector", "spatial", {{"num_neighbors", 2}});
  const auto pairs = testing::Unguarded(selector).SelectPairs(Images(AllTagged(local)));
  const std::vector<ImageIndexPair> expected = {{0, 1},  {0, 4},   {1, 2}, {2, 3}, {3, 7},
                                                {4, 5},  {5, 6},   {6, 7}, {8, 9}, {8, 4},
                                                {9, 10}, {10, 11}, {11, 7}};
  std::vector<ImageIndexPair> sorted;
  for (const auto& [i, j] : expected) sorted.emplace_back(std::min(i, j), std::max(i, j));
  std::sort(sorted.begin(), sorted.end());
  EXPECT_EQ(pairs, sorted);
}

TEST(SpatialPairSelector, AltitudeCountsUnlessIgnoredOrMissing) {
  // Two images 30 m apart horizontally and 50 m apart in height.
  const std::vector<Local> local = {{0, 0, 0.0}, {30, 0, 50.0}};
  const nlohmann::json options = {{"max_distance", 40}};
  auto selector = testing::LoadBundledPlugin<PairSelector>("pair_selector", "spatial", options);
  EXPECT_TRUE(
      testing::Unguarded(selector).SelectPairs(Images(AllTagged(local))).empty());  // 58 m apart

  nlohmann::json ignore = options;
  ignore["ignore_altitude"] = true;
  auto flat = testing::LoadBundledPlugin<PairSelector>("pair_selector", "spatial", ignore);
  EXPECT_EQ(testing::Unguarded(flat).SelectPairs(Images(AllTagged(local))),
            (std::vector<ImageIndexPair>{{0, 1}}));

  // One image without an altitude: altitudes are ignored for all.
  const std::vector<std::optional<Local>> partial = {Local{0, 0, 0.0}, Local{30, 0, std::nullopt}};
  EXPECT_EQ(testing::Unguarded(selector).SelectPairs(Images(partial)),
            (std::vector<ImageIndexPair>{{0, 1}}));
}

TEST(SpatialPairSelector, ImagesWithoutGpsFallBackToAWindow) {
  // Ten images 100 m apart in a line, too far to pair by position; 3 and 7 lack GPS.
  std::vector<std::optional<Local>> positions;
  for (int i = 0; i < 10; ++i) positions.push_back(Local{100.0 * i, 0, 0.0});
  positions[3].reset();
  positions[7].reset();
  auto selector = testing::LoadBundledPlugin<PairSelector>(
      "pair_selector", "spatial", {{"max_distance", 50}, {"fallback_window", 1}});
  EXPECT_EQ(testing::Unguarded(selector).SelectPairs(Images(positions)),
            (std::vector<ImageIndexPair>{{2, 3}, {3, 4}, {6, 7}, {7, 8}}));
  auto wider = testing::LoadBundledPlugin<PairSelector>(
      "pair_selector", "spatial", {{"max_distance", 150}, {"fallback_window", 2}});
  // Neighbours at 100 m where both have GPS (not across a missing image: 200 m), and
  // the missing images' windows.
  EXPECT_EQ(testing::Unguarded(wider).SelectPairs(Images(positions)),
            (std::vector<ImageIndexPair>{{0, 1},
                                         {1, 2},
                                         {1, 3},
                                         {2, 3},
                                         {3, 4},
                                         {3, 5},
                                         {4, 5},
                                         {5, 6},
                                         {5, 7},
                                         {6, 7},
                                         {7, 8},
                                         {7, 9},
                                         {8, 9}}));
  auto none = testing::LoadBundledPlugin<PairSelector>(
      "pair_selector", "spatial", {{"max_distance", 50}, {"fallback_window", 0}});
  EXPECT_TRUE(testing::Unguarded(none).SelectPairs(Images(positions)).empty());

  // No image has GPS: a plain window.
  const std::vector<std::optional<Local>> untagged(4);
  EXPECT_EQ(testing::Unguarded(selector).SelectPairs(Images(untagged)),
            (std::vector<ImageIndexPair>{{0, 1}, {1, 2}, {2, 3}}));
  EXPECT_TRUE(testing::Unguarded(selector).SelectPairs(Images({})).empty());
  EXPECT_TRUE(testing::Unguarded(selector).SelectPairs(Images({Local{0, 0, 0.0}})).empty());
}

TEST(SpatialPairSelector, OptionsAndErrors) {
  auto selector = testing::LoadBundledPlugin<PairSelector>("pair_selector", "spatial");
  EXPECT_EQ(testing::Unguarded(selector).EffectiveOptions(),
            (nlohmann::json{{"num_neighbors", 50},
                            {"max_distance", 100.0},
                            {"ignore_altitude", false},
                            {"fallback_window", 5}}));
  try {
    testing::LoadBundledPlugin<PairSelector>("pair_selector", "spatial", {{"max_distance", -1}},
                                             "pipeline.pair_selector[1]");
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what())
                  .find("pipeline.pair_selector[1].options.max_distance = -1 is out of range"),
              std::string::npos)
        << error.what();
  }
  try {
    testing::LoadBundledPlugin<PairSelector>("pair_selector", "spatial", {{"num_neighbours", 3}});
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("did you mean 'num_neighbors'?"), std::string::npos)
        << error.what();
  }
}

}  // namespace
}  // namespace tessera
