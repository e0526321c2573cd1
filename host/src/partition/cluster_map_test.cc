#include "partition/cluster_map.h"

#include <gtest/gtest.h>

#include <fstream>
#include <memory>
#include <set>

#include "partition/hierarchical_map.h"
#include "partition/partition_stage.h"
#include "pipeline/mapping_summary.h"
#include "pipeline/stage_test_util.h"
#include "pipeline/workspace.h"
#include "tessera/errors.h"
#include "util/child_process.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

TEST(MapClusterCommand, IsTheClusterThenWhatTheProcessIsGiven) {
  ClusterProcessOptions options;
  options.tessera = "/opt/bin/tessera";
  options.output_dir = "out dir";
  EXPECT_EQ(MapClusterCommand(options, 3),
            (std::vector<std::string>{"/opt/bin/tessera", "map", "--cluster", "3", "--output",
                                      "out dir"}));
  options.manifest = "m.json";
  options.camera_K = "K.txt";
  options.image_dir = "images";
  options.threads = 2;
  EXPECT_EQ(MapClusterCommand(options, 0),
            (std::vector<std::string>{"/opt/bin/tessera", "map", "--cluster", "0", "--output",
                                      "out dir", "--manifest", "m.json", "--camera-K", "K.txt",
                                      "--images", "images", "--threads", "2"}));
}

// One workspace for the suite: eight images of the sample extracted, matched and cut into
// clusters of at most six images, by the manifest in m.json.
class MapClusterTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new testing::TemporaryDir();
    testing::WriteSampleImages(Images(), 8);
    const nlohmann::json manifest = {
        {"plugin_paths", {testing::PluginDir().string()}},
        {"threads", 2},
        {"pipeline",
         {{"detector", {{"plugin", "sift"}, {"options", {{"max_num_features", 1000}}}}},
          {"pair_selector", {{"plugin", "exhaustive"}}},
          {"matcher", {{"plugin", "brute_force"}}},
          {"bundle_adjuster", {{"plugin", "ceres"}, {"options", {{"num_threads", 1}}}}}}},
        {"camera", {{"model", "SIMPLE_RADIAL"}, {"single_camera", true}}},
        {"distributed", {{"cluster_max_images", 6}, {"cluster_overlap", 2}}}};
    std::ofstream(ManifestFile()) << manifest.dump(2);
    context_ = new PipelineContext(PipelineContext::Create(ManifestFile()));
    RunExtract(*context_, Run());
    RunMatch(*context_, Run());
    Workspace::Options open;
    open.require_database_for = "partition";
    clusters_ = new ClustersFile(PartitionWorkspace(*Workspace::Open(Output(), open), *context_));
  }
  static void TearDownTestSuite() {
    delete clusters_;
    delete context_;
    delete dir_;
  }

  static fs::path Images() { return dir_->path() / "images"; }
  static fs::path Output() { return dir_->path() / "out"; }
  static fs::path ManifestFile() { return dir_->path() / "m.json"; }
  static RunOptions Run() { return {Images(), Output()}; }

  static testing::TemporaryDir* dir_;
  static PipelineContext* context_;
  static ClustersFile* clusters_;
};

testing::TemporaryDir* MapClusterTest::dir_ = nullptr;
PipelineContext* MapClusterTest::context_ = nullptr;
ClustersFile* MapClusterTest::clusters_ = nullptr;

