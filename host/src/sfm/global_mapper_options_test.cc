#include "tessera/sfm/global_mapper_options.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <type_traits>

#include "tessera/errors.h"

namespace tessera {
namespace {

TEST(GlobalMapperOptions, DefaultsRoundTrip) {
  const GlobalMapperOptions defaults;
  const GlobalMapperOptions read = GlobalMapperOptions::FromJson(defaults.ToJson());
  EXPECT_EQ(read.ToJson(), defaults.ToJson());
  EXPECT_EQ(GlobalMapperOptions::FromJson(nlohmann::json::object()).ToJson(), defaults.ToJson());
}

TEST(GlobalMapperOptions, ReadsEveryKey) {
  nlohmann::json json = GlobalMapperOptions().ToJson();
  json["ba_num_rounds"] = 5;
  json["filter_max_reproj_error"] = 2.5;
  json["retriangulate"] = false;
  const GlobalMapperOptions options = GlobalMapperOptions::FromJson(json);
  EXPECT_EQ(options.ba_num_rounds, 5);
  EXPECT_EQ(options.filter_max_reproj_error, 2.5);
  EXPECT_FALSE(options.retriangulate);
}

// The OptionError's path for `json`, "" when nothing is thrown.
std::string ErrorPath(const nlohmann::json& json) {
  try {
    GlobalMapperOptions::FromJson(json);
  } catch (const OptionError& error) {
    return error.path();
  }
  return "";
}

TEST(GlobalMapperOptions, RangeErrorsNameTheKey) {
  EXPECT_EQ(ErrorPath({{"ba_num_rounds", -1}}), "ba_num_rounds");
  EXPECT_EQ(ErrorPath({{"ra_max_num_iterations", 0}}), "ra_max_num_iterations");
  EXPECT_EQ(ErrorPath({{"ra_num_l1_iterations", -2}}), "ra_num_l1_iterations");
  EXPECT_EQ(ErrorPath({{"gp_max_num_iterations", -5}}), "gp_max_num_iterations");
  EXPECT_EQ(ErrorPath({{"filter_max_reproj_error", 0}}), "filter_max_reproj_error");
  EXPECT_EQ(ErrorPath({{"filter_max_angle_error", 0.0}}), "filter_max_angle_error");
  EXPECT_EQ(ErrorPath({{"ra_max_residual", 0}}), "ra_max_residual");
  EXPECT_EQ(ErrorPath({{"gp_huber_threshold", 0}}), "gp_huber_threshold");
  EXPECT_EQ(ErrorPath({{"tri_max_error", -1.0}}), "tri_max_error");
  EXPECT_EQ(ErrorPath({{"min_model_size", 1}}), "min_model_size");
  EXPECT_EQ(ErrorPath({{"tracks_max_per_image", 0}}), "tracks_max_per_image");
  EXPECT_EQ(ErrorPath({{"retriangulate", 1}}), "retriangulate");
  EXPECT_EQ(ErrorPath({{"ba_num_rounds", 1.5}}), "ba_num_rounds");
  EXPECT_EQ(ErrorPath({{"min_relative_pair_strength", -0.1}}), "min_relative_pair_strength");
  EXPECT_EQ(ErrorPath({{"min_relative_pair_strength", 1.5}}), "min_relative_pair_strength");
}

// The same shape as IncrementalMapperOptions::FromJson: a path prefixes every key, and
// the range is printed after the value.
TEST(GlobalMapperOptions, FromJsonTakesThePathItNames) {
  try {
    GlobalMapperOptions::FromJson({{"ba_num_rounds", 300}}, "pipeline.mapper.options");
    FAIL() << "expected an OptionError";
  } catch (const OptionError& error) {
    EXPECT_EQ(error.path(), "pipeline.mapper.options.ba_num_rounds");
    EXPECT_STREQ(error.what(),
                 "pipeline.mapper.options.ba_num_rounds = 300 is out of range [1, 100]");
  }
}

// One seed type with MapperContext::seed: a 64-bit seed is kept whole.
TEST(GlobalMapperOptions, TheSeedIsSixtyFourBits) {
  const uint64_t seed = (uint64_t{1} << 40) + 7;
  static_assert(std::is_same_v<decltype(GlobalMapperOptions::seed), uint64_t>);
  const GlobalMapperOptions read = GlobalMapperOptions::FromJson({{"seed", seed}});
  EXPECT_EQ(read.seed, seed);
  EXPECT_EQ(read.ToJson().at("seed").get<uint64_t>(), seed);
}

TEST(GlobalMapperOptions, UnknownKeysAreRefused) {
  EXPECT_THROW(GlobalMapperOptions::FromJson({{"ba_num_round", 2}}), OptionError);
}

}  // namespace
}  // namespace tessera
