#pragma once

// What Tessera's rows and COLMAP's rows of `tessera bench` share: the row, the figures
// read back from a database and a model, and bench's scratch folders. Each row's process
// runs through util/child_process.h (RunChild: its exit code, time and peak memory).

#include <filesystem>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "bench/bench.h"
#include "eval/ground_truth.h"
#include "pipeline/run_summary.h"
#include "tessera/reconstruction.h"
#include "util/child_process.h"

namespace tessera {

constexpr double kBenchNaN = std::numeric_limits<double>::quiet_NaN();

// One system on the images: a manifest, or COLMAP.
struct BenchRow {
  std::string name;  // the manifest's file stem, or "colmap-<version>-<mapper>"
  // detector / pair_selector / matcher / bundle_adjuster / exporters, each with its
  // version once the run has said it (plugins_used)
  std::string plugins;
  std::vector<PluginUsed> plugins_used;  // from run_summary.json
  std::string workspace;
  std::string log;  // the row's log file, named when the row fails
  int exit_code = 0;
  // Why the row failed, one line ("timed out after 5 s", COLMAP's last log line, a file
  // that does not read); empty when it did not.
  std::string error;
  bool colmap = false;              // one of COLMAP's rows
  std::string extract_shared_with;  // the row whose features this one started from
  std::string matches_of;           // the row whose database this one mapped (a copy)
  double extract_seconds = kBenchNaN;
  double match_seconds = kBenchNaN;
  double map_seconds = kBenchNaN;
  double total_seconds = kBenchNaN;
  double peak_memory_mb = kBenchNaN;
  size_t num_pairs = 0;
  // The pairs each pair selector chose, from run_summary.json; their union is the
  // run's pair count.
  std::vector<SelectorPairs> pairs_per_selector;
  size_t num_selected_pairs = 0;
  size_t num_verified = 0;
  double mean_inliers = kBenchNaN;
  size_t num_images = 0;
  size_t num_registered = 0;  // in model 0
  size_t num_models = 0;
  size_t num_points = 0;
  double mean_track_length = kBenchNaN;
  double mean_reprojection_error = kBenchNaN;
  // With --gt, model 0 against it.
  double position_error_mean = kBenchNaN;
  double position_error_relative = kBenchNaN;  // of the scene extent
  double rotation_error_mean_deg = kBenchNaN;
  // Registered images more than kWrongRegistrationDeg off; -1 without ground truth.
  int num_wrongly_registered = -1;
};

using BenchGroundTruth = std::map<std::string, GroundTruthPose>;

// Pairs matched, pairs verified and their mean number of inliers, from a database.
void ReadMatchingFigures(const std::filesystem::path& database_file, BenchRow* row);

// Model 0's figures (registered images, points, track length, reprojection error) and,
// with ground truth (not nullptr), its errors.
void ReadModelFigures(const Reconstruction& model, const BenchGroundTruth* ground_truth,
                      BenchRow* row);

// A model scored against the ground truth, when there is one (nullptr: none).
void ScoreModel(const Reconstruction& model, const BenchGroundTruth* ground_truth, BenchRow* row);

// Throws InputError naming `folder` when it exists and bench did not make it.
void CheckBenchWorkspace(const std::filesystem::path& folder);

// Throws InputError naming `folder` (OUTPUT/tessera, OUTPUT/colmap, ...: a folder of row
// folders) when it exists and is not a folder (a link to one included).
void CheckBenchFolder(const std::filesystem::path& folder);

// The last line of `log` with text on it, read from its last 64 KiB, as a one-line
// excerpt (PrintableExcerpt); with `marker`, the last line holding it. Empty when none.
std::string LastLogLine(const std::filesystem::path& log, const std::string& marker = "");

// How long each of the bench's children may run: --child-timeout, else
// kBenchChildTimeoutSeconds.
double BenchChildTimeout(const BenchOptions& options);

// RunChild's options for a child of the bench: its output appended to `log`, the bench's
// timeout and its stop request.
RunChildOptions BenchChildOptions(const BenchOptions& options, const std::filesystem::path& log);

// The error of a child that did not end with 0: "timed out after N s", "interrupted",
// "crashed (signal N)", or "exited with code N", and `detail` (a log line) after it.
std::string ChildFailure(const ChildRun& child, double timeout_seconds, const std::string& detail);

// Empties a row's workspace (CheckBenchWorkspace passed) and marks it as bench's.
void ResetBenchWorkspace(const std::filesystem::path& folder);

}  // namespace tessera
