// The mappers' option descriptions (what `tessera plugins incremental` and `tessera
// plugins global` print): one per option FromJson reads, each default the value FromJson
// gives without that key, so that the described defaults are the ones a run uses.

#include <gtest/gtest.h>

#include <cstdint>
#include <nlohmann/json.hpp>
#include <set>
#include <string>

#include "tessera/errors.h"
#include "tessera/sfm/global_pipeline.h"
#include "tessera/sfm/incremental_mapper_options.h"

namespace tessera {
namespace {

// Each described option's default against `parsed` (FromJson({})'s options as ToJson
// writes them), and the described names against its keys.
void ExpectDefaultsAreParsed(const nlohmann::json& described, const nlohmann::json& parsed) {
  ASSERT_TRUE(described.is_array());
  std::set<std::string> names;
  for (const nlohmann::json& option : described) {
    const std::string name = option.at("name");
    EXPECT_TRUE(names.insert(name).second) << name << " is described twice";
    ASSERT_TRUE(parsed.contains(name)) << name << " is described but FromJson reads no such key";
    EXPECT_EQ(option.at("default"), parsed.at(name)) << name;
    EXPECT_FALSE(option.at("help").get<std::string>().empty()) << name << " has no help";
  }
  for (const auto& [key, value] : parsed.items()) {
    EXPECT_TRUE(names.count(key)) << key << " is read but not described";
  }
}

TEST(OptionsDescription, IncrementalMapperDefaultsAreFromJsonOfNothing) {
  ExpectDefaultsAreParsed(IncrementalMapperOptions::Describe(),
                          IncrementalMapperOptions::FromJson(nlohmann::json::object()).ToJson());
}

TEST(OptionsDescription, GlobalMapperDefaultsAreFromJsonOfNothing) {
  ExpectDefaultsAreParsed(GlobalPipelineOptions::Describe(),
                          GlobalPipelineOptions::FromJson(nlohmann::json::object()).ToJson());
}

// The ranges described are the ones FromJson reads with: a value just past a described
// bound is refused, the bound itself taken.
TEST(OptionsDescription, DescribedRangesAreTheOnesRead) {
  for (const nlohmann::json& option : IncrementalMapperOptions::Describe()) {
    if (option.at("type") != "integer" || option.at("min").is_null()) continue;
    const std::string name = option.at("name");
    const int64_t min_value = option.at("min");
    EXPECT_NO_THROW(IncrementalMapperOptions::FromJson({{name, min_value}})) << name;
    EXPECT_THROW(IncrementalMapperOptions::FromJson({{name, min_value - 1}}), OptionError) << name;
  }
}

}  // namespace
}  // namespace tessera
