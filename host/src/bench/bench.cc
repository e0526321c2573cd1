// `tessera bench --images DIR [--gt GT] MANIFEST...`: every manifest run on the same
// images, each as its own `tessera run` child process (so that one plugin's crash loses
// no other row, and each row's peak memory is its own), and optionally COLMAP (4 and
// 3.8, colmap_rows.h) on the CPU, in the same command on the same machine. Detection is shared: a
// manifest whose detector and camera settings equal an earlier one's starts from a copy of that
// workspace's features (not its matches), and its row says so. Prints a Markdown
// table; --json and --csv write the same rows to files, --chart draws them (gnuplot).
// Each row works in a folder of its own (OUTPUT/tessera/<name>, OUTPUT/colmap/<binary>/),
// and a row that fails is a row with its error: the other rows run and are reported.

#include "bench/bench.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <thread>

#include "bench/bench_rows.h"
#include "bench/colmap_rows.h"
#include "database/database.h"
#include "eval/ground_truth.h"
#include "pipeline/mapping_summary.h"
#include "pipeline/run_summary.h"
#include "pipeline/workspace.h"
#include "tessera/errors.h"
#include "tessera/io/colmap_model_io.h"
#include "tessera/io/file_io.h"
#include "util/child_process.h"
#include "util/exit_codes.h"
#include "util/paths.h"
#include "util/strings.h"
#include "util/tessera_commands.h"
#include "util/workspace_layout.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

nlohmann::json ReadJsonFile(const fs::path& file) {
  return nlohmann::json::parse(ReadFileContents(file), nullptr, /*allow_exceptions=*/true,
                               /*ignore_comments=*/true);
}

using GroundTruth = BenchGroundTruth;

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

// OUTPUT/tessera/<name>: a Tessera row's workspace.
fs::path TesseraWorkspace(const BenchOptions& options, const std::string& name) {
  return fs::path(options.output) / "tessera" / name;
}

// A Tessera row's figures, read back from its workspace after its run ended with 0.
void ReadTesseraRow(const fs::path& workspace, const GroundTruth* ground_truth, BenchRow* row) {
  const RunSummary run =
      RunSummary::FromJson(ReadJsonFile(workspace / workspace_layout::kRunSummary));
  row->extract_seconds = run.extract.seconds;
  row->match_seconds = run.match.seconds;
  row->map_seconds = run.map.seconds;
  row->total_seconds = run.total_seconds;
  row->num_models = run.map.num_models;
  row->num_selected_pairs = run.match.num_pairs;
  row->pairs_per_selector = run.match.pairs_per_selector;
  if (!run.plugins.empty()) {
    row->plugins_used = run.plugins;
    row->plugins = DescribePlugins(run.plugins);
  }
  ReadMatchingFigures(workspace / workspace_layout::kDatabase, row);
  const MappingSummary mapping =
      MappingSummary::FromJson(ReadJsonFile(workspace / workspace_layout::kMappingSummary));
  if (!mapping.models.empty()) {
    const MappingSummary::Model& model = mapping.models.front();
    row->num_registered = model.num_images;
    row->num_points = model.num_points3D;
    row->mean_track_length = model.mean_track_length;
    row->mean_reprojection_error = model.mean_reprojection_error;
    const fs::path model_dir = workspace / workspace_layout::kModelsFolder / "0";
    if (ground_truth != nullptr && fs::exists(model_dir / "images.bin")) {
      ScoreModel(ReadColmapModel(model_dir), ground_truth, row);
    }
  }
}

