// COLMAP's rows of `tessera bench` (--with-colmap): the binaries, found and asked their
// versions before any row runs, then either COLMAP's whole pipeline on the images or its
// mappers alone on a copy of a Tessera row's database (--colmap-mapper-only), so that
// the mapper rows compare identical matches.

#include "bench/colmap_rows.h"

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <regex>
#include <sstream>

#include "tessera/errors.h"
#include "tessera/io/colmap_model_io.h"
#include "tessera/io/file_io.h"
#include "util/child_process.h"
#include "util/paths.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

std::string FirstLine(const std::string& text) {
  const size_t start = text.find_first_not_of(" \t\r\n");
  if (start == std::string::npos) return "";
  return text.substr(start, text.find_first_of("\r\n", start) - start);
}

// `given` checked and asked its version (`colmap -h`); `how` says who named it, for the
// error line.
ColmapBinary ProbeColmap(const std::string& given, const std::string& how,
                         const fs::path& scratch) {
  const std::string where = " (" + how + ")";
  ColmapBinary colmap;
  colmap.path = given;
  if (given.find('/') == std::string::npos) {
    colmap.path = FindOnPath(given).string();
    if (colmap.path.empty()) throw InputError(given + ": not found on the PATH" + where);
  }
  std::error_code error;
  if (!fs::exists(colmap.path, error)) throw InputError(colmap.path + ": no such file" + where);
  if (fs::is_directory(colmap.path, error) || access(colmap.path.c_str(), X_OK) != 0) {
    throw InputError(colmap.path + ": not executable" + where);
  }
  const fs::path log = scratch / "colmap-version.log";
  fs::remove(log, error);
  const ChildRun child = RunChild({colmap.path, "-h"}, log);
  const std::string text = fs::exists(log, error) ? ReadFileContents(log) : "";
  if (child.exit_code > 128) {
    throw InputError(colmap.path + ": crashed (signal " + std::to_string(child.exit_code - 128) +
                     ") when asked its version with -h" + where);
  }
  if (child.exit_code != 0) {
    const std::string hint = child.exit_code == 127 && !text.empty()
                                 ? "; scripts/install_dependencies.sh installs COLMAP 4's libraries"
                                 : "";
    throw InputError(colmap.path + ": exited with code " + std::to_string(child.exit_code) +
                     " when asked its version with -h: " + FirstLine(text) + hint + where);
  }
  std::smatch match;
  if (!std::regex_search(text, match, std::regex(R"(COLMAP ((\d+)\.(\d+)[^\s]*))"))) {
    throw InputError(colmap.path + ": does not say it is COLMAP (its -h begins '" +
                     FirstLine(text) + "')" + where);
  }
  colmap.version = match[1].str();
  const int major = std::stoi(match[2].str()), minor = std::stoi(match[3].str());
  if (major < 3 || (major == 3 && minor < 8)) {
    throw InputError(colmap.path + ": is COLMAP " + colmap.version +
                     "; tessera bench needs COLMAP 3.8 or later" + where);
  }
  colmap.has_global_mapper = text.find("global_mapper") != std::string::npos;
  spdlog::info("bench: {} is COLMAP {}{}", colmap.path, colmap.version,
               colmap.has_global_mapper ? ", with global_mapper" : "");
  return colmap;
}

double OrZero(double value) { return std::isnan(value) ? 0.0 : value; }

bool IsColmap3(const ColmapBinary& colmap) { return colmap.version.rfind("3.", 0) == 0; }

std::string Threads(const BenchOptions& options) {
  return std::to_string(options.threads > 0 ? options.threads : -1);
}

// Option names: COLMAP 4 renamed SiftExtraction/SiftMatching to Feature*.
std::vector<std::string> ExtractCommand(const BenchOptions& options, const ColmapBinary& colmap,
                                        const fs::path& database) {
  const std::string prefix = IsColmap3(colmap) ? "--SiftExtraction." : "--FeatureExtraction.";
  return {colmap.path,
          "feature_extractor",
          "--database_path",
          database.string(),
          "--image_path",
          options.images,
          options.camera_per_folder ? "--ImageReader.single_camera_per_folder"
                                    : "--ImageReader.single_camera",
          "1",
          prefix + "use_gpu",
          "0",
          prefix + "num_threads",
          Threads(options)};
}

std::vector<std::string> MatchCommand(const BenchOptions& options, const ColmapBinary& colmap,
                                      const fs::path& database) {
  const std::string prefix = IsColmap3(colmap) ? "--SiftMatching." : "--FeatureMatching.";
  return {
      colmap.path, "exhaustive_matcher",   "--database_path", database.string(), prefix + "use_gpu",
      "0",         prefix + "num_threads", Threads(options)};
}

// The model with the most images among `sparse`'s numbered folders, with the number of
// models, read back and scored.
void ReadLargestModel(const fs::path& sparse, const BenchGroundTruth* ground_truth, BenchRow* row) {
  std::optional<Reconstruction> largest;
  row->num_models = 0;
  for (const fs::directory_entry& entry : fs::directory_iterator(sparse)) {
    if (!fs::exists(entry.path() / "images.bin")) continue;
    ++row->num_models;
    Reconstruction model = ReadColmapModel(entry.path());
    if (!largest || model.images.size() > largest->images.size()) largest = std::move(model);
  }
  if (largest) ReadModelFigures(*largest, ground_truth, row);
}

bool IsGlobalRow(const std::string& name) {
  return name.size() > 7 && name.compare(name.size() - 7, 7, "-global") == 0;
}

