// The self-calibration diagnostic (issue 62), as a benchmark program: a Markdown table
// of the mapper's camera against the true one, and of the position error, after each
// stage (eval/calibration_diagnostic.h). The mapper, its options, the bundle adjuster's
// options and the seed are the manifest's.
//
//   calibration_diagnostic --manifest M --database DB --true-K K.txt --gt GT [--mm]
//       a workspace's verified matches (`tessera run` or `tessera match` made DB), K.txt
//       and the ground-truth poses of the set; --mm: metric ground truth, errors in mm
//   calibration_diagnostic --manifest M --synthetic N [--scene-seed S] [--view-angle A]
//                          [--given-K]
//       a synthetic arc of N views with known K (1600x1200 px, f 1200 px, the principal
//       point 16 px right and 10 px up of the centre, k1 -0.02), no focal-length prior
//       (the default 1.2 times the larger side), 0.5 px noise and 5% wrong matches;
//       every camera sees the whole cube of points, or with --view-angle A each point
//       only from within A degrees of its outward normal (an object's surface)
//       --given-K: the true camera given as a prior (the reference of calibrated.json,
//       whose mapper holds it)
//   --threads T: of the mapper and Ceres (1)
//
// Exit codes: 0, 2 for bad arguments or input (one line naming the file), 1 otherwise.

#include "eval/calibration_diagnostic.h"

#include <spdlog/spdlog.h>

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <iostream>
#include <map>
#include <string>

#include "database/database.h"
#include "eval/calibration_uncertainty.h"
#include "eval/ground_truth.h"
#include "pipeline/load_mapper_input.h"
#include "synthetic_scene.h"
#include "tessera/errors.h"
#include "test_support.h"

namespace tessera {
namespace {

constexpr const char* kUsage =
    "usage: calibration_diagnostic --manifest M (--database DB --true-K K.txt --gt GT [--mm] | "
    "--synthetic N [--scene-seed S] [--view-angle A] [--given-K]) [--threads T]";

struct Arguments {
  std::map<std::string, std::string> values;
  bool mm = false;
  bool given_k = false;
  std::string Get(const std::string& key) const {
    const auto it = values.find(key);
    return it == values.end() ? "" : it->second;
  }
};

// False unless the arguments are one of the two forms of the usage line.
bool Parse(int argc, char** argv, Arguments* arguments) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--mm") {
      arguments->mm = true;
    } else if (arg == "--given-K") {
      arguments->given_k = true;
    } else if ((arg == "--manifest" || arg == "--database" || arg == "--true-K" || arg == "--gt" ||
                arg == "--synthetic" || arg == "--scene-seed" || arg == "--view-angle" ||
                arg == "--threads") &&
               i + 1 < argc) {
      arguments->values[arg] = argv[++i];
    } else {
      return false;
    }
  }
  const bool real = !arguments->Get("--database").empty() && !arguments->Get("--true-K").empty() &&
                    !arguments->Get("--gt").empty();
  const bool synthetic = !arguments->Get("--synthetic").empty();
  return !arguments->Get("--manifest").empty() && real != synthetic &&
         (synthetic || !arguments->given_k);
}

int PositiveInt(const std::string& text, const std::string& option) {
  char* end = nullptr;
  const long value = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || value < 1 || value > 100000) {
    throw InputError(option + " " + text + ": not a whole number from 1 to 100000");
  }
  return static_cast<int>(value);
}

nlohmann::json ReadManifest(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw InputError(path + ": cannot be read");
  try {
    nlohmann::json manifest = nlohmann::json::parse(file);
    const std::string plugin = manifest.at("pipeline").at("mapper").at("plugin");
    if (plugin != "global" && plugin != "incremental") {
      throw InputError(path + ": pipeline.mapper.plugin '" + plugin +
                       "' is neither 'global' nor 'incremental'");
    }
    return manifest;
  } catch (const nlohmann::json::exception& error) {
    throw InputError(path + ": not a manifest with pipeline.mapper.plugin (" + error.what() + ")");
  }
}

// The synthetic scene of the header: no prior, the default focal length a camera
// without EXIF gets (1.2 times the larger side).
testing::SyntheticSceneOptions SyntheticOptions(int num_images, uint64_t seed) {
  testing::SyntheticSceneOptions options;
  options.num_images = num_images;
  options.num_points = 1500;
  options.focal_length = 1200;
  options.width = 1600;
  options.height = 1200;
  options.k1 = -0.02;
  options.principal_point_offset_x = 16;
  options.principal_point_offset_y = -10;
  options.focal_prior = false;
  options.prior_focal_factor = 1.2 * options.width / options.focal_length;
  options.noise_px = 0.5;
  options.outlier_ratio = 0.05;
  options.seed = seed;
  return options;
}

// The scene's true camera (MakeSyntheticScene's): the centre moved by the offsets.
TrueIntrinsics SyntheticTruth(const testing::SyntheticSceneOptions& options) {
  return {options.focal_length,
          options.focal_length,
          options.width / 2.0 + options.principal_point_offset_x,
          options.height / 2.0 + options.principal_point_offset_y,
          {options.k1}};
}