// A manifest's row: its `tessera run` in its own workspace. A failure is the row's error.
BenchRow RunManifest(const BenchOptions& options, const GroundTruth* ground_truth,
                     const std::string& manifest_file, const nlohmann::json& manifest,
                     const std::string& name, const std::string& shared_from) {
  const fs::path workspace = TesseraWorkspace(options, name);
  BenchRow row;
  row.name = name;
  row.workspace = workspace.string();
  row.plugins = SlotPlugin(manifest, "detector") + " / " + SlotPlugin(manifest, "pair_selector") +
                " / " + SlotPlugin(manifest, "matcher") + " / " + SlotPlugin(manifest, "mapper") +
                " / " + SlotPlugin(manifest, "bundle_adjuster") + " / " +
                SlotPlugin(manifest, "exporters");
  row.log = (workspace / "run.log").string();
  try {
    ResetBenchWorkspace(workspace);
    if (!shared_from.empty()) {
      fs::copy_file(TesseraWorkspace(options, shared_from) / workspace_layout::kDatabase,
                    workspace / workspace_layout::kDatabase);
      // Only the features are shared: a workspace keeps pairs matched under another pair
      // selector, and those would make this row map pairs its own selector never chose.
      Workspace::Open(workspace)->database().ClearMatches();
      row.extract_shared_with = shared_from;
    }
    BenchRunArguments run;
    run.tessera = TesseraExecutable();
    run.images = options.images;
    run.output = workspace;
    run.manifest = manifest_file;
    run.camera_K = options.camera_K;
    run.camera_per_folder = options.camera_per_folder;
    run.threads = options.threads;
    spdlog::info("bench: {} ({}) ...", name, row.plugins);
    const ChildRun child = RunChild(BenchRunCommand(run), BenchChildOptions(options, row.log));
    row.exit_code = child.timed_out ? 124 : child.exit_code;
    row.peak_memory_mb = child.peak_memory_mb;
    if (child.exit_code != 0 || child.timed_out || child.stopped) {
      // Its own error line says what went wrong; a crash or a timeout has none.
      const std::string line = LastLogLine(row.log, "[error]");
      row.error =
          ChildFailure(child, BenchChildTimeout(options), line.empty() ? "see " + row.log : line);
      if (!fs::exists(workspace / workspace_layout::kRunSummary)) return row;
    }
    if (fs::exists(workspace / workspace_layout::kRunSummary)) {
      ReadTesseraRow(workspace, ground_truth, &row);
    }
  } catch (const std::exception& exception) {
    row.error = PrintableExcerpt(exception.what(), 600);
    if (row.exit_code == 0) row.exit_code = kExitBadInput;
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
                                                   "exit code",
                                                   "error"};
  return columns;
}

// A cell's text that keeps the Markdown table whole: no '|' (the error lines are already
// one line of printable text).
std::string TableText(std::string text) {
  std::replace(text.begin(), text.end(), '|', '/');
  return text;
}