// One of COLMAP's mappers on its own copy of `database`, in the workspace `name`.
BenchRow RunColmapMapper(const BenchOptions& options, const ColmapBinary& colmap,
                         const BenchGroundTruth* ground_truth, const fs::path& database,
                         const std::string& name) {
  const bool global = IsGlobalRow(name);
  BenchRow row;
  row.name = name;
  row.plugins = "COLMAP " + colmap.version + ": " + (global ? "global_mapper" : "mapper");
  const fs::path workspace = fs::path(options.output) / name;
  row.workspace = workspace.string();
  row.log = (workspace / "colmap.log").string();
  ResetBenchWorkspace(workspace);
  CreateFolder(workspace / "sparse");
  // COLMAP 4 upgrades the database it opens in place: it maps a copy.
  fs::copy_file(database, workspace / "database.db");
  spdlog::info("bench: {} ...", name);
  const ChildRun child =
      RunChild({colmap.path, global ? "global_mapper" : "mapper", "--database_path",
                (workspace / "database.db").string(), "--image_path", options.images,
                "--output_path", (workspace / "sparse").string(),
                global ? "--GlobalMapper.num_threads" : "--Mapper.num_threads", Threads(options)},
               workspace / "colmap.log");
  row.map_seconds = child.seconds;
  row.total_seconds = child.seconds;
  row.peak_memory_mb = child.peak_memory_mb;
  row.exit_code = child.exit_code;
  if (row.exit_code == 0) ReadLargestModel(workspace / "sparse", ground_truth, &row);
  return row;
}

}  // namespace

std::vector<ColmapBinary> FindColmapBinaries(const BenchOptions& options, const fs::path& scratch) {
  setenv("QT_QPA_PLATFORM", "offscreen", 1);  // COLMAP 3.8 starts Qt even without its GUI
  std::vector<ColmapBinary> binaries;
  if (!options.colmap_binaries.empty()) {
    for (const std::string& path : options.colmap_binaries) {
      binaries.push_back(ProbeColmap(path, "named by --colmap", scratch));
    }
    return binaries;
  }
  const char* variable = std::getenv("TESSERA_COLMAP");
  if (variable != nullptr && *variable != '\0') {
    binaries.push_back(ProbeColmap(variable, "named by TESSERA_COLMAP", scratch));
  } else {
    for (const fs::path& anchor :
         {fs::path(kColmap4Anchor),
          (ExecutableDir() / "../.." / kColmap4Anchor).lexically_normal()}) {
      std::error_code error;
      if (!fs::exists(anchor, error)) continue;
      binaries.push_back(ProbeColmap(anchor.string(), "the COLMAP 4 build of ../shared", scratch));
      break;
    }
  }
  const fs::path debian = FindOnPath("colmap");
  std::error_code error;
  if (!debian.empty() && (binaries.empty() || !fs::equivalent(debian, binaries[0].path, error))) {
    binaries.push_back(ProbeColmap(debian.string(), "colmap on the PATH", scratch));
  }
  return binaries;
}

std::vector<std::string> ColmapRowNames(const ColmapBinary& colmap) {
  std::vector<std::string> names;
  if (colmap.has_global_mapper) names.push_back("colmap-" + colmap.version + "-global");
  names.push_back("colmap-" + colmap.version + "-incremental");
  return names;
}

std::vector<BenchRow> RunColmapPipeline(const BenchOptions& options, const ColmapBinary& colmap,
                                        const BenchGroundTruth* ground_truth) {
  // Extraction and matching once, in a folder of their own; each mapper maps a copy.
  const fs::path folder = fs::path(options.output) / ("colmap-" + colmap.version);
  ResetBenchWorkspace(folder);
  const fs::path database = folder / "database.db";
  spdlog::info("bench: COLMAP {}: extraction and exhaustive matching ...", colmap.version);
  const ChildRun extract =
      RunChild(ExtractCommand(options, colmap, database), folder / "colmap.log");
  ChildRun match;
  if (extract.exit_code == 0) {
    match = RunChild(MatchCommand(options, colmap, database), folder / "colmap.log");
  }
  std::vector<BenchRow> rows;
  for (const std::string& name : ColmapRowNames(colmap)) {
    BenchRow row;
    if (extract.exit_code != 0 || match.exit_code != 0) {
      row.name = name;
      row.workspace = folder.string();
      row.log = (folder / "colmap.log").string();
      row.exit_code = extract.exit_code != 0 ? extract.exit_code : match.exit_code;
    } else {
      row = RunColmapMapper(options, colmap, ground_truth, database, name);
      ReadMatchingFigures(database, &row);
    }
    row.plugins = "COLMAP " + colmap.version + ": sift / exhaustive / sift_matcher / " +
                  (IsGlobalRow(name) ? "global_mapper" : "mapper");
    row.extract_seconds = extract.seconds;
    row.match_seconds = match.seconds;
    row.total_seconds = extract.seconds + match.seconds + OrZero(row.map_seconds);
    row.peak_memory_mb = std::max(
        {OrZero(row.peak_memory_mb), OrZero(extract.peak_memory_mb), OrZero(match.peak_memory_mb)});
    rows.push_back(row);
  }
  return rows;
}

std::vector<BenchRow> RunColmapMappers(const BenchOptions& options, const ColmapBinary& colmap,
                                       const BenchGroundTruth* ground_truth,
                                       const BenchRow& source) {
  const fs::path database = fs::path(source.workspace) / "database.db";
  std::vector<BenchRow> rows;
  for (const std::string& name : ColmapRowNames(colmap)) {
    BenchRow row = RunColmapMapper(options, colmap, ground_truth, database, name);
    row.plugins += " on " + source.name + "'s matches";
    row.matches_of = source.name;
    ReadMatchingFigures(database, &row);
    rows.push_back(row);
  }
  return rows;
}

}  // namespace tessera
