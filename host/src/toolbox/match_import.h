#pragma once

// `tessera import --matches`: COLMAP matches_importer's two formats into a workspace
// that holds features: image pairs to match with the manifest's matcher, or matches
// made elsewhere (LightGlue, SuperGlue), verified with the core's two-view geometry
// estimation unless the user says they are verified already.

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "pipeline/match_stage.h"
#include "pipeline/stage_control.h"
#include "pipeline/workspace.h"

namespace tessera {

// One pair of a match file, with its matches (raw) or none (pairs).
struct ImportedPair {
  std::string name1, name2;
  FeatureMatches matches;           // point2D_idx1 indexes name1's keypoints
  std::string where;                // "FILE:LINE" of the pair's line, or "matches[('a', 'b')]"
  std::vector<size_t> match_lines;  // the line of each match (text files), for messages
};

enum class MatchImportType { kPairs, kRaw };

// `pairs`: one pair per line, `name1 name2` (blank lines and lines starting with # are
// skipped). Throws InputError naming the file and line for a line that is not two names.
std::vector<ImportedPair> ParsePairsFile(const std::filesystem::path& file);
// `raw`: blocks of a line `name1 name2` and then lines `idx1 idx2` (keypoint indices,
// from 0), blocks separated by a blank line. Throws InputError naming the file and line
// for a header that is not two names or an index line that is not two whole numbers.
std::vector<ImportedPair> ParseRawMatchesFile(const std::filesystem::path& file);

struct MatchImportSummary {
  StageStatus status = StageStatus::kCompleted;
  size_t num_pairs = 0;     // pairs in the file
  size_t num_matched = 0;   // pairs matched by the matcher (pairs) or written (raw) now
  size_t num_reused = 0;    // pairs the workspace held already, with the same matches
  size_t num_verified = 0;  // pairs of the file with a verified geometry
  size_t num_matches = 0;   // matches of the file's pairs (raw: given; pairs: found)
  size_t num_inliers = 0;   // inlier matches of the file's pairs
  double seconds = 0;
  nlohmann::json ToJson() const;
};

// Stores the pairs of a match file in the workspace. Every pair is checked first: both
// images in the workspace with features, two different images, each pair once, every
// keypoint index in range (InputError naming the file and line, or the pair).
//   kPairs: the pairs are matched with settings.matcher and verified, exactly as
//           `match` does (the same provenance, so a later `match` with the same
//           manifest reuses them);
//   kRaw:   the matches are stored as given (provenance: imported), then verified with
//           settings.verification, or, with `verified`, stored as their own inliers
//           (config UNCALIBRATED, as COLMAP's matches_importer does). Matches of a
//           matcher held before are discarded (two sources never mix).
// The pairs become the workspace's pair selection, which `map` maps; each pair is its own
// transaction, and a call cut short resumes. `control`: progress ("import", pairs done,
// pairs to do) and cancellation between pairs.
MatchImportSummary ImportMatches(const Workspace& workspace, const MatchSettings& settings,
                                 MatchImportType type, const std::vector<ImportedPair>& pairs,
                                 const std::string& source, bool verified,
                                 const StageControl& control = {});

}  // namespace tessera