std::vector<std::string> Cells(const BenchRow& row) {
  std::string extract = Format(row.extract_seconds, 1);
  if (!row.extract_shared_with.empty()) extract += " (features of " + row.extract_shared_with + ")";
  if (!row.matches_of.empty()) extract += " (matches of " + row.matches_of + ")";
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
          std::to_string(row.exit_code),
          row.error.empty() ? std::string("-") : TableText(row.error)};
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
          {"error", row.error.empty() ? nlohmann::json(nullptr) : nlohmann::json(row.error)},
          {"extract_shared_with", row.extract_shared_with},
          {"matches_of", row.matches_of},
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
  const ChildRun gnuplot = RunChild({FindOnPath("gnuplot").string(), (dir / "chart.gp").string()},
                                    BenchChildOptions(options, dir / "chart.log"));
  if (gnuplot.exit_code != 0 || gnuplot.timed_out) {
    throw InputError(
        options.chart_file + ": gnuplot " +
        ChildFailure(gnuplot, BenchChildTimeout(options), "see " + (dir / "chart.log").string()));
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

// Every row is printed and written first; then each failure is logged, and the first
// decides the exit code.
int ExitCodeOfRows(const std::vector<BenchRow>& rows) {
  int code = kExitSuccess;
  for (const BenchRow& row : rows) {
    if (row.exit_code == 0 && row.error.empty()) continue;
    spdlog::error("bench: {} ended with exit code {}{}; its log: {}", row.name, row.exit_code,
                  row.error.empty() ? "" : ": " + row.error, row.log);
    if (code != kExitSuccess) continue;
    // A documented exit code stays what it is; a COLMAP row's failure or a timeout is the
    // bench's input (the binary, --child-timeout); a signal or failure to start is 1.
    const bool documented = row.exit_code == kExitBadInput || row.exit_code == kExitNoModel ||
                            row.exit_code == kExitPluginCrash;
    if (documented) {
      code = row.exit_code;
    } else if (row.colmap || row.exit_code == 124) {
      code = kExitBadInput;
    } else {
      code = kExitInternalError;
    }
  }
  return code;
}

// COLMAP's rows: its whole pipeline, or (--colmap-mapper-only) its mappers on the
// database of the first Tessera row that ended with 0.
std::vector<BenchRow> RunColmapRows(const BenchOptions& options,
                                    const std::vector<ColmapBinary>& colmaps,
                                    const GroundTruth* ground_truth,
                                    const std::vector<BenchRow>& tessera_rows) {
  std::vector<BenchRow> rows;
  const BenchRow* source = nullptr;
  if (options.colmap_mapper_only && !colmaps.empty()) {
    const auto ok = std::find_if(tessera_rows.begin(), tessera_rows.end(), [](const BenchRow& row) {
      return row.exit_code == 0 && row.error.empty();
    });
    if (ok == tessera_rows.end()) {
      spdlog::warn(
          "bench: --colmap-mapper-only: no manifest's run ended with exit code 0, so "
          "COLMAP has no database to map: no COLMAP rows");
      return rows;
    }
    source = &*ok;
  }
  for (const ColmapBinary& colmap : colmaps) {
    if (options.stop_requested && options.stop_requested()) break;
    for (BenchRow& row : source != nullptr
                             ? RunColmapMappers(options, colmap, ground_truth, *source)
                             : RunColmapPipeline(options, colmap, ground_truth)) {
      rows.push_back(std::move(row));
    }
  }
  return rows;
}

// Each Tessera row's time as a share of each COLMAP row's that ended with 0: end to end
// and extract + match, or map time alone where COLMAP mapped a Tessera row's matches.
void PrintShares(const std::vector<BenchRow>& rows, size_t num_tessera_rows) {
  for (size_t c = num_tessera_rows; c < rows.size(); ++c) {
    const BenchRow& colmap = rows[c];
    if (colmap.exit_code != 0) continue;
    const bool mapper_only = !colmap.matches_of.empty();
    std::cout << "\n"
              << (mapper_only ? "Map time as a share of " + colmap.name + "'s:\n"
                              : "Time as a share of " + colmap.name +
                                    "'s (end to end; extract + match):\n");
    for (size_t i = 0; i < num_tessera_rows; ++i) {
      std::cout << "- " << rows[i].name << ": ";
      if (mapper_only) {
        std::cout << Format(rows[i].map_seconds / colmap.map_seconds, 2) << "\n";
        continue;
      }
      std::cout << Format(rows[i].total_seconds / colmap.total_seconds, 2) << "; "
                << Format((rows[i].extract_seconds + rows[i].match_seconds) /
                              (colmap.extract_seconds + colmap.match_seconds),
                          2)
                << "\n";
    }
  }
}

}  // namespace

