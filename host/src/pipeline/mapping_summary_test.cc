#include "pipeline/mapping_summary.h"

#include <gtest/gtest.h>

#include "tessera/errors.h"
#include "tessera/io/file_io.h"
#include "test_support.h"

namespace tessera {
namespace {

MappingSummary ExampleMappingSummary() {
  MappingSummary summary;
  MappingSummary::Model model;
  model.index = 0;
  model.folder = "out/sparse/0";
  model.num_images = 3;
  model.num_points3D = 1200;
  model.mean_track_length = 2.75;
  model.mean_reprojection_error = 0.625;
  model.mean_observation_reprojection_error = 0.75;
  model.view_graph_check = {3, 2, 0.875, true, {"c.jpg"}};
  model.images = {"a.jpg", "b.jpg", "c.jpg"};
  model.calibration = {{"assessed", true},
                       {"parameters", {{{"parameter", "f"}, {"sigma", 0.5}, {"weak", false}}}},
                       {"weak", nlohmann::json::array()}};
  summary.models.push_back(model);
  summary.unregistered = {{"d.jpg", "no verified pair"}};
  summary.focal_lengths_estimated = {{1, 1200.0, 1150.5, "view graph", 6, 0}};
  summary.view_graph_pairs_dropped = 2;
  summary.registrations_refused = 1;
  summary.merges = {"merged model 1 into model 0"};
  summary.seconds = 4.5;
  summary.mapper_options = {{"init_min_num_inliers", 100}};
  summary.seed = 42;
  summary.quarantined = {"bundle adjuster 'ceres' refused: it crashed twice on this bundle"};
  return summary;
}

TEST(MappingSummary, JsonKeys) {
  const nlohmann::json json = ExampleMappingSummary().ToJson();
  const nlohmann::json& model = json.at("models").at(0);
  EXPECT_EQ(model.at("num_points3D").get<size_t>(), 1200u);
  EXPECT_DOUBLE_EQ(model.at("view_graph_check").at("agreement").get<double>(), 0.875);
  EXPECT_DOUBLE_EQ(model.at("mean_reprojection_error").get<double>(), 0.625);
  EXPECT_DOUBLE_EQ(model.at("mean_observation_reprojection_error").get<double>(), 0.75);
  EXPECT_EQ(model.at("view_graph_check").at("disagreeing_images").at(0), "c.jpg");
  EXPECT_EQ(json.at("unregistered").at(0).at("reason"), "no verified pair");
  EXPECT_EQ(json.at("focal_lengths_estimated").at(0).at("method"), "view graph");
  EXPECT_EQ(json.at("seed").get<uint64_t>(), 42u);
  EXPECT_EQ(json.at("quarantined").size(), 1u);
  EXPECT_EQ(json.at("mapper"), "incremental");
  EXPECT_TRUE(json.at("mapper_details").is_object());
  EXPECT_EQ(json.size(), 12u);
}

TEST(MappingSummary, RoundTripThroughAFile) {
  const testing::TemporaryDir dir;
  const MappingSummary summary = ExampleMappingSummary();
  summary.Write(dir.path() / "mapping_summary.json");
  const MappingSummary back = MappingSummary::Read(dir.path() / "mapping_summary.json");
  EXPECT_EQ(back.ToJson(), summary.ToJson());
  ASSERT_EQ(back.models.size(), 1u);
  EXPECT_EQ(back.models[0].images.size(), 3u);
  EXPECT_TRUE(back.models[0].view_graph_check.possibly_folded);
  EXPECT_EQ(back.focal_lengths_estimated.at(0).camera_id, 1u);
  EXPECT_DOUBLE_EQ(back.focal_lengths_estimated.at(0).estimated, 1150.5);
  EXPECT_EQ(back.merges, summary.merges);
  EXPECT_EQ(back.quarantined, summary.quarantined);
  EXPECT_EQ(back.models[0].calibration.at("parameters").at(0).at("parameter"), "f");
}

// A summary from before the calibration was assessed reads with none; one whose
// calibration is no object is refused naming the file.
TEST(MappingSummary, TheCalibrationIsOptionalAndAnObject) {
  const testing::TemporaryDir dir;
  const std::filesystem::path file = dir.path() / "mapping_summary.json";
  nlohmann::json json = ExampleMappingSummary().ToJson();
  json["models"][0].erase("calibration");
  WriteFileAtomically(file, json.dump());
  EXPECT_TRUE(MappingSummary::Read(file).models.at(0).calibration.empty());
  json["models"][0]["calibration"] = "weak";
  WriteFileAtomically(file, json.dump());
  EXPECT_THROW(
      {
        try {
          MappingSummary::Read(file);
        } catch (const InputError& error) {
          EXPECT_NE(std::string(error.what()).find(file.string() + ": not a mapping summary"),
                    std::string::npos);
          throw;
        }
      },
      InputError);
}

// `rig` is written only with a rig (json.size() above counts without), and read back.
TEST(MappingSummary, RigSectionRoundTrips) {
  const testing::TemporaryDir dir;
  MappingSummary summary = ExampleMappingSummary();
  summary.rig = {{"file", "rig.json"}, {"digest", "0123456789abcdef"}, {"poses_known", false}};
  summary.Write(dir.path() / "mapping_summary.json");
  const MappingSummary back = MappingSummary::Read(dir.path() / "mapping_summary.json");
  EXPECT_EQ(back.rig.at("digest"), "0123456789abcdef");
  EXPECT_EQ(back.ToJson().size(), 13u);
}

TEST(MappingSummary, AFileThatIsNoSummaryIsRefusedNamingIt) {
  const testing::TemporaryDir dir;
  const std::filesystem::path file = dir.path() / "mapping_summary.json";
  WriteFileAtomically(file, "{\"models\": []}\n");
  try {
    MappingSummary::Read(file);
    FAIL() << "no exception";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find(file.string() + ": not a mapping summary"),
              std::string::npos);
  }
}

}  // namespace
}  // namespace tessera
