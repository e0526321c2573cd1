// `tessera triangulate --output WS (--model KNOWN | --poses transforms.json) [--model-index N]
// [--refine-intrinsics] [--manifest M] [--threads N] [--json]`: points for poses known from
// elsewhere, from the workspace's verified matches, every pose held
// (toolbox/triangulate_known_poses.h).

#include <spdlog/spdlog.h>

#include <iostream>
#include <memory>

#include "cli/commands.h"
#include "toolbox/triangulate_known_poses.h"
#include "util/exit_codes.h"

namespace tessera {

CommandRegistration RegisterTriangulateCommand(CLI::App& app, const GlobalOptions&) {
  struct Options {
    TriangulateArguments arguments;
    std::string output;
    std::string model;
    std::string poses;
    bool json = false;
  };
  auto options = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand(
      "triangulate", "Triangulate the workspace's matches for known poses (poses held)");
  sub->add_option("--output", options->output, "Workspace folder (database.db with matches)")
      ->required();
  auto* model = sub->add_option("--model", options->model,
                                "COLMAP model (text or binary) with the cameras and poses");
  auto* poses = sub->add_option("--poses", options->poses,
                                "transforms.json (nerfstudio / instant-ngp) with the cameras "
                                "and poses");
  model->excludes(poses);
  sub->callback([model, poses] {
    if (model->count() == 0 && poses->count() == 0) throw CLI::RequiredError("--model or --poses");
  });
  sub->add_option("--model-index", options->arguments.model_index,
                  "Written as OUTPUT/sparse/N (default 0)")
      ->check(AtLeast(0));
  sub->add_flag("--refine-intrinsics", options->arguments.refine_intrinsics,
                "Refine focal lengths and distortion with the manifest's bundle adjuster, "
                "poses held");
  sub->add_option("--manifest", options->arguments.stage.manifest,
                  "Pipeline manifest, for its bundle adjuster (default: default.json)");
  sub->add_option("--threads", options->arguments.stage.threads,
                  "Worker threads (default: manifest, else all cores)")
      ->check(CLI::Range(0, 1024));
  sub->add_flag("--json", options->json, "Print a JSON summary on stdout");

  auto run = [options]() {
    options->arguments.output = options->output;
    options->arguments.model = options->model;
    options->arguments.poses = options->poses;
    const TriangulateSummary summary = TriangulateWorkspace(options->arguments);
    spdlog::info(
        "triangulate: {} images in common, {} points, {} observations, mean reprojection error "
        "{:.3f} px, written to {} in {:.2f} s",
        summary.num_images_in_common, summary.num_points3D, summary.num_observations,
        summary.mean_reprojection_error, summary.model_folder.string(), summary.seconds);
    if (options->json) std::cout << summary.ToJson().dump(2) << std::endl;
    return static_cast<int>(kExitSuccess);
  };
  return {sub, run};
}

}  // namespace tessera
