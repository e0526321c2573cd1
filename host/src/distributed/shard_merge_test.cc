#include "distributed/shard_merge.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <fstream>
#include <map>

#include "distributed/shard_database.h"
#include "distributed/sharded_stages.h"
#include "pipeline/extract_stage.h"
#include "pipeline/match_stage.h"
#include "pipeline/stage_test_util.h"
#include "tessera/errors.h"

namespace tessera {
namespace {

// The plugins of the stage tests (orb, exhaustive, brute_force) as a run's context.
PipelineContext CheapContext() {
  testing::CheapPlugins plugins;
  PipelineContext context;
  context.manifest = testing::CheapManifest(2);
  context.detector = std::move(plugins.detector);
  context.pair_selectors = std::move(plugins.pair_selectors);
  context.matcher = std::move(plugins.matcher);
  return context;
}

// Every row of a table, as text, in key order.
std::string Rows(const Database& database, const std::string& table) {
  std::string text;
  if (table == "features") {
    for (const Image& image : database.ReadAllImages()) {
      const FeatureKeypoints keypoints = database.ReadKeypoints(image.image_id);
      const FeatureDescriptors descriptors =
          database.ReadDescriptors(image.image_id, DescriptorMetric::kHamming);
      text += image.name + " " + std::to_string(image.image_id) + " " +
              std::to_string(keypoints.size()) + " ";
      for (const FeatureKeypoint& k : keypoints)
        text += std::to_string(k.x) + "," + std::to_string(k.y) + ";";
      text.append(reinterpret_cast<const char*>(descriptors.data.data()),
                  static_cast<size_t>(descriptors.data.size()));
    }
  } else if (table == "matches") {
    for (const image_pair_t pair_id : database.ReadMatchedPairIds()) {
      const auto [id1, id2] = PairIdToImagePair(pair_id);
      text += std::to_string(pair_id) + ":";
      for (const FeatureMatch& m : database.ReadMatches(id1, id2)) {
        text += std::to_string(m.point2D_idx1) + "-" + std::to_string(m.point2D_idx2) + ",";
      }
    }
  } else {
    for (const auto& [pair_id, geometry] : database.ReadAllTwoViewGeometries()) {
      text += std::to_string(pair_id) + ":" + std::to_string(static_cast<int>(geometry.config)) +
              " " + std::to_string(geometry.inlier_matches.size()) + " " +
              std::to_string(geometry.F(0, 1)) + " " + std::to_string(geometry.E(1, 2)) + ";";
    }
  }
  return text;
}

std::string FileBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// `tessera merge --stage STAGE` on `output`.
ShardMergeSummary Merge(const std::filesystem::path& output, const std::string& stage) {
  Workspace::Options open;
  open.open_database = false;
  const auto workspace = Workspace::Open(output, open);
  return MergeShards(*workspace, {stage, std::nullopt});
}

std::string MergeError(const std::filesystem::path& output, const std::string& stage) {
  try {
    Merge(output, stage);
  } catch (const InputError& error) {
    return error.what();
  }
  return "no error";
}

// 4 images of the sample (6 pairs): a single-process workspace, and the same stages as
// shards in another.
class MergeTest : public ::testing::Test {
 protected:
  void SetUp() override { testing::WriteSampleImages(images(), 4); }
  std::filesystem::path images() const { return dir_.path() / "images"; }
  std::filesystem::path output() const { return dir_.path() / "out"; }
  RunOptions run() const { return {images(), output()}; }

  void Single() {
    const auto workspace = Workspace::Open(dir_.path() / "single");
    const Database& database = workspace->database();
    ExtractFeatures(*workspace, context_.MakeExtractSettings(images()));
    MatchFeatures(*workspace, context_.MakeMatchSettings());
    features_ = Rows(database, "features");
    matches_ = Rows(database, "matches");
    geometries_ = Rows(database, "geometries");
  }
  void ExtractShards(int count) {
    for (int k = 0; k < count; ++k) RunExtractShard(context_, run(), {k, count});
  }
  void MatchShards(int count) {
    for (int k = 0; k < count; ++k) RunMatchShard(context_, run(), {k, count});
  }
  void Rewrite(const std::string& stage, const Shard& shard,
               const std::function<void(ShardRecord*)>& change) {
    Database database(ShardDatabasePath(output(), stage, shard));
    ShardRecord record = *ReadShardRecord(database);
    change(&record);
    WriteShardRecord(record, &database);
  }

