#include "partition/clusters_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "tessera/errors.h"
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
  camera.method = "view graph, first model";
  camera.num_images = 16;
  written.cameras.push_back(camera);
  const ClustersFile read = ClustersFile::FromJson(written.ToJson());
  ASSERT_EQ(read.cameras.size(), 1u);
  EXPECT_EQ(read.cameras[0].camera_id, 3u);
  EXPECT_EQ(read.cameras[0].estimated, 1379.5);
  EXPECT_EQ(read.cameras[0].initial, 2304);
  EXPECT_EQ(read.cameras[0].method, "view graph, first model");
  EXPECT_EQ(read.cameras[0].num_images, 16u);
  EXPECT_NE(read.Fingerprint(), TwoClusters().Fingerprint());

  nlohmann::json bad = written.ToJson();
  bad["cameras"][0]["focal_length"] = -1.0;
  EXPECT_THROW(ClustersFile::FromJson(bad), InputError);
}

// The message FromJson gives for `json` (an InputError naming the entry), or "" if none.
std::string FromJsonError(const nlohmann::json& json) {
  try {
    ClustersFile::FromJson(json);
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST(ClustersFile, NumbersOutOfRangeAreRefusedNamingTheEntry) {
  ClustersFile file = TwoClusters();
  file.cameras.push_back({});
  file.cameras[0].camera_id = 1;
  file.cameras[0].initial = file.cameras[0].estimated = 400;
  file.cameras[0].method = "view graph";
  const nlohmann::json good = file.ToJson();
  EXPECT_EQ(FromJsonError(good), "");
  const auto with = [&](const nlohmann::json::json_pointer& at, const nlohmann::json& value) {
    nlohmann::json json = good;
    json[at] = value;
    return FromJsonError(json);
  };
  using Pointer = nlohmann::json::json_pointer;
  EXPECT_EQ(with(Pointer("/cameras/0/camera_id"), 1e300),
            "cameras[0].camera_id = 1e+300: not an integer from 0 to 4294967295");
  EXPECT_EQ(with(Pointer("/cameras/0/camera_id"), -1),
            "cameras[0].camera_id = -1: not an integer from 0 to 4294967295");
  EXPECT_EQ(with(Pointer("/cameras/0/num_pairs"), 2.5),
            "cameras[0].num_pairs = 2.5: not an integer from 0 to 18446744073709551615");
  EXPECT_EQ(with(Pointer("/cameras/0/initial_focal_length"), 0),
            "cameras[0].initial_focal_length = 0: not a finite number above 0");
  EXPECT_EQ(with(Pointer("/cameras/0/method"), "guess"),
            "cameras[0].method = \"guess\": not \"view graph\", \"first model\" or \"view graph, "
            "first model\"");
  EXPECT_EQ(with(Pointer("/total_weight"), -5),
            "total_weight = -5: not a finite number of at least 0");
  EXPECT_NE(with(Pointer("/clusters/1/index"), 1e300).find("clusters[1].index = 1e+300"),
            std::string::npos);
  EXPECT_NE(with(Pointer("/tree/children/0/cluster"), 3e9).find("tree: cluster = 3000000000"),
            std::string::npos);
  // A focal length of 1e300 is a finite number: the workspace's image size refuses it
  // (ReadWorkspaceClusters, tests/end_to_end/partition_test.sh).
  EXPECT_EQ(with(Pointer("/cameras/0/focal_length"), 1e300), "");
}

// The message CheckClusters gives for `file`, or "" if none.
std::string CheckError(const ClustersFile& file) {
  try {
    file.CheckClusters("OUT/clusters.json");
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST(ClustersFile, ClustersThatDoNotHoldTogetherAreRefusedNamingTheClusterAndImage) {
  EXPECT_EQ(CheckError(TwoClusters()), "");
  ClustersFile file = TwoClusters();
  file.clusters[1].images.push_back("g");
  EXPECT_EQ(CheckError(file), "OUT/clusters.json: cluster 1: images: image 'g' is listed twice");
  file = TwoClusters();
  file.clusters[1].images.push_back("a");
  file.clusters[1].core.push_back("a");
  EXPECT_EQ(CheckError(file),
            "OUT/clusters.json: cluster 1: core: image 'a' is in the core of cluster 0 too (the "
            "cores are disjoint)");
  file = TwoClusters();
  file.clusters[1].core.push_back("z");
  EXPECT_EQ(CheckError(file), "OUT/clusters.json: cluster 1: core: image 'z' is not in its images");
  file = TwoClusters();
  file.isolated = {"g"};
  EXPECT_EQ(CheckError(file), "OUT/clusters.json: cluster 1: core: image 'g' is isolated too");
  file = TwoClusters();
  file.clusters[0].neighbours.push_back({1, {"a"}});
  EXPECT_EQ(CheckError(file),
            "OUT/clusters.json: cluster 0: neighbour 1: shared image 'a' is not in the images "
            "of both clusters");
  file = TwoClusters();
  file.clusters[0].neighbours.push_back({7, {}});
  EXPECT_EQ(CheckError(file),
            "OUT/clusters.json: cluster 0: neighbour 7: not another cluster of the file, or "
            "listed twice");
  file = TwoClusters();
  file.cameras.resize(2);
  file.cameras[0].camera_id = file.cameras[1].camera_id = 1;
  EXPECT_EQ(CheckError(file), "OUT/clusters.json: cameras: camera 1 is listed twice");
  file = TwoClusters();
  file.tree.children[1].cluster = 0;
  EXPECT_NE(CheckError(file).find("cluster 1 is missing from its list or its tree"),
            std::string::npos);
}

TEST(ClustersFile, AMissingFileIsStaleAForeignOneIsNot) {
  const std::filesystem::path folder = std::filesystem::path(::testing::TempDir()) /
                                       ("tessera-clusters-stale-" + std::to_string(getpid()));
  std::filesystem::create_directories(folder);
  const std::filesystem::path path = ClustersFilePath(folder);
  EXPECT_THROW(ClustersFile::Read(path), StaleClustersError);
  WriteFileAtomically(path, "{\"version\": 0}");
  EXPECT_THROW(ClustersFile::Read(path), StaleClustersError);
  WriteFileAtomically(path, "not json");
  try {
    ClustersFile::Read(path);
    ADD_FAILURE() << "read";
  } catch (const StaleClustersError&) {
    ADD_FAILURE() << "a file that does not parse is not stale: it is refused";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()).rfind(path.string() + ": not a clusters file: ", 0), 0u)
        << error.what();
  }
  nlohmann::json json = TwoClusters().ToJson();
  json["clusters"][0]["images"].push_back("a");
  WriteFileAtomically(path, json.dump());
  try {
    ClustersFile::Read(path);
    ADD_FAILURE() << "read";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()),
              path.string() + ": cluster 0: images: image 'a' is listed twice");
  }
  std::filesystem::remove_all(folder);
}

}  // namespace
}  // namespace tessera
