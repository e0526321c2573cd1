#pragma once

// `tessera import` and its Python twins as one call on a workspace: features, then
// matches, with the settings of a run's context.

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "pipeline/pipeline_context.h"
#include "toolbox/feature_import.h"
#include "toolbox/match_import.h"

namespace tessera {

struct ImportOptions {
  std::filesystem::path output;  // the workspace
  std::filesystem::path images;  // empty: the folder the workspace records
  std::optional<FeatureSource> features;
  // Matches, when given: the pairs of `matches_source` (a file, or "matches" for arrays).
  std::optional<std::vector<ImportedPair>> matches;
  MatchImportType match_type = MatchImportType::kRaw;
  std::string matches_source;
  bool verified = false;  // raw matches are stored as their own inliers
};

struct ImportResult {
  std::optional<FeatureImportSummary> features;
  std::optional<MatchImportSummary> matches;
  StageStatus status = StageStatus::kCompleted;
  // {"features": {...}, "matches": {...}}, the parts that ran.
  nlohmann::json ToJson() const;
};

// Opens the workspace as its writer, imports the features (when given) and then the
// matches (when given; raw matches need no matcher, pairs the manifest's). Throws
// InputError for bad input, before anything of that part is written.
ImportResult RunImport(const PipelineContext& context, const ImportOptions& options,
                       const StageControl& control = {});

}  // namespace tessera