  testing::TemporaryDir dir_;
  PipelineContext context_ = CheapContext();
  std::string features_, matches_, geometries_;
};

TEST_F(MergeTest, ShardsMergeIntoWhatOneProcessMakes) {
  Single();
  ExtractShards(3);
  const ShardMergeSummary extraction = Merge(output(), kExtractStage);
  EXPECT_EQ(extraction.num_shards, 3);
  EXPECT_EQ(extraction.num_images, 4u);
  EXPECT_FALSE(extraction.already_merged);
  {
    const Database database(output() / "database.db");
    EXPECT_EQ(Rows(database, "features"), features_);
    EXPECT_FALSE(ReadShardRecord(database)) << "shard 0's record came along";
  }
  MatchShards(2);
  const ShardMergeSummary matching = Merge(output(), kMatchStage);
  EXPECT_EQ(matching.num_pairs, 6u);
  const Database database(output() / "database.db");
  EXPECT_EQ(Rows(database, "matches"), matches_);
  EXPECT_EQ(Rows(database, "geometries"), geometries_);
}

// The index files of the workspace's matcher cache, with their inode numbers (a file
// written again gets a new one).
std::map<std::string, ino_t> CacheFiles(const std::filesystem::path& output) {
  std::map<std::string, ino_t> files;
  const std::filesystem::path folder = output / "cache" / "matcher" / "flann";
  if (!std::filesystem::exists(folder)) return files;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    struct stat status {};
    EXPECT_EQ(::stat(entry.path().c_str(), &status), 0);
    files[entry.path().filename().string()] = status.st_ino;
  }
  return files;
}

TEST_F(MergeTest, ExtractionShardsBuildEachIndexOnceAndMatchingShardsReadIt) {
  // With flann (hierarchical trees over ORB's binary descriptors), each extraction shard
  // writes the index of every image it detects; the matching shards read them, write
  // none, and find the matches of one process that builds its own.
  context_.matcher = testing::LoadBundledPlugin<Matcher>(
      "matcher", "flann", nlohmann::json::object(), "pipeline.matcher");
  Single();
  ExtractShards(3);
  const auto prepared = CacheFiles(output());
  EXPECT_EQ(prepared.size(), 4u);
  Merge(output(), kExtractStage);
  MatchShards(3);
  EXPECT_EQ(CacheFiles(output()), prepared);
  Merge(output(), kMatchStage);
  const Database database(output() / "database.db");
  EXPECT_EQ(Rows(database, "matches"), matches_);
  EXPECT_EQ(Rows(database, "geometries"), geometries_);
}

TEST_F(MergeTest, AnUnwritableCacheCostsOnlyTheIndexFiles) {
  // OUTPUT/cache is a file: Prepare fails (one warning), and every image is still
  // extracted and every pair matched as one process does.
  context_.matcher = testing::LoadBundledPlugin<Matcher>(
      "matcher", "flann", nlohmann::json::object(), "pipeline.matcher");
  Single();
  std::filesystem::create_directories(output());
  std::ofstream(output() / "cache") << "not a folder";
  ExtractShards(2);
  Merge(output(), kExtractStage);
  MatchShards(2);
  Merge(output(), kMatchStage);
  const Database database(output() / "database.db");
  EXPECT_EQ(Rows(database, "features"), features_);
  EXPECT_EQ(Rows(database, "matches"), matches_);
  EXPECT_EQ(Rows(database, "geometries"), geometries_);
}

TEST_F(MergeTest, MergingAgainChangesNothing) {
  ExtractShards(2);
  Merge(output(), kExtractStage);
  MatchShards(2);
  Merge(output(), kMatchStage);
  const std::string before = Rows(Database(output() / "database.db"), "matches");
  EXPECT_TRUE(Merge(output(), kExtractStage).already_merged);
  EXPECT_EQ(Merge(output(), kMatchStage).num_pairs, 6u);
  const Database database(output() / "database.db");
  EXPECT_EQ(Rows(database, "matches"), before);
  EXPECT_EQ(database.NumMatchedPairs(), 6u);
  EXPECT_FALSE(std::filesystem::exists(output() / "database.db.before-merge"));
}

TEST_F(MergeTest, AShardRunAgainSkipsWhatItFinished) {
  CancellationToken token;
  StageControl control;
  control.cancel = &token;
  control.progress = [&](const std::string&, size_t done, size_t) {
    if (done == 1) token.Cancel();
  };
  context_.manifest.num_threads = 1;
  const ExtractionSummary first = RunExtractShard(context_, run(), {0, 1}, control);
  EXPECT_EQ(first.status, StageStatus::kCancelled);
  EXPECT_EQ(first.num_detected, 1u);
  EXPECT_NE(MergeError(output(), kExtractStage).find("unfinished"), std::string::npos);
  const ExtractionSummary second = RunExtractShard(context_, run(), {0, 1});
  EXPECT_EQ(second.num_reused, 1u);
  EXPECT_EQ(second.num_detected, 3u);
  Merge(output(), kExtractStage);
  MatchShards(2);
  const MatchingSummary again = RunMatchShard(context_, run(), {1, 2});
  EXPECT_EQ(again.num_matched, 0u);
  EXPECT_EQ(again.num_reused, again.num_pairs);
  EXPECT_GT(again.num_pairs, 0u);
}

// OUTPUT/shards a link to another folder: a shard of other inputs there is not removed
// through it, nor a shard written there.
TEST_F(MergeTest, NoShardIsWrittenOrRemovedThroughALink) {
  const std::filesystem::path elsewhere = dir_.path() / "elsewhere";
  std::filesystem::create_directories(elsewhere);
  std::ofstream(elsewhere / "extract-0-of-2.db") << "precious";
  std::filesystem::create_directories(output());
  std::filesystem::create_directory_symlink(elsewhere, output() / "shards");
  try {
    RunExtractShard(context_, run(), {0, 2});
    FAIL() << "no error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find((output() / "shards").string() + ", a symbolic link"),
              std::string::npos)
        << error.what();
  }
  std::ifstream file(elsewhere / "extract-0-of-2.db");
  std::string text;
  std::getline(file, text);
  EXPECT_EQ(text, "precious");
}

