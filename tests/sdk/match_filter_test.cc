#include "tessera/match_filter.h"

#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

namespace tessera {
namespace {

// One query row's neighbours: best and second row (-1: none) and their distances.
struct Row {
  int best = -1;
  float best_distance = 0;
  int second = -1;
  float second_distance = 0;
};

NearestNeighbors NeighborsOf(const std::vector<Row>& rows) {
  NearestNeighbors neighbors(rows.size());
  for (size_t i = 0; i < rows.size(); ++i) {
    neighbors.best[i] = rows[i].best;
    neighbors.best_distance[i] = rows[i].best_distance;
    neighbors.second[i] = rows[i].second;
    neighbors.second_distance[i] = rows[i].second_distance;
  }
  return neighbors;
}

std::vector<std::pair<int, int>> Pairs(const FeatureMatches& matches) {
  std::vector<std::pair<int, int>> pairs;
  for (const FeatureMatch& match : matches) {
    pairs.emplace_back(static_cast<int>(match.point2D_idx1), static_cast<int>(match.point2D_idx2));
  }
  return pairs;
}

using P = std::vector<std::pair<int, int>>;

MatchFilterOptions Options(double ratio, bool cross_check, double max_distance = 0) {
  MatchFilterOptions options;
  options.ratio = ratio;
  options.cross_check = cross_check;
  options.max_distance = max_distance;
  return options;
}

TEST(FilterMatches, RatioTestIsStrictOnDistancesNotSquared) {
  const NearestNeighbors forward = NeighborsOf({
      {0, 5, 1, 5},    // a tie: ambiguous at any ratio
      {3, 10, 2, 20},  // ratio 0.5
      {1, 6, 4, 10},   // ratio 0.6
      {-1, 0, -1, 0},  // no neighbour at all
  });
  const NearestNeighbors none;
  EXPECT_EQ(Pairs(FilterMatches(Options(1.0, false), forward, none, 5)), (P{{1, 3}, {2, 1}}));
  EXPECT_EQ(Pairs(FilterMatches(Options(0.8, false), forward, none, 5)), (P{{1, 3}, {2, 1}}));
  EXPECT_EQ(Pairs(FilterMatches(Options(0.6, false), forward, none, 5)), (P{{1, 3}}));
  EXPECT_EQ(Pairs(FilterMatches(Options(0.51, false), forward, none, 5)), (P{{1, 3}}));
  EXPECT_EQ(Pairs(FilterMatches(Options(0.5, false), forward, none, 5)), (P{}));
}

TEST(FilterMatches, MaxDistanceKeepsDistancesUpToItAndZeroTurnsItOff) {
  const NearestNeighbors forward = NeighborsOf({{0, 10, 1, 100}, {1, 30, 0, 100}});
  const NearestNeighbors none;
  EXPECT_EQ(Pairs(FilterMatches(Options(0.8, false, 0), forward, none, 2)), (P{{0, 0}, {1, 1}}));
  EXPECT_EQ(Pairs(FilterMatches(Options(0.8, false, 30), forward, none, 2)), (P{{0, 0}, {1, 1}}));
  EXPECT_EQ(Pairs(FilterMatches(Options(0.8, false, 29.9), forward, none, 2)), (P{{0, 0}}));
  EXPECT_EQ(Pairs(FilterMatches(Options(0.8, false, 9.9), forward, none, 2)), (P{}));
}

TEST(FilterMatches, ALoneNeighbourPassesOnlyWhenItIsTheOnlyTrainRow) {
  const NearestNeighbors forward = NeighborsOf({{0, 40}, {0, 3}});
  const NearestNeighbors none;
  EXPECT_EQ(Pairs(FilterMatches(Options(0.8, false), forward, none, 1)), (P{{0, 0}, {1, 0}}));
  // With more train rows a missing second neighbour means the search missed it.
  EXPECT_EQ(Pairs(FilterMatches(Options(0.8, false), forward, none, 2)), (P{}));
  EXPECT_TRUE(PassesRatioAndDistance(Options(0.8, false), forward, 0, 1));
  EXPECT_FALSE(PassesRatioAndDistance(Options(0.8, false), forward, 0, 2));
  EXPECT_FALSE(PassesRatioAndDistance(Options(0.8, false, 39), forward, 0, 1));
}

TEST(FilterMatches, CrossCheckKeepsOnlyMutualNearestNeighbours) {
  // Queries 0 and 1 are both nearest to train row 0, whose nearest query is 1; query 2
  // and train row 2 are mutual; train row 1's nearest query is 2, so 3 -> 1 is not mutual.
  const NearestNeighbors forward =
      NeighborsOf({{0, 3, 1, 30}, {0, 1, 2, 30}, {2, 2, 0, 30}, {1, 4, 0, 30}});
  const NearestNeighbors backward = NeighborsOf({{1, 1}, {2, 5}, {2, 2}});
  EXPECT_EQ(Pairs(FilterMatches(Options(0.8, true), forward, backward, 3)), (P{{1, 0}, {2, 2}}));
  EXPECT_EQ(Pairs(FilterMatches(Options(0.8, false), forward, backward, 3)),
            (P{{0, 0}, {1, 0}, {2, 2}, {3, 1}}));
  // The ratio test comes first: query 1 fails it, and its mutual match goes with it.
  NearestNeighbors ambiguous = forward;
  ambiguous.second_distance[1] = 1;
  EXPECT_EQ(Pairs(FilterMatches(Options(0.8, true), ambiguous, backward, 3)), (P{{2, 2}}));
}

TEST(ReadMatchFilterOptions, ReadsDefaultsValuesAndRefusesOutOfRange) {
  {
    OptionReader reader(nlohmann::json::object(), "pipeline.matcher.options");
    const MatchFilterOptions options = ReadMatchFilterOptions(reader);
    EXPECT_EQ(options.ratio, 0.8);
    EXPECT_TRUE(options.cross_check);
    EXPECT_EQ(options.max_distance, 0);
    EXPECT_EQ(reader.Effective(),
              (nlohmann::json{{"ratio", 0.8}, {"cross_check", true}, {"max_distance", 0.0}}));
  }
  {
    OptionReader reader(nlohmann::json{{"max_distance", 64}}, "options");
    const MatchFilterOptions options = ReadMatchFilterOptions(reader, Options(0.7, false));
    EXPECT_EQ(options.ratio, 0.7);
    EXPECT_FALSE(options.cross_check);
    EXPECT_EQ(options.max_distance, 64);
  }
  const auto message = [](const nlohmann::json& json) -> std::string {
    try {
      OptionReader reader(json, "pipeline.matcher.options");
      ReadMatchFilterOptions(reader);
    } catch (const OptionError& error) {
      return error.what();
    }
    return "no error";
  };
  EXPECT_EQ(message({{"ratio", 0}}), "pipeline.matcher.options.ratio = 0.0 is out of range (0, 1]");
  EXPECT_EQ(message({{"ratio", 1.5}}),
            "pipeline.matcher.options.ratio = 1.5 is out of range (0, 1]");
  EXPECT_EQ(message({{"ratio", 1}}), "no error");
  EXPECT_EQ(message({{"max_distance", -1}}),
            "pipeline.matcher.options.max_distance = -1 is out of range [0, 1e+09]");
  EXPECT_EQ(message({{"cross_check", 1}}),
            "pipeline.matcher.options.cross_check: expected true or false, got a number");
}

// Read through its option list once per key: an unknown key's message lists each once, and
// a matcher's own list that visits the filter's reads ratio's open range the same way.
TEST(ReadMatchFilterOptions, ReadsEachKeyOnceThroughItsList) {
  OptionReader reader(nlohmann::json{{"xyzzy_plugh", 1}}, "options");
  ReadMatchFilterOptions(reader);
  try {
    reader.Finish();
    ADD_FAILURE() << "no error";
  } catch (const OptionError& error) {
    EXPECT_EQ(std::string(error.what()),
              "options.xyzzy_plugh: unknown key (known: ratio, cross_check, max_distance)");
  }
  MatchFilterOptions options;
  OptionReader zero(nlohmann::json{{"ratio", 0}, {"max_distance", 8}}, "options");
  EXPECT_THROW(VisitMatchFilterOptions(options, option_list::Reader(&zero)), OptionError);
  OptionReader given(nlohmann::json{{"ratio", 0.5}, {"max_distance", 8}}, "options");
  VisitMatchFilterOptions(options, option_list::Reader(&given));
  EXPECT_EQ(options.ratio, 0.5);
  EXPECT_EQ(options.max_distance, 8);
}

TEST(CheckDescriptorsMatchable, NamesTheMetricsOrTheWidths) {
  FeatureDescriptors l2;
  l2.data.setZero(2, 128);
  FeatureDescriptors binary;
  binary.metric = DescriptorMetric::kHamming;
  binary.data.setZero(2, 32);
  FeatureDescriptors short_l2;
  short_l2.data.setZero(3, 64);
  const auto message = [](const FeatureDescriptors& a, const FeatureDescriptors& b) -> std::string {
    try {
      CheckDescriptorsMatchable(a, b);
    } catch (const InputError& error) {
      return error.what();
    }
    return "no error";
  };
  EXPECT_EQ(message(l2, l2), "no error");
  EXPECT_EQ(message(binary, l2),
            "Cannot match hamming descriptors against l2 descriptors: both images must be "
            "described by the same detector.");
  EXPECT_EQ(message(l2, short_l2),
            "Cannot match descriptors of 128 bytes against descriptors of 64 bytes: both images "
            "must be described by the same detector.");
}

}  // namespace
}  // namespace tessera
