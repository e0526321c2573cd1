// `tessera eval MODEL GT [--json] [--no-align [--gt-origin LAT,LON,ALT]] [--alignment FILE]`:
// accuracy of a
// COLMAP-format model against ground-truth poses (Strecha *.camera files, a transforms.json or
// another model), as eval_gt.py scores it.

#include <cmath>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "pipeline/evaluate_model.h"
#include "toolbox/model_alignment.h"
#include "util/exit_codes.h"

namespace tessera {
namespace {

// The altitudes georeference.json may hold (io/georeference_io.cc), so that the origin
// given here is checked as the one Tessera writes.
constexpr double kMaxAltitudeM = 1e5;

}  // namespace

CommandRegistration RegisterEvalCommand(CLI::App& app, const GlobalOptions&) {
  struct Options {
    std::string model;
    std::string ground_truth;
    bool json = false;
    bool no_align = false;
    std::string gt_origin;
    std::string alignment;
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
  sub->add_flag("--no-align", options->no_align,
                "Score without a similarity alignment: the model's GPS-anchored frame "
                "(georeference.json) against the ground truth's");
  sub->add_option("--gt-origin", options->gt_origin,
                  "With --no-align: the ground truth is in east-north-up metres about "
                  "LAT,LON,ALT (degrees, degrees, metres)");
  sub->add_option("--alignment", options->alignment,
                  "An alignment.json of `tessera align`: the model is moved by it first (with "
                  "--no-align: then scored in the ground truth's frame as it is)");

  auto run = [options]() {
    std::optional<Georeference> gt_origin;
    if (!options->gt_origin.empty()) {
      double values[3];
      char tail = 0;
      if (std::sscanf(options->gt_origin.c_str(), "%lf,%lf,%lf%c", &values[0], &values[1],
                      &values[2], &tail) != 3 ||
          !(std::abs(values[0]) <= 90) || !(std::abs(values[1]) <= 180) ||
          !(std::abs(values[2]) <= kMaxAltitudeM)) {
        throw InputError(
            "--gt-origin: expected LAT,LON,ALT (latitude in [-90, 90], longitude "
            "in [-180, 180] degrees, altitude in [-100000, 100000] metres), got '" +
            options->gt_origin + "'");
      }
      gt_origin = Georeference{values[0], values[1], values[2], "ENU"};
    }
    if (gt_origin && !options->no_align) throw InputError("--gt-origin: needs --no-align");
    std::optional<Similarity3d> moved_by;
    if (!options->alignment.empty()) moved_by = ReadAlignmentFile(options->alignment);
    const EvaluationResult result = EvaluateModelFolder(options->model, options->ground_truth,
                                                        options->no_align, gt_origin, moved_by);
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
