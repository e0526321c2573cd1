#pragma once

// `tessera bench`: several manifests (and COLMAP) on the same images, compared.

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace tessera {

struct BenchOptions {
  std::string images;
  std::string ground_truth;  // empty: no accuracy columns
  std::string output;        // folder of the workspaces, one per manifest
  std::string json_file;     // each empty: not written
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
  std::vector<std::string> manifests;
};

// What a bench gave: the exit code RunBench returns, and the JSON that --json writes
// ({"images", "ground_truth", "hardware_threads", "rows": [...]}).
struct BenchReport {
  int exit_code = 0;
  nlohmann::json json;
};

// Runs every manifest as its own `tessera run` child process (this executable), reads
// back each run's run_summary.json and mapping_summary.json (RunSummary,
// MappingSummary), prints the Markdown table and writes the files asked for. Returns
// the exit code: 0 when every row ended with 0, else the first failing row's documented
// code (2, 3 or 4), or 1. Throws InputError for bad options or a malformed manifest.
int RunBench(const BenchOptions& options);
// The same, with the rows (for the Python module).
BenchReport RunBenchReport(const BenchOptions& options);

}  // namespace tessera
