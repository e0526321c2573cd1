// `tessera bench --images DIR [--gt GT] MANIFEST...`: every manifest run on the same
// images, each as its own `tessera run` child process (so that one plugin's crash loses
// no other row, and each row's peak memory is its own), and optionally COLMAP 3.8 on the
// CPU, in the same command on the same machine. Detection is shared: a manifest whose
// detector and camera settings equal an earlier one's starts from a copy of that
// workspace's features (not its matches), and its row says so. Prints a Markdown
// table; --json and --csv write the same rows to files, --chart draws them (gnuplot).

#include "bench/bench.h"

#include <fcntl.h>
#include <spawn.h>
#include <spdlog/spdlog.h>
#include <sys/resource.h>
#include <sys/wait.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <thread>

#include "database/database.h"
#include "eval/evaluation.h"
#include "eval/ground_truth.h"
#include "pipeline/mapping_summary.h"
#include "pipeline/run_summary.h"
#include "pipeline/workspace.h"
#include "tessera/errors.h"
#include "tessera/io/colmap_model_io.h"
#include "tessera/io/file_io.h"
#include "tessera/io/model_statistics.h"
#include "util/exit_codes.h"
#include "util/paths.h"
#include "util/timer.h"

extern char** environ;

namespace tessera {
namespace {

namespace fs = std::filesystem;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// One system on the images: a manifest, or COLMAP.
struct BenchRow {
  std::string name;  // the manifest's file stem, or "colmap"
  // detector / pair_selector / matcher / bundle_adjuster / exporters, each with its
  // version once the run has said it (plugins_used)
  std::string plugins;
  std::vector<PluginUsed> plugins_used;  // from run_summary.json
  std::string workspace;
  int exit_code = 0;
  std::string extract_shared_with;  // the row whose features this one started from
  double extract_seconds = kNaN;
  double match_seconds = kNaN;
  double map_seconds = kNaN;
  double total_seconds = kNaN;
  double peak_memory_mb = kNaN;
  size_t num_pairs = 0;
  // The pairs each pair selector chose, from run_summary.json; their union is the
  // run's pair count.
  std::vector<SelectorPairs> pairs_per_selector;
  size_t num_selected_pairs = 0;
  size_t num_verified = 0;
  double mean_inliers = kNaN;
  size_t num_images = 0;
  size_t num_registered = 0;  // in model 0
  size_t num_models = 0;
  size_t num_points = 0;
  double mean_track_length = kNaN;
  double mean_reprojection_error = kNaN;
  // With --gt, model 0 against it.
  double position_error_mean = kNaN;
  double position_error_relative = kNaN;  // of the scene extent
  double rotation_error_mean_deg = kNaN;
  // Registered images more than kWrongRegistrationDeg off; -1 without ground truth.
  int num_wrongly_registered = -1;
};

struct ChildResult {
  int exit_code = 0;  // 127: could not be started; 128 + n: killed by signal n
  double peak_memory_mb = kNaN;
  double seconds = 0;
};

// Runs `argv` with stdout and stderr appended to `log`; waits for it.
ChildResult RunChild(const std::vector<std::string>& argv, const fs::path& log) {
  std::vector<char*> args;
  for (const std::string& arg : argv) args.push_back(const_cast<char*>(arg.c_str()));
  args.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(),
                                   O_WRONLY | O_CREAT | O_APPEND, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  const Timer timer;
  pid_t pid = 0;
  const int error = posix_spawnp(&pid, args[0], &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ChildResult result;
  if (error != 0) {
    result.exit_code = 127;
    return result;
  }
  int status = 0;
  struct rusage usage {};
  while (wait4(pid, &status, 0, &usage) < 0) {
    if (errno != EINTR) {
      throw InputError(argv[0] + ": cannot wait for the row's process " + std::to_string(pid) +
                       ": " + std::strerror(errno));
    }
  }
  result.seconds = timer.ElapsedSeconds();
  result.peak_memory_mb = static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss: KiB
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return result;
}

nlohmann::json ReadJsonFile(const fs::path& file) {
  return nlohmann::json::parse(ReadFileContents(file), nullptr, /*allow_exceptions=*/true,
                               /*ignore_comments=*/true);
}

// Pairs matched, pairs verified and their mean number of inliers, from a workspace.
void ReadMatchingFigures(const fs::path& database_file, BenchRow* row) {
  const Database database(database_file, Database::Mode::kReadOnly);
  row->num_images = database.NumImages();
  row->num_pairs = database.NumMatchedPairs();
  size_t num_inliers = 0;
  row->num_verified = 0;
  for (const auto& [pair_id, geometry] : database.ReadAllTwoViewGeometries()) {
    if (geometry.config == TwoViewGeometry::UNDEFINED ||
        geometry.config == TwoViewGeometry::DEGENERATE) {
      continue;
    }
    ++row->num_verified;
    num_inliers += geometry.inlier_matches.size();
  }
  row->mean_inliers =
      row->num_verified > 0 ? static_cast<double>(num_inliers) / row->num_verified : kNaN;
}

using GroundTruth = std::map<std::string, GroundTruthPose>;

// A model scored against the ground truth, when there is one (nullptr: none).
void ScoreModel(const Reconstruction& model, const GroundTruth* ground_truth, BenchRow* row) {
  if (ground_truth == nullptr) return;
  const EvaluationResult result = EvaluateReconstruction(model, *ground_truth);
  if (!result.aligned) {
    spdlog::warn("bench: {}: model 0 cannot be scored: {}", row->name, result.error);
    return;
  }
  row->position_error_mean = result.position_error_mean;
  row->position_error_relative = result.position_error_mean / result.scene_extent;
  row->rotation_error_mean_deg = result.rotation_error_mean_deg;
  row->num_wrongly_registered = static_cast<int>(result.num_wrongly_registered);
}

std::string SlotPlugin(const nlohmann::json& manifest, const std::string& slot) {
  const auto pipeline = manifest.find("pipeline");
  if (pipeline == manifest.end() || !pipeline->contains(slot)) {
    return slot == "mapper" ? "incremental" : "-";  // the default mapper
  }
  const auto plugin = [](const nlohmann::json& value) {
    return value.is_object() && value.contains("plugin") && value.at("plugin").is_string()
               ? value.at("plugin").get<std::string>()
               : "-";
  };
  const nlohmann::json& value = pipeline->at(slot);
  if (!value.is_array()) return plugin(value);
  // Several pair selectors: "sequential+retrieval".
  std::string names;
  for (const nlohmann::json& item : value) names += (names.empty() ? "" : "+") + plugin(item);
  return names.empty() ? "-" : names;
}

// "orb 1.0.0 / exhaustive 1.0.0 / brute_force 1.0.0 / ceres 1.0.0 / colmap_binary 1.0.0+ply
// 1.0.0": the plugins of each slot in pipeline order, joined by "+".
std::string DescribePlugins(const std::vector<PluginUsed>& plugins) {
  std::string text;
  for (size_t k = 0; k < plugins.size(); ++k) {
    if (k > 0) text += plugins[k].slot == plugins[k - 1].slot ? "+" : " / ";
    text += plugins[k].plugin + " " + plugins[k].version;
  }
  return text;
}

// "window 40", or "sequential 497 + retrieval 300 = 720" for several selectors.
std::string PairsBySelector(const BenchRow& row) {
  if (row.pairs_per_selector.empty()) return "-";
  std::string text;
  for (const SelectorPairs& selector : row.pairs_per_selector) {
    text +=
        (text.empty() ? "" : " + ") + selector.plugin + " " + std::to_string(selector.num_pairs);
  }
  if (row.pairs_per_selector.size() > 1) text += " = " + std::to_string(row.num_selected_pairs);
  return text;
}

// A row's workspace is bench's own scratch folder, marked with this file when made: a
// rerun replaces it whole. A folder without the mark is never deleted.
constexpr const char* kBenchMark = ".tessera_bench";

// Throws InputError naming `folder` when it exists and bench did not make it (a link,
// a file, or a folder without the mark that is not empty).
void CheckBenchWorkspace(const fs::path& folder) {
  std::error_code error;
  const fs::file_status status = fs::symlink_status(folder, error);
  if (status.type() == fs::file_type::not_found) return;
  const bool made_by_bench =
      status.type() == fs::file_type::directory &&
      fs::symlink_status(folder / kBenchMark, error).type() == fs::file_type::regular;
  if (made_by_bench) return;
  if (status.type() == fs::file_type::directory && fs::is_empty(folder, error)) return;
  throw InputError(folder.string() + ": exists and was not made by tessera bench (no " +
                   kBenchMark +
                   "), so it is not replaced; choose another --output or move it away");
}

// Empties a row's workspace (CheckBenchWorkspace passed) and marks it as bench's.
void ResetBenchWorkspace(const fs::path& folder) {
  CheckBenchWorkspace(folder);
  std::error_code error;
  fs::remove_all(folder, error);
  CreateFolder(folder);
  WriteFileAtomically(folder / kBenchMark, "made by tessera bench; replaced by each bench run\n");
}

BenchRow RunManifest(const BenchOptions& options, const GroundTruth* ground_truth,
                     const std::string& manifest_file, const nlohmann::json& manifest,
                     const std::string& name, const std::string& shared_from,
                     const fs::path& workspace) {
  BenchRow row;
  row.name = name;
  row.workspace = workspace.string();
  row.plugins = SlotPlugin(manifest, "detector") + " / " + SlotPlugin(manifest, "pair_selector") +
                " / " + SlotPlugin(manifest, "matcher") + " / " + SlotPlugin(manifest, "mapper") +
                " / " + SlotPlugin(manifest, "bundle_adjuster") + " / " +
                SlotPlugin(manifest, "exporters");
  ResetBenchWorkspace(workspace);
  if (!shared_from.empty()) {
    fs::copy_file(fs::path(options.output) / shared_from / "database.db",
                  workspace / "database.db");
    // Only the features are shared: a workspace keeps pairs matched under another pair
    // selector, and those would make this row map pairs its own selector never chose.
    Workspace::Open(workspace)->database().ClearMatches();
    row.extract_shared_with = shared_from;
  }
  std::vector<std::string> argv = {
      TesseraExecutable().string(), "run",        "--images",   options.images, "--output",
      workspace.string(),           "--manifest", manifest_file};
  if (options.threads > 0) argv.insert(argv.end(), {"--threads", std::to_string(options.threads)});
  if (!options.camera_K.empty()) argv.insert(argv.end(), {"--camera-K", options.camera_K});
  if (options.camera_per_folder) argv.push_back("--camera-per-folder");
  spdlog::info("bench: {} ({}) ...", name, row.plugins);
  const ChildResult child = RunChild(argv, workspace / "run.log");
  row.exit_code = child.exit_code;
  row.peak_memory_mb = child.peak_memory_mb;
  if (!fs::exists(workspace / "run_summary.json")) return row;  // failed before the end
  const RunSummary run = RunSummary::FromJson(ReadJsonFile(workspace / "run_summary.json"));
  row.extract_seconds = run.extract.seconds;
  row.match_seconds = run.match.seconds;
  row.map_seconds = run.map.seconds;
  row.total_seconds = run.total_seconds;
  row.num_models = run.map.num_models;
  row.num_selected_pairs = run.match.num_pairs;
  row.pairs_per_selector = run.match.pairs_per_selector;
  if (!run.plugins.empty()) {
    row.plugins_used = run.plugins;
    row.plugins = DescribePlugins(run.plugins);
  }
  ReadMatchingFigures(workspace / "database.db", &row);
  const MappingSummary mapping =
      MappingSummary::FromJson(ReadJsonFile(workspace / "mapping_summary.json"));
  if (!mapping.models.empty()) {
    const MappingSummary::Model& model = mapping.models.front();
    row.num_registered = model.num_images;
    row.num_points = model.num_points3D;
    row.mean_track_length = model.mean_track_length;
    row.mean_reprojection_error = model.mean_reprojection_error;
    const fs::path model_dir = workspace / "sparse" / "0";
    if (ground_truth != nullptr && fs::exists(model_dir / "images.bin")) {
      ScoreModel(ReadColmapModel(model_dir), ground_truth, &row);
    }
  }
  return row;
}

// COLMAP 3.8 with its CPU defaults, one shared camera and exhaustive matching.
BenchRow RunColmap(const BenchOptions& options, const GroundTruth* ground_truth,
                   const fs::path& workspace) {
  BenchRow row;
  row.name = "colmap";
  row.plugins = "COLMAP 3.8: sift / exhaustive / sift_matcher / mapper";
  row.workspace = workspace.string();
  ResetBenchWorkspace(workspace);
  CreateFolder(workspace / "sparse");
  setenv("QT_QPA_PLATFORM", "offscreen", 1);
  const std::string database = (workspace / "database.db").string();
  const std::string threads = std::to_string(options.threads > 0 ? options.threads : -1);
  const std::vector<std::vector<std::string>> steps = {
      {"colmap", "feature_extractor", "--database_path", database, "--image_path", options.images,
       options.camera_per_folder ? "--ImageReader.single_camera_per_folder"
                                 : "--ImageReader.single_camera",
       "1", "--SiftExtraction.use_gpu", "0", "--SiftExtraction.num_threads", threads},
      {"colmap", "exhaustive_matcher", "--database_path", database, "--SiftMatching.use_gpu", "0",
       "--SiftMatching.num_threads", threads},
      {"colmap", "mapper", "--database_path", database, "--image_path", options.images,
       "--output_path", (workspace / "sparse").string(), "--Mapper.num_threads", threads}};
  spdlog::info("bench: colmap ...");
  double* const seconds[] = {&row.extract_seconds, &row.match_seconds, &row.map_seconds};
  row.peak_memory_mb = 0;
  row.total_seconds = 0;
  for (size_t i = 0; i < steps.size(); ++i) {
    const ChildResult child = RunChild(steps[i], workspace / "colmap.log");
    *seconds[i] = child.seconds;
    row.total_seconds += child.seconds;
    row.peak_memory_mb = std::max(row.peak_memory_mb, child.peak_memory_mb);
    row.exit_code = child.exit_code;
    if (child.exit_code != 0) return row;
  }
  ReadMatchingFigures(database, &row);
  const fs::path model_dir = workspace / "sparse" / "0";
  if (fs::exists(model_dir / "images.bin")) {
    const Reconstruction model = ReadColmapModel(model_dir);
    row.num_models = 1;
    row.num_registered = model.images.size();
    row.num_points = model.points3D.size();
    // The same figures, computed the same way, as Tessera's rows (mapping_summary.json).
    const ModelStatistics statistics = ComputeModelStatistics(model);
    row.mean_track_length = statistics.mean_track_length;
    row.mean_reprojection_error = statistics.mean_reprojection_error;
    ScoreModel(model, ground_truth, &row);
  }
  return row;
}

std::string Format(double value, int precision) {
  if (std::isnan(value)) return "-";
  std::ostringstream stream;
  stream.setf(std::ios::fixed);
  stream.precision(precision);
  stream << value;
  return stream.str();
}

const std::vector<std::string>& Columns() {
  static const std::vector<std::string> columns = {"manifest",
                                                   "plugins",
                                                   "extract s",
                                                   "match s",
                                                   "map s",
                                                   "total s",
                                                   "peak MB",
                                                   "pairs",
                                                   "pairs by selector",
                                                   "verified pairs",
                                                   "mean inliers",
                                                   "registered",
                                                   "models",
                                                   "points",
                                                   "track length",
                                                   "reproj px",
                                                   "position error",
                                                   "position error % of extent",
                                                   "rotation error deg",
                                                   "wrong (>5 deg)",
                                                   "exit code"};
  return columns;
}

std::vector<std::string> Cells(const BenchRow& row) {
  std::string extract = Format(row.extract_seconds, 1);
  if (!row.extract_shared_with.empty()) extract += " (features of " + row.extract_shared_with + ")";
  return {row.name,
          row.plugins,
          extract,
          Format(row.match_seconds, 1),
          Format(row.map_seconds, 1),
          Format(row.total_seconds, 1),
          Format(row.peak_memory_mb, 0),
          std::to_string(row.num_pairs),
          PairsBySelector(row),
          std::to_string(row.num_verified),
          Format(row.mean_inliers, 0),
          std::to_string(row.num_registered) + "/" + std::to_string(row.num_images),
          std::to_string(row.num_models),
          std::to_string(row.num_points),
          Format(row.mean_track_length, 2),
          Format(row.mean_reprojection_error, 3),
          Format(row.position_error_mean, 5),
          Format(100 * row.position_error_relative, 3),
          Format(row.rotation_error_mean_deg, 3),
          row.num_wrongly_registered < 0 ? std::string("-")
                                         : std::to_string(row.num_wrongly_registered),
          std::to_string(row.exit_code)};
}

nlohmann::json ToJson(const BenchRow& row) {
  const auto number = [](double value) -> nlohmann::json {
    return std::isnan(value) ? nlohmann::json(nullptr) : nlohmann::json(value);
  };
  return {{"manifest", row.name},
          {"plugins", row.plugins},
          {"plugins_used", row.plugins_used},
          {"workspace", row.workspace},
          {"exit_code", row.exit_code},
          {"extract_shared_with", row.extract_shared_with},
          {"extract_seconds", number(row.extract_seconds)},
          {"match_seconds", number(row.match_seconds)},
          {"map_seconds", number(row.map_seconds)},
          {"total_seconds", number(row.total_seconds)},
          {"peak_memory_mb", number(row.peak_memory_mb)},
          {"num_pairs", row.num_pairs},
          {"pairs_per_selector", nlohmann::json(row.pairs_per_selector)},
          {"num_verified_pairs", row.num_verified},
          {"mean_inliers_per_verified_pair", number(row.mean_inliers)},
          {"num_images", row.num_images},
          {"num_registered", row.num_registered},
          {"num_models", row.num_models},
          {"num_points3D", row.num_points},
          {"mean_track_length", number(row.mean_track_length)},
          {"mean_reprojection_error_px", number(row.mean_reprojection_error)},
          {"position_error_mean", number(row.position_error_mean)},
          {"position_error_mean_relative", number(row.position_error_relative)},
          {"rotation_error_mean_deg", number(row.rotation_error_mean_deg)},
          {"num_wrongly_registered", row.num_wrongly_registered < 0
                                         ? nlohmann::json(nullptr)
                                         : nlohmann::json(row.num_wrongly_registered)}};
}

std::string MarkdownTable(const std::vector<BenchRow>& rows) {
  std::ostringstream out;
  const std::vector<std::string>& columns = Columns();
  out << "|";
  for (const std::string& column : columns) out << " " << column << " |";
  out << "\n|";
  for (size_t i = 0; i < columns.size(); ++i) out << " --- |";
  out << "\n";
  for (const BenchRow& row : rows) {
    out << "|";
    for (const std::string& cell : Cells(row)) out << " " << cell << " |";
    out << "\n";
  }
  return out.str();
}

std::string CsvCell(const std::string& cell) {
  if (cell.find_first_of(",\"\n") == std::string::npos) return cell;
  std::string quoted = "\"";
  for (const char c : cell) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

std::string Csv(const std::vector<BenchRow>& rows) {
  std::ostringstream out;
  const std::vector<std::string>& columns = Columns();
  for (size_t i = 0; i < columns.size(); ++i) out << (i ? "," : "") << CsvCell(columns[i]);
  out << "\n";
  for (const BenchRow& row : rows) {
    const std::vector<std::string> cells = Cells(row);
    for (size_t i = 0; i < cells.size(); ++i) out << (i ? "," : "") << CsvCell(cells[i]);
    out << "\n";
  }
  return out.str();
}

// An SVG chart drawn by gnuplot: seconds per stage per row, stacked, and (with ground
// truth) each row's mean position error as a share of the scene extent. Its data and
// script are kept next to it in the bench folder.
void WriteChart(const BenchOptions& options, const std::vector<BenchRow>& rows) {
  const fs::path dir(options.output);
  const auto cell = [](double value) {
    return std::isnan(value) ? std::string("-") : Format(value, 4);
  };
  std::ostringstream data;
  data << "row\textract\tmatch\tmap\tposition_error_percent\n";
  for (const BenchRow& row : rows) {
    data << row.name << "\t" << cell(row.extract_seconds) << "\t" << cell(row.match_seconds) << "\t"
         << cell(row.map_seconds) << "\t" << cell(100 * row.position_error_relative) << "\n";
  }
  WriteFileAtomically(dir / "chart.dat", data.str());
  const bool has_errors = !options.ground_truth.empty();
  std::ostringstream script;
  script << "set terminal svg size " << (has_errors ? 1000 : 560) << ",440 font 'sans,11'\n"
         << "set output '" << fs::absolute(options.chart_file).string() << "'\n"
         << "set datafile separator '\\t'\n"
         << "set datafile missing '-'\n"
         << "set style fill solid 0.8 border -1\n"
         << "set boxwidth 0.7\n"
         << "set xtics rotate by -30 noenhanced\n"
         << "set key top right noenhanced\n"
         << "set grid ytics\n"
         << "set yrange [0:*]\n";
  if (has_errors) script << "set multiplot layout 1,2\n";
  script << "set title 'time per stage (s)'\n"
         << "set style data histograms\n"
         << "set style histogram rowstacked\n"
         << "plot '" << (dir / "chart.dat").string() << "' using 2:xtic(1) title columnheader(2), "
         << "'' using 3 title columnheader(3), '' using 4 title columnheader(4)\n";
  if (has_errors) {
    script << "set title 'mean camera position error (% of the scene extent)'\n"
           << "set style histogram clustered\n"
           << "unset key\n"
           << "plot '" << (dir / "chart.dat").string()
           << "' using 5:xtic(1) notitle lc rgb '#b04040'\n"
           << "unset multiplot\n";
  }
  WriteFileAtomically(dir / "chart.gp", script.str());
  const ChildResult gnuplot = RunChild({"gnuplot", (dir / "chart.gp").string()}, dir / "chart.log");
  if (gnuplot.exit_code != 0) {
    throw InputError(options.chart_file + ": gnuplot failed (exit code " +
                     std::to_string(gnuplot.exit_code) + "), see " + (dir / "chart.log").string());
  }
}

// The settings that decide what extraction produces, as text: equal keys, equal
// features.
std::string ExtractionKey(const nlohmann::json& manifest) {
  const auto pipeline = manifest.find("pipeline");
  if (pipeline == manifest.end() || !pipeline->contains("detector")) return "";
  return pipeline->at("detector").dump() + "|" +
         (manifest.contains("camera") ? manifest.at("camera").dump() : "");
}

// Every row is printed and written first; then the first failure decides the exit code.
int ExitCodeOfRows(const std::vector<BenchRow>& rows) {
  for (const BenchRow& row : rows) {
    if (row.exit_code != 0) {
      spdlog::error(
          "bench: {} ended with exit code {}; its log: {}", row.name, row.exit_code,
          (fs::path(row.workspace) / (row.name == "colmap" ? "colmap.log" : "run.log")).string());
      // A documented exit code stays what it is; a signal or failure to start is 1.
      const bool documented = row.exit_code == kExitBadInput || row.exit_code == kExitNoModel ||
                              row.exit_code == kExitPluginCrash;
      return documented ? row.exit_code : static_cast<int>(kExitInternalError);
    }
  }
  return kExitSuccess;
}

}  // namespace

BenchReport RunBenchReport(const BenchOptions& options) {
  if (!fs::is_directory(options.images)) {
    throw InputError(options.images + ": --images is not a folder");
  }
  if (!options.ground_truth.empty() && !fs::exists(options.ground_truth)) {
    throw InputError(options.ground_truth + ": --gt does not exist");
  }
  if (!options.chart_file.empty() && std::system("command -v gnuplot > /dev/null 2>&1") != 0) {
    throw InputError("--chart " + options.chart_file +
                     ": needs gnuplot, which is not installed (Debian package gnuplot-nox)");
  }
  // Read the ground truth and every manifest first: a missing or malformed one fails
  // before any run.
  std::optional<GroundTruth> ground_truth;
  if (!options.ground_truth.empty()) ground_truth = ReadGroundTruth(options.ground_truth);
  const GroundTruth* const gt = ground_truth ? &*ground_truth : nullptr;
  std::vector<nlohmann::json> manifests;
  std::vector<std::string> names;
  std::vector<std::string> keys;
  for (const std::string& file : options.manifests) {
    nlohmann::json manifest;
    try {
      manifest = ReadJsonFile(file);
    } catch (const nlohmann::json::exception& error) {
      throw InputError(file + ": not a JSON manifest: " + error.what());
    }
    std::string name = fs::path(file).stem().string();
    for (int suffix = 2; std::find(names.begin(), names.end(), name) != names.end(); ++suffix) {
      name = fs::path(file).stem().string() + "-" + std::to_string(suffix);
    }
    names.push_back(name);
    keys.push_back(ExtractionKey(manifest));
    manifests.push_back(std::move(manifest));
  }
  CreateFolder(options.output);
  // Every row's folder is checked before the first row runs.
  for (const std::string& name : names) CheckBenchWorkspace(fs::path(options.output) / name);
  if (options.with_colmap) CheckBenchWorkspace(fs::path(options.output) / "colmap");

  std::vector<BenchRow> rows;
  for (size_t i = 0; i < options.manifests.size(); ++i) {
    std::string shared_from;
    for (size_t j = 0; j < i && !keys[i].empty(); ++j) {
      if (keys[j] == keys[i] && rows[j].exit_code == 0) {
        shared_from = names[j];
        break;
      }
    }
    rows.push_back(RunManifest(options, gt, options.manifests[i], manifests[i], names[i],
                               shared_from, fs::path(options.output) / names[i]));
  }
  if (options.with_colmap) {
    if (std::system("command -v colmap > /dev/null 2>&1") != 0) {
      spdlog::warn("bench: colmap is not installed: no COLMAP row");
    } else {
      rows.push_back(RunColmap(options, gt, fs::path(options.output) / "colmap"));
    }
  }

  std::cout << MarkdownTable(rows);
  if (options.with_colmap && rows.back().name == "colmap" && rows.back().exit_code == 0) {
    const BenchRow& colmap = rows.back();
    std::cout << "\nTime as a share of COLMAP's (end to end; extract + match):\n";
    for (size_t i = 0; i + 1 < rows.size(); ++i) {
      std::cout << "- " << rows[i].name << ": "
                << Format(rows[i].total_seconds / colmap.total_seconds, 2) << "; "
                << Format((rows[i].extract_seconds + rows[i].match_seconds) /
                              (colmap.extract_seconds + colmap.match_seconds),
                          2)
                << "\n";
    }
  }
  nlohmann::json json = {{"images", options.images},
                         {"ground_truth", options.ground_truth},
                         {"hardware_threads", std::thread::hardware_concurrency()},
                         {"rows", nlohmann::json::array()}};
  for (const BenchRow& row : rows) json["rows"].push_back(ToJson(row));
  if (!options.json_file.empty()) WriteFileAtomically(options.json_file, json.dump(2) + "\n");
  if (!options.csv_file.empty()) WriteFileAtomically(options.csv_file, Csv(rows));
  if (!options.chart_file.empty()) WriteChart(options, rows);

  return {ExitCodeOfRows(rows), json};
}

int RunBench(const BenchOptions& options) { return RunBenchReport(options).exit_code; }

}  // namespace tessera