// The reference of a K given and held: the true camera as a prior, every pair's
// geometry calibrated (its essential matrix and pose are the true ones already).
void GiveTrueCamera(const testing::SyntheticSceneOptions& options, MapperInput* input) {
  const TrueIntrinsics truth = SyntheticTruth(options);
  for (auto& [camera_id, camera] : input->cameras) {
    camera.params = {truth.fx, truth.cx, truth.cy, truth.distortion.at(0)};
    camera.has_prior_focal_length = true;
    camera.calibration_source = CalibrationSource::kUser;
  }
  for (MapperInput::Pair& pair : input->pairs) pair.geometry.config = TwoViewGeometry::CALIBRATED;
}

int Run(const Arguments& arguments) {
  const nlohmann::json manifest = ReadManifest(arguments.Get("--manifest"));
  const int threads =
      arguments.Get("--threads").empty() ? 1 : PositiveInt(arguments.Get("--threads"), "--threads");
  const nlohmann::json& pipeline = manifest.at("pipeline");
  const nlohmann::json mapper_options =
      pipeline.at("mapper").value("options", nlohmann::json::object());
  nlohmann::json adjuster_options =
      pipeline.contains("bundle_adjuster")
          ? pipeline["bundle_adjuster"].value("options", nlohmann::json::object())
          : nlohmann::json::object();
  adjuster_options["num_threads"] = threads;
  const uint64_t seed = manifest.value("seed", 0);
  const auto adjuster =
      testing::LoadBundledPlugin<BundleAdjuster>("bundle_adjuster", "ceres", adjuster_options);

  MapperInput input;
  std::map<std::string, GroundTruthPose> truth_poses;
  TrueIntrinsics truth;
  if (!arguments.Get("--synthetic").empty()) {
    const int seed_of_scene = arguments.Get("--scene-seed").empty()
                                  ? 1
                                  : PositiveInt(arguments.Get("--scene-seed"), "--scene-seed");
    testing::SyntheticSceneOptions options =
        SyntheticOptions(PositiveInt(arguments.Get("--synthetic"), "--synthetic"), seed_of_scene);
    if (!arguments.Get("--view-angle").empty()) {
      options.max_view_angle_deg = PositiveInt(arguments.Get("--view-angle"), "--view-angle");
    }
    testing::SyntheticScene scene = testing::MakeSyntheticScene(options);
    truth_poses = scene.GroundTruth();
    truth = SyntheticTruth(options);
    input = std::move(scene.input);
    if (arguments.given_k) GiveTrueCamera(options, &input);
  } else {
    const std::string database = arguments.Get("--database");
    if (!std::filesystem::is_regular_file(database)) throw InputError(database + ": not found");
    truth = ReadTrueIntrinsics(arguments.Get("--true-K"));
    truth_poses = ReadGroundTruth(arguments.Get("--gt"));
    input = LoadMapperInput(Database(database, Database::Mode::kReadOnly));
  }
  CalibrationDiagnosis diagnosis;
  RefinedIntrinsics refined;  // what the mapper's final adjustment refines
  if (pipeline.at("mapper").at("plugin") == "global") {
    GlobalPipelineOptions options = GlobalPipelineOptions::FromJson(mapper_options);
    options.mapper.num_threads = options.finishing.num_threads = threads;
    refined = {options.mapper.ba_refine_focal_length, options.mapper.ba_refine_principal_point,
               options.mapper.ba_refine_extra_params};
    diagnosis =
        DiagnoseGlobalMapper(input, testing::Unguarded(adjuster), options, seed, truth_poses);
  } else {
    IncrementalMapperOptions options = IncrementalMapperOptions::FromJson(mapper_options);
    options.num_threads = threads;
    refined = {options.ba_refine_focal_length, options.ba_refine_principal_point,
               options.ba_refine_extra_params};
    diagnosis =
        DiagnoseIncrementalMapper(input, testing::Unguarded(adjuster), options, seed, truth_poses);
  }
  std::cout << CalibrationTable(diagnosis, truth, arguments.mm ? 1000.0 : 1.0);
  // What the final model says of its own calibration (what `tessera map` writes into
  // mapping_summary.json), beside the truth above.
  const CalibrationUncertainty assessed = AssessCalibration(diagnosis.final_model, refined);
  std::cout << "\nFinal calibration, as the model assesses it";
  if (!assessed.assessed) {
    std::cout << ": not assessed (" << assessed.reason << ")\n";
    return 0;
  }
  std::cout << " (observations' sigma " << assessed.observation_sigma_px << " px):\n";
  for (const IntrinsicUncertainty& parameter : assessed.parameters) {
    std::cout << "- " << parameter.parameter << " = " << parameter.value << ", sigma "
              << parameter.sigma << ", corner shift " << parameter.corner_shift_px << " px"
              << (parameter.weak ? ", weak" : "") << "\n";
  }
  return 0;
}

}  // namespace
}  // namespace tessera

int main(int argc, char** argv) {
  spdlog::set_level(spdlog::level::warn);  // the table alone on stdout, warnings on stderr
  tessera::Arguments arguments;
  if (!tessera::Parse(argc, argv, &arguments)) {
    std::cerr << tessera::kUsage << "\n";
    return 2;
  }
  try {
    return tessera::Run(arguments);
  } catch (const tessera::InputError& error) {
    std::cerr << "calibration_diagnostic: " << error.what() << "\n";
    return 2;
  } catch (const std::exception& error) {
    std::cerr << "calibration_diagnostic: " << error.what() << "\n";
    return 1;
  }
}
