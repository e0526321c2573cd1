#include "pipeline/run_summary.h"

#include <gtest/gtest.h>

#include "pipeline/run_pipeline.h"

namespace tessera {
namespace {

RunSummary ExampleRunSummary() {
  RunSummary summary;
  summary.extract = {StageStatus::kCompleted, 11, 1, 9, 2, 70000, 0, 3, 4, 1.5, 5};
  summary.match.num_pairs = 55;
  summary.match.pairs_per_selector = {{"spatial", "pipeline.pair_selector[0]", 40},
                                      {"sequential", "pipeline.pair_selector[1]", 20}};
  summary.match.num_matched = 50;
  summary.match.num_reused = 5;
  summary.match.num_verified = 53;
  summary.match.seconds = 2.25;
  summary.match.num_quarantined = 2;
  summary.map = {StageStatus::kCompleted, 2, 10, 11, 3.5, {7, 3}, true};
  summary.total_seconds = 7.75;
  summary.plugins = {{"detector", "orb", "1.0.0", "/p/libmy_orb.so", "0123456789abcdef"},
                     {"pair_selector", "spatial", "1.0.0", "", ""},
                     {"pair_selector", "sequential", "1.0.0", "", ""},
                     {"matcher", "brute_force", "1.0.0", "", ""},
                     {"bundle_adjuster", "ceres", "1.0.0", "", ""},
                     {"exporter", "ply", "1.1.0", "", ""}};
  return summary;
}

TEST(RunSummary, JsonHasTheKeysBenchReads) {
  const nlohmann::json json = ExampleRunSummary().ToJson();
  EXPECT_DOUBLE_EQ(json.at("extract").at("seconds").get<double>(), 1.5);
  EXPECT_EQ(json.at("extract").at("num_images").get<size_t>(), 11u);
  EXPECT_EQ(json.at("match").at("num_pairs").get<size_t>(), 55u);
  EXPECT_EQ(json.at("match").at("pairs_per_selector").size(), 2u);
  EXPECT_EQ(json.at("match").at("pairs_per_selector").at(1).at("plugin"), "sequential");
  EXPECT_EQ(json.at("map").at("num_models").get<size_t>(), 2u);
  EXPECT_EQ(json.at("map").at("images_per_model"), nlohmann::json({7, 3}));
  EXPECT_EQ(json.at("map").at("kept"), true);
  EXPECT_DOUBLE_EQ(json.at("total_seconds").get<double>(), 7.75);
  EXPECT_EQ(json.at("plugins").at(0), nlohmann::json({{"slot", "detector"},
                                                      {"plugin", "orb"},
                                                      {"version", "1.0.0"},
                                                      {"file", "/p/libmy_orb.so"},
                                                      {"file_hash", "0123456789abcdef"}}));
  // What the file has is exactly this (status and in-memory figures stay out).
  EXPECT_EQ(json.at("extract").at("num_quarantined").get<size_t>(), 5u);
  EXPECT_EQ(json.at("match").at("num_quarantined").get<size_t>(), 2u);
  EXPECT_EQ(json.at("extract").size(), 8u);
  EXPECT_EQ(json.at("match").size(), 7u);
  EXPECT_EQ(json.at("map").size(), 6u);
  EXPECT_EQ(json.size(), 5u);
}

TEST(RunSummary, RoundTrip) {
  const RunSummary summary = ExampleRunSummary();
  const RunSummary back = RunSummary::FromJson(nlohmann::json::parse(summary.ToJson().dump(2)));
  EXPECT_EQ(back.ToJson(), summary.ToJson());
  EXPECT_EQ(back.extract.num_detected, 9u);
  EXPECT_EQ(back.extract.num_removed, 4u);
  EXPECT_EQ(back.extract.num_quarantined, 5u);
  ASSERT_EQ(back.match.pairs_per_selector.size(), 2u);
  EXPECT_EQ(back.match.pairs_per_selector[0].json_path, "pipeline.pair_selector[0]");
  EXPECT_EQ(back.match.pairs_per_selector[0].num_pairs, 40u);
  EXPECT_EQ(back.map.num_registered, 10u);
  EXPECT_EQ(back.map.images_per_model, (std::vector<size_t>{7, 3}));
  EXPECT_TRUE(back.map.kept);
  ASSERT_EQ(back.plugins.size(), 6u);
  EXPECT_EQ(back.plugins[2].plugin, "sequential");
  EXPECT_EQ(back.plugins[5].version, "1.1.0");
  EXPECT_EQ(back.plugins[0].file, "/p/libmy_orb.so");
  EXPECT_EQ(back.plugins[0].file_hash, "0123456789abcdef");
  EXPECT_EQ(back.match.num_quarantined, 2u);
}

TEST(RunSummary, OlderFilesWithoutPairsPerSelectorOrImagesPerModelRead) {
  nlohmann::json json = ExampleRunSummary().ToJson();
  json["match"].erase("pairs_per_selector");
  json["map"].erase("images_per_model");
  json["map"].erase("kept");
  json["extract"].erase("num_quarantined");
  json["match"].erase("num_quarantined");
  json.erase("plugins");
  const RunSummary back = RunSummary::FromJson(json);
  EXPECT_EQ(back.extract.num_quarantined, 0u);
  EXPECT_TRUE(back.plugins.empty());
  EXPECT_TRUE(back.match.pairs_per_selector.empty());
  EXPECT_TRUE(back.map.images_per_model.empty());
  EXPECT_FALSE(back.map.kept);
  EXPECT_EQ(back.match.num_pairs, 55u);
}

TEST(RunSummary, MissingOrMistypedFieldThrows) {
  nlohmann::json json = ExampleRunSummary().ToJson();
  json["map"].erase("num_models");
  EXPECT_THROW(RunSummary::FromJson(json), nlohmann::json::exception);
  json = ExampleRunSummary().ToJson();
  json["total_seconds"] = "soon";
  EXPECT_THROW(RunSummary::FromJson(json), nlohmann::json::exception);
}

// The no-model verdict of `map` and `run` points at the warnings above only when some
// were logged (issue 50: it did after a run that logged none).
TEST(NoModelMessage, PointsAtTheWarningsAboveOnlyWhenThereAreSome) {
  EXPECT_EQ(NoModelMessage("out/database.db", true),
            "out/database.db: no model could be built: no pair of images initialised a model "
            "(see the warnings above)");
  EXPECT_EQ(NoModelMessage("out/database.db", false),
            "out/database.db: no model could be built: no pair of images initialised a model");
}

}  // namespace
}  // namespace tessera
