// `tessera eval MODEL GT [--json]`: accuracy of a COLMAP-format model against ground-truth
// poses (Strecha *.camera files, a transforms.json or another model), as eval_gt.py
// scores it.

#include <iostream>
#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "eval/evaluation.h"
#include "eval/ground_truth.h"
#include "pipeline/workspace.h"
#include "tessera/errors.h"
#include "tessera/io/colmap_model_io.h"
#include "util/exit_codes.h"

namespace tessera {

CommandRegistration RegisterEvalCommand(CLI::App& app, const GlobalOptions&) {
  struct Options {
    std::string model;
    std::string ground_truth;
    bool json = false;
  };
  auto options = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand("eval", "Score a model's camera poses against ground truth");
  sub->add_option("MODEL", options->model, "COLMAP model folder (cameras/images/points3D)")
      ->required();
  sub->add_option("GT", options->ground_truth,
                  "Ground truth: a folder of *.camera files, a transforms.json or a COLMAP "
                  "model folder")
      ->required();
  sub->add_flag("--json", options->json, "Print JSON instead of a table");

  auto run = [options]() {
    // A model of a workspace is read while no run can rewrite it.
    const auto workspaces = HoldEnclosingWorkspaces({options->model});
    const Reconstruction model = ReadColmapModel(options->model);
    const auto ground_truth = ReadGroundTruth(options->ground_truth);
    const EvaluationResult result = EvaluateReconstruction(model, ground_truth, options->model);
    if (options->json) {
      std::cout << result.ToJson().dump(2) << std::endl;
    } else {
      std::cout << result.ToTable() << std::flush;
    }
    // Figures that cannot be computed are the user's to fix (wrong ground truth, names
    // that do not match), so they end as bad input after the partial result.
    if (!result.aligned) {
      throw InputError("Cannot score " + options->model + " against " + options->ground_truth +
                       ": " + result.error + ".");
    }
    return static_cast<int>(kExitSuccess);
  };
  return {sub, run};
}

}  // namespace tessera
