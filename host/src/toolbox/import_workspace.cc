#include "toolbox/import_workspace.h"

#include "pipeline/workspace.h"

namespace tessera {

nlohmann::json ImportResult::ToJson() const {
  nlohmann::json json = nlohmann::json::object();
  if (features) json["features"] = features->ToJson();
  if (matches) json["matches"] = matches->ToJson();
  return json;
}

ImportResult RunImport(const PipelineContext& context, const ImportOptions& options,
                       const StageControl& control) {
  if (!options.features && !options.matches) {
    throw InputError("import: give features, matches or both");
  }
  if (options.matches && options.match_type == MatchImportType::kPairs) {
    context.Require("matcher", "import (pairs to match)");
  }
  // A workspace is made only for features; matches need one that holds them.
  Workspace::Options open;
  if (!options.features) open.require_database_for = "import";
  const auto workspace = Workspace::Open(options.output, open);
  context.UseWorkspaceCaches(*workspace);
  const MatchSettings matching = context.MakeMatchSettings();
  ImportResult result;
  if (options.features) {
    result.features = ImportFeatures(
        *workspace, MakeFeatureImportSettings(context, matching, *workspace, options.images),
        *options.features, control);
    if (result.features->status == StageStatus::kCancelled) {
      result.status = StageStatus::kCancelled;
      return result;
    }
  }
  if (options.matches) {
    result.matches = ImportMatches(*workspace, matching, options.match_type, *options.matches,
                                   options.matches_source, options.verified, control);
    result.status = result.matches->status;
  }
  return result;
}

}  // namespace tessera