TEST_F(MergeTest, MissingShardsAreNamedByIndex) {
  RunExtractShard(context_, run(), {1, 4});
  EXPECT_NE(MergeError(output(), kExtractStage).find("extract shards 0, 2, 3 of 4 missing"),
            std::string::npos)
      << MergeError(output(), kExtractStage);
  EXPECT_FALSE(std::filesystem::exists(output() / "database.db"));
}

TEST_F(MergeTest, AShardOfAnotherManifestOptionsOrImageListIsRefusedByName) {
  ExtractShards(2);
  Merge(output(), kExtractStage);
  MatchShards(2);
  const std::string database_bytes = FileBytes(output() / "database.db");
  const auto expect_refused = [&](const std::string& stage, const std::string& what,
                                  const std::function<void(ShardRecord*)>& change) {
    ShardRecord saved;
    Rewrite(stage, {1, 2}, [&](ShardRecord* record) {
      saved = *record;
      change(record);
    });
    const std::string error = MergeError(output(), stage);
    EXPECT_NE(error.find(stage + " shard 1/2 ("), std::string::npos) << error;
    EXPECT_NE(error.find(what), std::string::npos) << error;
    Rewrite(stage, {1, 2}, [&](ShardRecord* record) { *record = saved; });
  };
  expect_refused(kMatchStage, "another manifest", [](ShardRecord* r) { r->manifest = "other"; });
  expect_refused(kMatchStage, "other options", [](ShardRecord* r) { r->options = {{"x", 1}}; });
  expect_refused(kMatchStage, "another image list", [](ShardRecord* r) { r->images = "other"; });
  expect_refused(kExtractStage, "another manifest", [](ShardRecord* r) { r->manifest = "x"; });
  expect_refused(kExtractStage, "another image list", [](ShardRecord* r) { r->images = "x"; });
  EXPECT_EQ(FileBytes(output() / "database.db"), database_bytes);
  Merge(output(), kMatchStage);  // restored: merges
  EXPECT_EQ(Database(output() / "database.db").NumMatchedPairs(), 6u);
}

TEST_F(MergeTest, ACorruptOrTruncatedShardIsNamedAndDatabaseUntouched) {
  ExtractShards(2);
  Merge(output(), kExtractStage);
  MatchShards(2);
  const std::string database_bytes = FileBytes(output() / "database.db");
  const std::filesystem::path shard = ShardDatabasePath(output(), kMatchStage, {1, 2});
  const std::string bytes = FileBytes(shard);
  std::ofstream(shard, std::ios::binary | std::ios::trunc) << bytes.substr(0, bytes.size() / 3);
  const std::string error = MergeError(output(), kMatchStage);
  EXPECT_NE(error.find("match shard 1/2 (" + shard.string() + ")"), std::string::npos) << error;
  EXPECT_EQ(FileBytes(output() / "database.db"), database_bytes);
  EXPECT_EQ(Database(output() / "database.db").NumMatchedPairs(), 0u);

  std::ofstream(shard, std::ios::binary | std::ios::trunc) << "not a database at all";
  EXPECT_NE(MergeError(output(), kMatchStage).find("match shard 1/2"), std::string::npos);
  EXPECT_EQ(FileBytes(output() / "database.db"), database_bytes);
}

}  // namespace
}  // namespace tessera
