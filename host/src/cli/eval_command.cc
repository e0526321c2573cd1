// `tessera eval MODEL GT [--json]`: accuracy of a COLMAP-format model against ground-truth
// poses (Strecha *.camera files, a transforms.json or another model), as eval_gt.py
// scores it.

#include <iostream>
#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "pipeline/evaluate_model.h"
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
    const EvaluationResult result = EvaluateModelFolder(options->model, options->ground_truth);
    if (options->json) {
      std::cout << result.ToJson().dump(2) << std::endl;
    } else {
      std::cout << result.ToTable() << std::flush;
    }
    // Figures that cannot be computed end as bad input after the partial result.
    if (!result.aligned) throw UnscoredError(result, options->model, options->ground_truth);
    return static_cast<int>(kExitSuccess);
  };
  return {sub, run};
}

}  // namespace tessera
