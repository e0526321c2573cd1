// `tessera import --output WS --features DIR [--matches FILE] [--match-type pairs|raw]
// [--verified] [--images DIR] [--manifest M] [--json]`: features and matches made by
// another program (COLMAP's feature_importer and matches_importer formats) into a
// workspace; toolbox/import_workspace.h does the work.

#include <iostream>

#include "cli/commands.h"
#include "cli/interrupt.h"
#include "pipeline/stage_arguments.h"
#include "toolbox/import_workspace.h"
#include "util/exit_codes.h"

namespace tessera {

CommandRegistration RegisterImportCommand(CLI::App& app, const GlobalOptions&) {
  struct Options {
    std::string output, features, matches, images;
    std::string match_type = "raw";
    bool verified = false;
    bool json = false;
    StageArguments arguments;
  };
  auto options = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand(
      "import", "Import features and matches made by another program (COLMAP's text formats)");
  sub->add_option("--output", options->output, "Workspace folder (database.db, models)")
      ->required();
  sub->add_option("--features", options->features,
                  "Folder of NAME.txt per image: `N D`, then N lines `x y scale orientation "
                  "d1 ... dD`")
      ->required();
  sub->add_option("--matches", options->matches,
                  "A matches file: image pairs (`name1 name2` lines) or raw matches");
  sub->add_option("--match-type", options->match_type,
                  "pairs: match the listed pairs with the manifest's matcher; raw: blocks of "
                  "`name1 name2` and `idx1 idx2` lines (default: raw)")
      ->check(CLI::IsMember({"pairs", "raw"}));
  sub->add_flag("--verified", options->verified,
                "Raw matches are inliers already: store them without geometric verification");
  sub->add_option("--images", options->images,
                  "Folder of the images (default: the one the workspace records)");
  sub->add_option("--manifest", options->arguments.manifest,
                  "Pipeline manifest (default: default.json): camera settings, matcher");
  sub->add_option("--camera-K", options->arguments.camera_K,
                  "Known intrinsics: a text file with the 3x3 matrix K (overrides EXIF)");
  sub->add_option("--threads", options->arguments.threads,
                  "Worker threads (default: manifest, else all cores)")
      ->check(CLI::Range(0, 1024));
  sub->add_flag("--json", options->json, "Print a JSON summary on stdout");
  return {sub, [options]() {
            ImportOptions import;
            import.output = options->output;
            import.images = options->images;
            import.verified = options->verified;
            import.match_type =
                options->match_type == "pairs" ? MatchImportType::kPairs : MatchImportType::kRaw;
            if (options->verified && import.match_type == MatchImportType::kPairs) {
              throw InputError(
                  "--verified: only for --match-type raw (listed pairs are matched "
                  "and verified by the manifest's matcher)");
            }
            // Every file is read before the workspace is touched.
            import.features = FeatureFolderSource(options->features);
            if (!options->matches.empty()) {
              import.matches_source = options->matches;
              import.matches = import.match_type == MatchImportType::kPairs
                                   ? ParsePairsFile(options->matches)
                                   : ParseRawMatchesFile(options->matches);
            }
            InterruptToken();
            const PipelineContext context = LoadPipelineContext(options->arguments);
            StageControl control;
            control.cancel = &InterruptToken();
            const ImportResult result = RunImport(context, import, control);
            if (options->json) std::cout << result.ToJson().dump(2) << std::endl;
            return result.status == StageStatus::kCancelled ? ReportInterrupted("import")
                                                            : static_cast<int>(kExitSuccess);
          }};
}

}  // namespace tessera
