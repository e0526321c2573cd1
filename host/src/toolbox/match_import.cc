#include "toolbox/match_import.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <mutex>
#include <set>
#include <sstream>

#include "geometry/two_view_geometry_estimation.h"
#include "tessera/sfm/verified_pairs.h"
#include "util/parallel.h"
#include "util/random.h"
#include "util/timer.h"

namespace tessera {
namespace {

std::vector<std::string> Tokens(const std::string& line) {
  std::istringstream stream(line);
  std::vector<std::string> tokens;
  std::string token;
  while (stream >> token) tokens.push_back(token);
  return tokens;
}

std::ifstream OpenMatchFile(const std::filesystem::path& file) {
  std::ifstream stream(file, std::ios::binary);
  if (!stream) throw InputError(file.string() + ": cannot be read");
  return stream;
}

// A keypoint index: a whole number from 0 below 2^32 - 1.
bool ParseIndex(const std::string& token, point2D_t* index) {
  if (token.empty() || token.size() > 10 ||
      token.find_first_not_of("0123456789") != std::string::npos) {
    return false;
  }
  const unsigned long long value = std::stoull(token);
  if (value >= kInvalidPoint2DIdx) return false;
  *index = static_cast<point2D_t>(value);
  return true;
}

}  // namespace

std::vector<ImportedPair> ParsePairsFile(const std::filesystem::path& file) {
  std::ifstream stream = OpenMatchFile(file);
  std::vector<ImportedPair> pairs;
  std::string line;
  for (size_t number = 1; std::getline(stream, line); ++number) {
    const std::vector<std::string> tokens = Tokens(line);
    if (tokens.empty() || tokens.front()[0] == '#') continue;
    const std::string where = file.string() + ":" + std::to_string(number);
    if (tokens.size() != 2) {
      throw InputError(where + ": " + std::to_string(tokens.size()) +
                       " values; a line of a pairs file is `name1 name2`");
    }
    pairs.push_back({tokens[0], tokens[1], {}, where, {}});
  }
  if (pairs.empty()) throw InputError(file.string() + ": no image pairs in the file");
  return pairs;
}

std::vector<ImportedPair> ParseRawMatchesFile(const std::filesystem::path& file) {
  std::ifstream stream = OpenMatchFile(file);
  std::vector<ImportedPair> pairs;
  bool in_block = false;
  std::string line;
  for (size_t number = 1; std::getline(stream, line); ++number) {
    const std::vector<std::string> tokens = Tokens(line);
    const std::string where = file.string() + ":" + std::to_string(number);
    if (tokens.empty()) {
      in_block = false;
      continue;
    }
    if (tokens.size() != 2) {
      throw InputError(where + ": " + std::to_string(tokens.size()) + " values; " +
                       (in_block ? "a match is `idx1 idx2`" : "a block starts with `name1 name2`"));
    }
    if (!in_block) {
      pairs.push_back({tokens[0], tokens[1], {}, where, {}});
      in_block = true;
      continue;
    }
    FeatureMatch match;
    if (!ParseIndex(tokens[0], &match.point2D_idx1) ||
        !ParseIndex(tokens[1], &match.point2D_idx2)) {
      throw InputError(where + ": '" + line +
                       "' is not two keypoint indices (whole numbers from 0; blocks of "
                       "pairs are separated by a blank line)");
    }
    pairs.back().matches.push_back(match);
    pairs.back().match_lines.push_back(number);
  }
  if (pairs.empty()) throw InputError(file.string() + ": no image pairs in the file");
  return pairs;
}

nlohmann::json MatchImportSummary::ToJson() const {
  return {{"status", status == StageStatus::kCompleted ? "completed" : "cancelled"},
          {"num_pairs", num_pairs},
          {"num_matched", num_matched},
          {"num_reused", num_reused},
          {"num_verified", num_verified},
          {"num_matches", num_matches},
          {"num_inliers", num_inliers},
          {"seconds", seconds}};
}

namespace {

// The workspace's images by name, with their cameras and keypoint counts.
struct WorkspaceImages {
  std::vector<Image> images;  // by image id
  std::map<std::string, size_t> index_of_name;
  std::map<camera_t, Camera> cameras;
  std::map<image_t, size_t> num_keypoints;
};

WorkspaceImages ReadImages(const Database& database) {
  WorkspaceImages workspace;
  workspace.images = database.ReadAllImages();
  for (size_t i = 0; i < workspace.images.size(); ++i) {
    workspace.index_of_name[workspace.images[i].name] = i;
  }
  for (Camera& camera : database.ReadAllCameras()) workspace.cameras[camera.camera_id] = camera;
  workspace.num_keypoints = database.ReadNumKeypointsPerImage();
  return workspace;
}

// Each pair checked against the workspace: its two images' indices.
std::vector<ImageIndexPair> CheckPairs(const std::vector<ImportedPair>& pairs,
                                       const WorkspaceImages& workspace,
                                       const std::string& database) {
  std::vector<ImageIndexPair> indices;
  std::map<std::pair<size_t, size_t>, std::string> seen;
  for (const ImportedPair& pair : pairs) {
    size_t index[2];
    const std::string* names[2] = {&pair.name1, &pair.name2};
    for (int side = 0; side < 2; ++side) {
      const auto it = workspace.index_of_name.find(*names[side]);
      if (it == workspace.index_of_name.end()) {
        throw InputError(pair.where + ": no image '" + *names[side] + "' in workspace " + database);
      }
      index[side] = it->second;
      if (!workspace.num_keypoints.count(workspace.images[index[side]].image_id)) {
        throw InputError(pair.where + ": image '" + *names[side] +
                         "' has no features in the workspace; import them first");
      }
    }
    if (index[0] == index[1]) {
      throw InputError(pair.where + ": a pair of image '" + pair.name1 + "' with itself");
    }
    const auto key = std::minmax(index[0], index[1]);
    const auto [it, added] = seen.emplace(key, pair.where);
    if (!added)
      throw InputError(pair.where + ": the pair is given twice (first at " + it->second + ")");
    const size_t count1 = workspace.num_keypoints.at(workspace.images[index[0]].image_id);
    const size_t count2 = workspace.num_keypoints.at(workspace.images[index[1]].image_id);
    for (size_t m = 0; m < pair.matches.size(); ++m) {
      const FeatureMatch& match = pair.matches[m];
      if (match.point2D_idx1 < count1 && match.point2D_idx2 < count2) continue;
      const bool first = match.point2D_idx1 >= count1;
      const std::string where = m < pair.match_lines.size()
                                    ? pair.where.substr(0, pair.where.rfind(':')) + ":" +
                                          std::to_string(pair.match_lines[m])
                                    : pair.where + " row " + std::to_string(m);
      throw InputError(where + ": keypoint index " +
                       std::to_string(first ? match.point2D_idx1 : match.point2D_idx2) + " of '" +
                       (first ? pair.name1 : pair.name2) + "' is out of range: it has " +
                       std::to_string(first ? count1 : count2) + " keypoints");
    }
    indices.emplace_back(index[0], index[1]);
  }
  return indices;
}

// The staleness rule of the match stage for raw matches: matches of another source, or
// geometries verified otherwise, are discarded; this call's provenance is recorded.
void InvalidateForRawMatches(const WorkspaceDescriptors& descriptors, const MatchSettings& settings,
                             bool verified, Database* database) {
  const nlohmann::json matches = {{"features", descriptors.features_provenance},
                                  {"matcher", {{"imported", "tessera import"}, {"format", "raw"}}}};
  nlohmann::json verification = settings.verification.ToJson();
  verification["seed"] = settings.seed;
  const nlohmann::json geometries = {
      {"matches", matches},
      {"verification", verified ? nlohmann::json("given as verified") : verification}};
  const auto stored_matches = database->ReadStageProvenance(Database::kMatchesStage);
  if (stored_matches && *stored_matches != matches && database->NumMatchedPairs() > 0) {
    spdlog::warn(
        "import: the workspace's matches were made by matcher '{}'; discarding them for the "
        "imported ones",
        stored_matches->value("matcher", nlohmann::json::object()).value("plugin", "?"));
    database->ClearMatches();
  }
  const auto stored_geometries = database->ReadStageProvenance(Database::kTwoViewGeometriesStage);
  if (stored_geometries && *stored_geometries != geometries) {
    spdlog::info("import: the matches' verification changed; verifying them again");
    database->ClearTwoViewGeometries();
  }
  database->WriteStageProvenance(Database::kMatchesStage, matches);
  database->WriteStageProvenance(Database::kTwoViewGeometriesStage, geometries);
}

// Raw matches: stored and verified (or taken as verified) pair by pair.
void StoreRawMatches(const WorkspaceImages& workspace, const MatchSettings& settings,
                     const std::vector<ImportedPair>& pairs,
                     const std::vector<ImageIndexPair>& indices, bool verified, Database* database,
                     const StageControl& control, MatchImportSummary* summary) {
  std::mutex mutex;
  size_t done = 0;
  control.Report("import", 0, pairs.size());
  ParallelFor(pairs.size(), settings.num_threads, [&](size_t p) {
    if (control.Cancelled()) return;
    const Image& image1 = workspace.images[indices[p].first];
    const Image& image2 = workspace.images[indices[p].second];
    const FeatureMatches& matches = pairs[p].matches;
    {
      std::lock_guard<std::mutex> lock(mutex);
      if (database->ExistsTwoViewGeometry(image1.image_id, image2.image_id) &&
          database->ExistsMatches(image1.image_id, image2.image_id) &&
          database->ReadMatches(image1.image_id, image2.image_id) == matches) {
        ++summary->num_reused;
        control.Report("import", ++done, pairs.size());
        return;
      }
    }
    TwoViewGeometry geometry;
    if (verified) {
      geometry.config = TwoViewGeometry::UNCALIBRATED;
      geometry.inlier_matches = matches;
    } else {
      geometry = EstimateTwoViewGeometry(
          workspace.cameras.at(image1.camera_id), database->ReadKeypoints(image1.image_id),
          workspace.cameras.at(image2.camera_id), database->ReadKeypoints(image2.image_id), matches,
          settings.verification,
          DeriveSeed(settings.seed, ImagePairToPairId(image1.image_id, image2.image_id)));
    }
    std::lock_guard<std::mutex> lock(mutex);
    Database::Transaction transaction(database);
    database->WriteMatches(image1.image_id, image2.image_id, matches);
    database->WriteTwoViewGeometry(image1.image_id, image2.image_id, geometry);
    transaction.Commit();
    ++summary->num_matched;
    control.Report("import", ++done, pairs.size());
  });
}

// Pairs to match: the match stage's own matching and verification of one pair.
void MatchListedPairs(const Workspace& workspace, const WorkspaceImages& images,
                      const MatchSettings& settings, const WorkspaceDescriptors& descriptors,
                      const std::vector<ImageIndexPair>& indices, const StageControl& control,
                      MatchImportSummary* summary) {
  Database* database = &workspace.database();
  MatchPlan plan;
  plan.images = images.images;
  plan.cameras = images.cameras;
  plan.pairs = indices;
  for (const auto& [i, j] : indices) {
    const image_t id1 = plan.images[i].image_id, id2 = plan.images[j].image_id;
    if (database->ExistsMatches(id1, id2) && database->ExistsTwoViewGeometry(id1, id2)) {
      ++summary->num_reused;
    } else {
      plan.todo.emplace_back(i, j);
    }
  }
  spdlog::info("import: {} pairs to match with '{}' ({} already done)", plan.todo.size(),
               settings.matcher->name(), summary->num_reused);
  PairMatchVerifier verifier(settings, plan, descriptors, database, database);
  std::mutex mutex;
  size_t done = 0;
  control.Report("import", 0, plan.todo.size());
  ParallelFor(plan.todo.size(), settings.num_threads, [&](size_t k) {
    if (control.Cancelled()) return;
    verifier.Run(plan.todo[k]);
    std::lock_guard<std::mutex> lock(mutex);
    ++summary->num_matched;
    control.Report("import", ++done, plan.todo.size());
  });
}

}  // namespace

MatchImportSummary ImportMatches(const Workspace& workspace, const MatchSettings& settings,
                                 MatchImportType type, const std::vector<ImportedPair>& pairs,
                                 const std::string& source, bool verified,
                                 const StageControl& control) {
  const Timer timer;
  MatchImportSummary summary;
  summary.num_pairs = pairs.size();
  Database* database = &workspace.database();
  const WorkspaceDescriptors descriptors = ReadWorkspaceDescriptors(*database);
  const WorkspaceImages images = ReadImages(*database);
  const std::vector<ImageIndexPair> indices = CheckPairs(pairs, images, database->path().string());
  if (type == MatchImportType::kPairs) {
    if (settings.matcher == nullptr || !*settings.matcher) {
      throw std::logic_error("ImportMatches: pairs to match need a matcher");
    }
    InvalidateStaleResults(settings, descriptors, database);
    MatchListedPairs(workspace, images, settings, descriptors, indices, control, &summary);
  } else {
    InvalidateForRawMatches(descriptors, settings, verified, database);
    StoreRawMatches(images, settings, pairs, indices, verified, database, control, &summary);
  }
  if (summary.num_matched + summary.num_reused < pairs.size()) {
    summary.status = StageStatus::kCancelled;
    summary.seconds = timer.ElapsedSeconds();
    spdlog::info("import: cancelled after {} of {} pairs", summary.num_matched + summary.num_reused,
                 pairs.size());
    return summary;
  }
  // The pairs of the file are the selection `map` maps.
  std::vector<image_pair_t> pair_ids;
  for (const auto& [i, j] : indices) {
    const image_t id1 = images.images[i].image_id, id2 = images.images[j].image_id;
    pair_ids.push_back(ImagePairToPairId(std::min(id1, id2), std::max(id1, id2)));
    const TwoViewGeometry geometry = database->ReadTwoViewGeometry(id1, id2);
    summary.num_matches += database->ReadMatches(id1, id2).size();
    summary.num_inliers += geometry.inlier_matches.size();
    if (IsVerified(geometry) && !geometry.inlier_matches.empty()) ++summary.num_verified;
  }
  std::sort(pair_ids.begin(), pair_ids.end());
  database->WriteSelectedPairs(pair_ids,
                               {{"imported", source},
                                {"format", type == MatchImportType::kPairs ? "pairs" : "raw"},
                                {"num_pairs", pair_ids.size()}});
  summary.seconds = timer.ElapsedSeconds();
  spdlog::info(
      "import: {} pairs from {} ({} {}, {} already held): {} verified, {} of {} matches "
      "inliers; {:.2f} s",
      summary.num_pairs, source, summary.num_matched,
      type == MatchImportType::kPairs ? "matched" : (verified ? "taken as verified" : "verified"),
      summary.num_reused, summary.num_verified, summary.num_inliers, summary.num_matches,
      summary.seconds);
  return summary;
}

}  // namespace tessera