BenchReport RunBenchReport(const BenchOptions& options) {
  if (!fs::is_directory(options.images)) {
    throw InputError(options.images + ": --images is not a folder");
  }
  if (!options.ground_truth.empty() && !fs::exists(options.ground_truth)) {
    throw InputError(options.ground_truth + ": --gt does not exist");
  }
  if (!(options.child_timeout >= 0) || !std::isfinite(options.child_timeout)) {
    throw InputError("--child-timeout " + std::to_string(options.child_timeout) +
                     ": not a number of seconds (0: the default, " +
                     std::to_string(static_cast<int>(kBenchChildTimeoutSeconds)) + " s)");
  }
  if (!options.chart_file.empty() && FindOnPath("gnuplot").empty()) {
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
    // The row's name is its folder's: the file's stem made a file name, made unique.
    const std::string stem = SafeFileName(fs::path(file).stem().string(), 100);
    std::string name = stem;
    for (int suffix = 2; std::find(names.begin(), names.end(), name) != names.end(); ++suffix) {
      name = stem + "-" + std::to_string(suffix);
    }
    names.push_back(name);
    keys.push_back(ExtractionKey(manifest));
    manifests.push_back(std::move(manifest));
  }
  CreateFolder(options.output);
  // Every row's folder is checked before the first row runs.
  CheckBenchFolder(fs::path(options.output) / "tessera");
  for (const std::string& name : names) CheckBenchWorkspace(TesseraWorkspace(options, name));
  // COLMAP's binaries are asked their versions before the first row runs too.
  const bool with_colmap =
      options.with_colmap || !options.colmap_binaries.empty() || options.colmap_mapper_only;
  std::vector<ColmapBinary> colmaps;
  if (with_colmap) colmaps = FindColmapBinaries(options);
  if (with_colmap && colmaps.empty()) {
    spdlog::warn(
        "bench: no COLMAP found (no --colmap, TESSERA_COLMAP, {} or colmap on the "
        "PATH): no COLMAP rows",
        kColmap4Anchor);
  }
  AssignColmapLabels(&colmaps, names);  // no COLMAP row is named as a manifest's
  if (!colmaps.empty()) CheckBenchFolder(fs::path(options.output) / "colmap");
  for (const ColmapBinary& colmap : colmaps) {
    CheckBenchFolder(ColmapFolder(options, colmap));
    for (const fs::path& folder : ColmapWorkspaces(options, colmap)) CheckBenchWorkspace(folder);
  }
  const auto stopped = [&options] { return options.stop_requested && options.stop_requested(); };

  std::vector<BenchRow> rows;
  for (size_t i = 0; i < options.manifests.size() && !stopped(); ++i) {
    std::string shared_from;
    for (size_t j = 0; j < i && !keys[i].empty(); ++j) {
      if (keys[j] == keys[i] && rows[j].exit_code == 0 && rows[j].error.empty()) {
        shared_from = names[j];
        break;
      }
    }
    rows.push_back(
        RunManifest(options, gt, options.manifests[i], manifests[i], names[i], shared_from));
  }
  const size_t num_tessera_rows = rows.size();
  if (!stopped()) {
    for (BenchRow& row : RunColmapRows(options, colmaps, gt, rows)) rows.push_back(std::move(row));
  }
  const bool interrupted = stopped();

  std::cout << MarkdownTable(rows);
  PrintShares(rows, num_tessera_rows);
  nlohmann::json json = {{"images", options.images},
                         {"ground_truth", options.ground_truth},
                         {"hardware_threads", std::thread::hardware_concurrency()},
                         {"interrupted", interrupted},
                         {"rows", nlohmann::json::array()}};
  for (const BenchRow& row : rows) json["rows"].push_back(ToJson(row));
  if (!options.json_file.empty()) WriteFileAtomically(options.json_file, json.dump(2) + "\n");
  if (!options.csv_file.empty()) WriteFileAtomically(options.csv_file, Csv(rows));
  if (interrupted) {
    spdlog::error("bench: interrupted; the rows above are those that ran (of {} manifests{})",
                  options.manifests.size(), colmaps.empty() ? "" : " and COLMAP's rows");
    return {kExitInterrupted, true, json};
  }
  if (!options.chart_file.empty()) WriteChart(options, rows);
  return {ExitCodeOfRows(rows), false, json};
}

int RunBench(const BenchOptions& options) { return RunBenchReport(options).exit_code; }

}  // namespace tessera
