#pragma once

// `tessera bench`: several manifests (and COLMAP) on the same images, compared.

#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace tessera {

// How long each child of a bench may run (a Tessera row's `tessera run`, each COLMAP
// step) when --child-timeout does not say: generous, so that only a hang reaches it.
constexpr double kBenchChildTimeoutSeconds = 12 * 3600;
// How long a COLMAP binary has to answer `-h` (at most --child-timeout).
constexpr double kColmapProbeTimeoutSeconds = 60;

struct BenchOptions {
  std::string images;
  std::string ground_truth;  // empty: no accuracy columns
  // The bench's folder: OUTPUT/tessera/<row> for each manifest, OUTPUT/colmap/<binary>/
  // for COLMAP's rows (colmap_rows.h), each row's folder its own.
  std::string output;
  std::string json_file;  // each empty: not written
  std::string csv_file;
  std::string chart_file;
  std::string camera_K;
  bool camera_per_folder = false;  // every run with --camera-per-folder, COLMAP's per folder
  bool with_colmap = false;
  // --colmap: the COLMAP binaries to run, in order (each implies with_colmap); empty:
  // TESSERA_COLMAP or ../shared/anchors/colmap-4/bin/colmap, then colmap on the PATH
  // (FindColmapBinaries in colmap_rows.h).
  std::vector<std::string> colmap_binaries;
  // COLMAP's mappers alone, on a copy of the first successful row's database (implies
  // with_colmap), instead of COLMAP's whole pipeline.
  bool colmap_mapper_only = false;
  int threads = 0;
  // Seconds each child may run before it is stopped and its row says "timed out"; 0:
  // kBenchChildTimeoutSeconds (and kColmapProbeTimeoutSeconds for `colmap -h`).
  double child_timeout = 0;
  // Polled while children run (may be empty): once true (Ctrl-C), the running child's
  // process group is stopped, no other row starts, and the bench ends "interrupted".
  std::function<bool()> stop_requested;
  std::vector<std::string> manifests;
};

// What a bench gave: the exit code RunBench returns, and the JSON that --json writes
// ({"images", "ground_truth", "hardware_threads", "rows": [...]}).
struct BenchReport {
  int exit_code = 0;
  bool interrupted = false;  // stop_requested came true: exit_code is 130
  nlohmann::json json;
};

// Runs every manifest as its own `tessera run` child process (this executable), reads
// back each run's run_summary.json and mapping_summary.json (RunSummary,
// MappingSummary), prints the Markdown table and writes the files asked for. Rows are
// independent: a row that fails (its child's exit code, a timeout, a COLMAP output that
// does not read) has its error in the table and the JSON, and the other rows run.
// Returns the exit code: 0 when every row ended with 0, 130 when interrupted, else the
// first failing row's: its documented code (2, 3 or 4), 2 for a COLMAP row or a timeout,
// or 1. Throws InputError for bad options, a malformed manifest or a COLMAP binary that
// cannot be used, before any row runs.
int RunBench(const BenchOptions& options);
// The same, with the rows (for the Python module).
BenchReport RunBenchReport(const BenchOptions& options);

}  // namespace tessera
