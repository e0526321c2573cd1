// `partition`: the workspace's view graph cut into overlapping clusters
// (OUTPUT/clusters.json), which `map --cluster K` maps one by one and `merge --stage map`
// merges. The work is in partition/.

#include <memory>

#include "cli/commands.h"
#include "partition/partition_stage.h"
#include "pipeline/stage_arguments.h"
#include "pipeline/workspace.h"
#include "util/exit_codes.h"

namespace tessera {

CommandRegistration RegisterPartitionCommand(CLI::App& app, const GlobalOptions&) {
  struct Options {
    std::string output;
    StageArguments arguments;
  };
  auto options = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand(
      "partition", "Cut the view graph into overlapping clusters (OUTPUT/clusters.json)");
  sub->add_option("--output", options->output, "Workspace folder, matched")->required();
  sub->add_option("--manifest", options->arguments.manifest,
                  "Pipeline manifest (default: default.json); its distributed.cluster_max_images "
                  "and distributed.cluster_overlap set the cut");
  return {sub, [options]() {
            const PipelineContext context = LoadPipelineContext(options->arguments);
            Workspace::Options open;
            open.require_database_for = "partition";
            const auto workspace = Workspace::Open(options->output, open);
            PartitionWorkspace(*workspace, context);
            return static_cast<int>(kExitSuccess);
          }};
}

}  // namespace tessera
