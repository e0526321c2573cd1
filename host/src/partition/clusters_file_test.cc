#include "partition/clusters_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "tessera/io/file_io.h"

namespace tessera {
namespace {

// Two clusters side by side, the first a single loop kept whole.
ClustersFile TwoClusters() {
  ClustersFile file;
  file.pairs_fingerprint = "pairs";
  file.manifest_fingerprint = "manifest";
  file.cluster_max_images = 4;
  file.cluster_overlap = 1;
  file.clusters.resize(2);
  file.clusters[0].index = 0;
  file.clusters[0].images = file.clusters[0].core = {"a", "b", "c", "d", "e", "f"};
  file.clusters[0].single_loop = true;
  file.clusters[1].index = 1;
  file.clusters[1].images = file.clusters[1].core = {"g", "h"};
  file.tree.children.resize(2);
  file.tree.children[0].cluster = 0;
  file.tree.children[1].cluster = 1;
  file.total_weight = 100;
  return file;
}

TEST(ClustersFile, RoundTripsTheSingleLoopFlag) {
  const std::filesystem::path folder = std::filesystem::path(::testing::TempDir()) /
                                       ("tessera-clusters-file-" + std::to_string(getpid()));
  std::filesystem::create_directories(folder);
  const std::filesystem::path path = ClustersFilePath(folder);
  const ClustersFile written = TwoClusters();
  written.Write(path);
  const std::string text = ReadFileContents(path);
  EXPECT_NE(text.find("\"single_loop\": true"), std::string::npos) << text;
  // Only where set: other partitions' files and fingerprints stay as they were.
  EXPECT_EQ(text.find("single_loop"), text.rfind("single_loop")) << text;
  EXPECT_FALSE(written.ToJson().at("clusters").at(1).contains("single_loop"));

  const ClustersFile read = ClustersFile::Read(path);
  ASSERT_EQ(read.clusters.size(), 2u);
  EXPECT_TRUE(read.clusters[0].single_loop);
  EXPECT_FALSE(read.clusters[1].single_loop);
  EXPECT_EQ(read.clusters[0].images, written.clusters[0].images);
  EXPECT_EQ(read.Fingerprint(), written.Fingerprint());
  std::filesystem::remove_all(folder);
}

TEST(ClustersFile, AFileWithoutTheFlagReadsAsNoLoop) {
  nlohmann::json json = TwoClusters().ToJson();
  json["clusters"][0].erase("single_loop");
  const ClustersFile read = ClustersFile::FromJson(json);
  EXPECT_FALSE(read.clusters[0].single_loop);
  EXPECT_FALSE(read.clusters[1].single_loop);
}

TEST(ClustersFile, AMistypedFlagIsRefused) {
  nlohmann::json json = TwoClusters().ToJson();
  json["clusters"][0]["single_loop"] = "yes";
  EXPECT_THROW(ClustersFile::FromJson(json), nlohmann::json::exception);
}

TEST(ClustersFile, RoundTripsTheCalibrationOfEveryCluster) {
  ClustersFile written = TwoClusters();
  EXPECT_FALSE(written.ToJson().contains("cameras"));  // none: as before
  FocalLengthReport camera;
  camera.camera_id = 3;
  camera.initial = 2304;
  camera.estimated = 1379.5;
  camera.method = "first model";
  camera.num_images = 16;
  written.cameras.push_back(camera);
  const ClustersFile read = ClustersFile::FromJson(written.ToJson());
  ASSERT_EQ(read.cameras.size(), 1u);
  EXPECT_EQ(read.cameras[0].camera_id, 3u);
  EXPECT_EQ(read.cameras[0].estimated, 1379.5);
  EXPECT_EQ(read.cameras[0].initial, 2304);
  EXPECT_EQ(read.cameras[0].method, "first model");
  EXPECT_EQ(read.cameras[0].num_images, 16u);
  EXPECT_NE(read.Fingerprint(), TwoClusters().Fingerprint());

  nlohmann::json bad = written.ToJson();
  bad["cameras"][0]["focal_length"] = -1.0;
  EXPECT_THROW(ClustersFile::FromJson(bad), nlohmann::json::exception);
}

}  // namespace
}  // namespace tessera