TEST_F(MapClusterTest, MapsTheClustersImagesIntoItsFolderOnceAndSkipsItThen) {
  ASSERT_GE(clusters_->clusters.size(), 2u);
  const ClustersFile::Cluster& cluster = clusters_->clusters[0];
  const MapStageSummary summary = MapCluster(*context_, Run(), 0);
  ASSERT_EQ(summary.status, StageStatus::kCompleted);
  ASSERT_GE(summary.num_models, 1u);
  EXPECT_EQ(summary.num_images, cluster.images.size());

  const ClusterOutput output = ReadClusterOutput(Output(), 0, clusters_->Fingerprint());
  ASSERT_EQ(output.state, ClusterOutput::State::kFinished) << output.problem;
  ASSERT_EQ(output.models.size(), summary.num_models);
  const std::set<std::string> names(cluster.images.begin(), cluster.images.end());
  for (const Reconstruction& model : output.models) {
    for (const auto& [image_id, image] : model.images) {
      EXPECT_EQ(names.count(image.name), 1u) << image.name << " is not an image of cluster 0";
    }
  }
  EXPECT_EQ(output.models[0].images.size(), summary.images_per_model[0]);
  EXPECT_FALSE(fs::exists(Output() / "sparse")) << "a cluster writes only its own folder";

  // Mapped already for this clusters.json: the same figures, the folder left as it was.
  const fs::path points = ClusterFolder(Output(), 0) / "sparse" / "0" / "points3D.bin";
  const fs::file_time_type written = fs::last_write_time(points);
  const MapStageSummary again = MapCluster(*context_, Run(), 0);
  EXPECT_EQ(again.num_models, summary.num_models);
  EXPECT_EQ(again.num_registered, summary.num_registered);
  EXPECT_EQ(again.images_per_model, summary.images_per_model);
  EXPECT_EQ(fs::last_write_time(points), written);
}

TEST_F(MapClusterTest, AClusterOutsideTheFileIsAnInputErrorNamingIt) {
  const int count = static_cast<int>(clusters_->clusters.size());
  for (const int cluster : {count, -1}) {
    try {
      MapCluster(*context_, Run(), cluster);
      FAIL() << "cluster " << cluster << ": no error";
    } catch (const InputError& error) {
      EXPECT_EQ(std::string(error.what()), "--cluster " + std::to_string(cluster) + ": " +
                                               ClustersFilePath(Output()).string() + " has " +
                                               std::to_string(count) + " clusters (0 to " +
                                               std::to_string(count - 1) + ")");
    }
  }
}

// What `map --hierarchical` runs for a cluster: the CLI parses back what MapClusterCommand
// wrote, and maps the cluster in the same workspace with the same manifest.
TEST_F(MapClusterTest, TheCommandMapsTheClusterInAProcessOfItsOwn) {
  ClusterProcessOptions process;
  process.tessera = TESSERA_TEST_EXECUTABLE;
  process.output_dir = Output();
  process.manifest = ManifestFile();
  process.image_dir = Images();
  process.threads = 1;
  const int last = static_cast<int>(clusters_->clusters.size()) - 1;
  const ChildRun run = RunChild(MapClusterCommand(process, last));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const ClusterOutput output = ReadClusterOutput(Output(), last, clusters_->Fingerprint());
  EXPECT_EQ(output.state, ClusterOutput::State::kFinished) << output.problem;
  // Run again, it finds the cluster mapped for the same clusters.json and manifest.
  const ChildRun again = RunChild(MapClusterCommand(process, last));
  EXPECT_EQ(again.exit_code, 0) << again.output;
  EXPECT_NE(again.output.find("map: cluster " + std::to_string(last) +
                              " is already mapped for this clusters.json"),
            std::string::npos)
      << again.output;
}

// map --hierarchical's options are checked before anything runs: a count out of its range
// names the struct and the field.
TEST(HierarchicalMap, OptionsOutOfRangeAreRefusedNamingTheField) {
  EXPECT_NO_THROW(HierarchicalMapOptions().Check());
  HierarchicalMapOptions options;
  options.jobs = -1;
  try {
    options.Check();
    ADD_FAILURE() << "jobs = -1 passed";
  } catch (const InputError& error) {
    EXPECT_STREQ(error.what(), "HierarchicalMapOptions: jobs = -1 is out of range [0, 1024]");
  }
}

}  // namespace
}  // namespace tessera
