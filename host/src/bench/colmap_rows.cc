// COLMAP's rows of `tessera bench` (--with-colmap): the binaries, found and asked their
// versions before any row runs, then either COLMAP's whole pipeline on the images or its
// mappers alone on a copy of a Tessera row's database (--colmap-mapper-only), so that
// the mapper rows compare identical matches. What COLMAP prints is read with a bound and
// escaped before it reaches a message, and its version never becomes a path.

#include "bench/colmap_rows.h"

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <optional>

#include "tessera/errors.h"
#include "tessera/io/colmap_model_io.h"
#include "tessera/io/file_io.h"
#include "util/child_process.h"
#include "util/exit_codes.h"
#include "util/paths.h"
#include "util/strings.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

// A version is "3.8" or "4.2.0.dev0": more than this is not kept.
constexpr size_t kMaxVersionChars = 64;
// A message quotes this much of what a child printed.
constexpr size_t kMaxQuotedChars = 200;

bool IsDigit(char c) { return c >= '0' && c <= '9'; }

// The digits at `*at` as a number of at most 6 digits, advancing `*at`; nullopt when none.
std::optional<int> ReadNumber(std::string_view text, size_t* at) {
  const size_t start = *at;
  while (*at < text.size() && IsDigit(text[*at]) && *at - start < 6) ++*at;
  if (*at == start) return std::nullopt;
  return std::stoi(std::string(text.substr(start, *at - start)));
}

// `given` checked and asked its version (`colmap -h`); `how` says who named it, for the
// error line.
ColmapBinary ProbeColmap(const BenchOptions& options, const std::string& given,
                         const std::string& how) {
  const std::string where = " (" + how + ")";
  const std::string shown = PrintableExcerpt(given, 400);
  ColmapBinary colmap;
  colmap.path = given;
  if (given.find('/') == std::string::npos) {
    colmap.path = FindOnPath(given).string();
    if (colmap.path.empty()) throw InputError(shown + ": not found on the PATH" + where);
  }
  const std::string path = PrintableExcerpt(colmap.path, 400);
  std::error_code error;
  if (!fs::exists(colmap.path, error)) throw InputError(path + ": no such file" + where);
  if (fs::is_directory(colmap.path, error) || access(colmap.path.c_str(), X_OK) != 0) {
    throw InputError(path + ": not executable" + where);
  }
  RunChildOptions probe;  // its output captured, within kChildOutputHead + kChildOutputTail
  probe.timeout_seconds = std::min(BenchChildTimeout(options), kColmapProbeTimeoutSeconds);
  probe.stop_requested = options.stop_requested;
  const ChildRun child = RunChild({colmap.path, "-h"}, probe);
  const std::string first_line = PrintableExcerpt(FirstLine(child.output), kMaxQuotedChars);
  if (child.stopped) throw InputError(path + ": interrupted when asked its version with -h");
  if (child.timed_out) {
    throw InputError(path + ": no answer to -h (its version) within " +
                     std::to_string(static_cast<int>(probe.timeout_seconds)) + " s" + where);
  }
  if (child.exit_code > 128) {
    throw InputError(path + ": crashed (signal " + std::to_string(child.exit_code - 128) +
                     ") when asked its version with -h" + where);
  }
  if (child.exit_code != 0) {
    const std::string hint = child.exit_code == 127 && child.output_bytes > 0
                                 ? "; scripts/install_dependencies.sh installs COLMAP 4's libraries"
                                 : "";
    throw InputError(path + ": exited with code " + std::to_string(child.exit_code) +
                     " when asked its version with -h: " + first_line + hint + where);
  }
  const std::optional<ColmapVersion> version = ParseColmapVersion(child.output);
  if (!version) {
    throw InputError(path + ": does not say it is COLMAP (its -h begins '" + first_line + "')" +
                     where);
  }
  colmap.version = *version;
  if (version->major < 3 || (version->major == 3 && version->minor < 8)) {
    throw InputError(path + ": is COLMAP " + version->text +
                     "; tessera bench needs COLMAP 3.8 or later" + where);
  }
  colmap.has_global_mapper = child.output.find("global_mapper") != std::string::npos;
  spdlog::info("bench: {} is COLMAP {}{}", path, colmap.version.text,
               colmap.has_global_mapper ? ", with global_mapper" : "");
  return colmap;
}

double OrZero(double value) { return std::isnan(value) ? 0.0 : value; }

bool IsColmap3(const ColmapBinary& colmap) { return colmap.version.major == 3; }

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
// models, read back and scored. Throws (InputError, filesystem_error) when they do not
// read.
void ReadLargestModel(const fs::path& sparse, const BenchGroundTruth* ground_truth, BenchRow* row) {
  std::optional<Reconstruction> largest;
  row->num_models = 0;
  if (!fs::is_directory(sparse)) {
    throw InputError(sparse.string() + ": COLMAP's output folder is gone");
  }
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

// A row that failed: its error logged and kept.
void Fail(BenchRow* row, const std::string& error, int exit_code) {
  row->error = error;
  if (row->exit_code == 0) row->exit_code = exit_code;
}

// One of COLMAP's mappers on its own copy of `database`, in its own folder. A failure
// is the row's error.
BenchRow RunColmapMapper(const BenchOptions& options, const ColmapBinary& colmap,
                         const BenchGroundTruth* ground_truth, const fs::path& database,
                         const std::string& name) {
  const bool global = IsGlobalRow(name);
  BenchRow row;
  row.name = name;
  row.colmap = true;
  row.plugins = "COLMAP " + colmap.version.text + ": " + (global ? "global_mapper" : "mapper");
  const fs::path workspace = ColmapFolder(options, colmap) / (global ? "global" : "incremental");
  row.workspace = workspace.string();
  row.log = (workspace / "colmap.log").string();
  try {
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
                 BenchChildOptions(options, workspace / "colmap.log"));
    row.map_seconds = child.seconds;
    row.total_seconds = child.seconds;
    row.peak_memory_mb = child.peak_memory_mb;
    row.exit_code = child.timed_out ? 124 : child.exit_code;
    if (child.exit_code != 0 || child.timed_out || child.stopped) {
      Fail(&row,
           "COLMAP's " + std::string(global ? "global_mapper" : "mapper") + " " +
               ChildFailure(child, BenchChildTimeout(options), LastLogLine(row.log)),
           child.exit_code);
      return row;
    }
    ReadLargestModel(workspace / "sparse", ground_truth, &row);
  } catch (const std::exception& exception) {
    Fail(&row, PrintableExcerpt(exception.what(), 600), kExitBadInput);
  }
  return row;
}

}  // namespace

std::optional<ColmapVersion> ParseColmapVersion(std::string_view help) {
  static constexpr std::string_view kName = "COLMAP ";
  for (size_t at = help.find(kName); at != std::string_view::npos; at = help.find(kName, at + 1)) {
    size_t cursor = at + kName.size();
    const size_t start = cursor;
    const std::optional<int> major = ReadNumber(help, &cursor);
    if (!major || cursor >= help.size() || help[cursor] != '.') continue;
    ++cursor;
    const std::optional<int> minor = ReadNumber(help, &cursor);
    if (!minor) continue;
    // The rest of the version: up to blank space.
    size_t end = cursor;
    while (end < help.size() && end - start < 4 * kMaxVersionChars &&
           std::string_view(" \t\r\n").find(help[end]) == std::string_view::npos) {
      ++end;
    }
    ColmapVersion version;
    version.text = PrintableExcerpt(help.substr(start, end - start), kMaxVersionChars);
    version.major = *major;
    version.minor = *minor;
    return version;
  }
  return std::nullopt;
}

std::vector<ColmapBinary> FindColmapBinaries(const BenchOptions& options) {
  setenv("QT_QPA_PLATFORM", "offscreen", 1);  // COLMAP 3.8 starts Qt even without its GUI
  std::vector<ColmapBinary> binaries;
  if (!options.colmap_binaries.empty()) {
    for (const std::string& path : options.colmap_binaries) {
      binaries.push_back(ProbeColmap(options, path, "named by --colmap"));
    }
    AssignColmapLabels(&binaries, {});
    return binaries;
  }
  const char* variable = std::getenv("TESSERA_COLMAP");
  if (variable != nullptr && *variable != '\0') {
    binaries.push_back(ProbeColmap(options, variable, "named by TESSERA_COLMAP"));
  } else {
    for (const fs::path& anchor :
         {fs::path(kColmap4Anchor),
          (ExecutableDir() / "../.." / kColmap4Anchor).lexically_normal()}) {
      std::error_code error;
      if (!fs::exists(anchor, error)) continue;
      binaries.push_back(ProbeColmap(options, anchor.string(), "the COLMAP 4 build of ../shared"));
      break;
    }
  }
  const fs::path debian = FindOnPath("colmap");
  std::error_code error;
  if (!debian.empty() && (binaries.empty() || !fs::equivalent(debian, binaries[0].path, error))) {
    binaries.push_back(ProbeColmap(options, debian.string(), "colmap on the PATH"));
  }
  AssignColmapLabels(&binaries, {});
  return binaries;
}

void AssignColmapLabels(std::vector<ColmapBinary>* binaries,
                        const std::vector<std::string>& taken) {
  std::vector<std::string> names = taken;
  for (ColmapBinary& colmap : *binaries) {
    const std::string base = SafeFileName("colmap-" + colmap.version.text, kMaxVersionChars);
    colmap.label = base;
    for (int suffix = 2;; ++suffix) {
      const std::vector<std::string> rows = ColmapRowNames(colmap);
      const bool free = std::none_of(rows.begin(), rows.end(), [&](const std::string& row) {
        return std::find(names.begin(), names.end(), row) != names.end();
      });
      if (free) break;
      colmap.label = base + "-" + std::to_string(suffix);
    }
    for (const std::string& row : ColmapRowNames(colmap)) names.push_back(row);
  }
}

std::vector<std::string> ColmapRowNames(const ColmapBinary& colmap) {
  std::vector<std::string> names;
  if (colmap.has_global_mapper) names.push_back(colmap.label + "-global");
  names.push_back(colmap.label + "-incremental");
  return names;
}

fs::path ColmapFolder(const BenchOptions& options, const ColmapBinary& colmap) {
  return fs::path(options.output) / "colmap" / colmap.label;
}

std::vector<fs::path> ColmapWorkspaces(const BenchOptions& options, const ColmapBinary& colmap) {
  const fs::path folder = ColmapFolder(options, colmap);
  return {folder / "features", folder / "global", folder / "incremental"};
}

std::vector<BenchRow> RunColmapPipeline(const BenchOptions& options, const ColmapBinary& colmap,
                                        const BenchGroundTruth* ground_truth) {
  // Extraction and matching once, in a folder of their own; each mapper maps a copy.
  const fs::path folder = ColmapFolder(options, colmap) / "features";
  const fs::path database = folder / "database.db";
  const fs::path log = folder / "colmap.log";
  ChildRun extract, match;
  std::string failure;  // the shared steps' error, each row's
  int failure_code = 0;
  try {
    ResetBenchWorkspace(folder);
    spdlog::info("bench: COLMAP {}: extraction and exhaustive matching ...", colmap.version.text);
    extract = RunChild(ExtractCommand(options, colmap, database), BenchChildOptions(options, log));
    if (extract.exit_code != 0 || extract.timed_out || extract.stopped) {
      failure = "COLMAP's feature_extractor " +
                ChildFailure(extract, BenchChildTimeout(options), LastLogLine(log));
      failure_code = extract.timed_out ? 124 : extract.exit_code;
    } else {
      match = RunChild(MatchCommand(options, colmap, database), BenchChildOptions(options, log));
      if (match.exit_code != 0 || match.timed_out || match.stopped) {
        failure = "COLMAP's exhaustive_matcher " +
                  ChildFailure(match, BenchChildTimeout(options), LastLogLine(log));
        failure_code = match.timed_out ? 124 : match.exit_code;
      }
    }
  } catch (const std::exception& exception) {
    failure = PrintableExcerpt(exception.what(), 600);
    failure_code = kExitBadInput;
  }
  const bool interrupted = extract.stopped || match.stopped;
  std::vector<BenchRow> rows;
  for (const std::string& name : ColmapRowNames(colmap)) {
    BenchRow row;
    if (!failure.empty() || (options.stop_requested && options.stop_requested())) {
      row.name = name;
      row.colmap = true;
      row.workspace = folder.string();
      row.log = log.string();
      row.exit_code = failure_code;
      row.error = failure.empty() ? "interrupted" : failure;
      if (row.exit_code == 0) row.exit_code = kExitInterrupted;
    } else {
      row = RunColmapMapper(options, colmap, ground_truth, database, name);
      if (row.error.empty()) {
        try {
          ReadMatchingFigures(database, &row);
        } catch (const std::exception& exception) {
          Fail(&row, PrintableExcerpt(exception.what(), 600), kExitBadInput);
        }
      }
    }
    row.plugins = "COLMAP " + colmap.version.text + ": sift / exhaustive / sift_matcher / " +
                  (IsGlobalRow(name) ? "global_mapper" : "mapper");
    row.extract_seconds = extract.seconds;
    row.match_seconds = match.seconds;
    row.total_seconds = extract.seconds + match.seconds + OrZero(row.map_seconds);
    row.peak_memory_mb = std::max(
        {OrZero(row.peak_memory_mb), OrZero(extract.peak_memory_mb), OrZero(match.peak_memory_mb)});
    rows.push_back(row);
    if (interrupted) break;
  }
  return rows;
}

std::vector<BenchRow> RunColmapMappers(const BenchOptions& options, const ColmapBinary& colmap,
                                       const BenchGroundTruth* ground_truth,
                                       const BenchRow& source) {
  const fs::path database = fs::path(source.workspace) / "database.db";
  std::vector<BenchRow> rows;
  for (const std::string& name : ColmapRowNames(colmap)) {
    if (options.stop_requested && options.stop_requested()) break;
    BenchRow row = RunColmapMapper(options, colmap, ground_truth, database, name);
    row.plugins += " on " + source.name + "'s matches";
    row.matches_of = source.name;
    if (row.error.empty()) {
      try {
        ReadMatchingFigures(database, &row);
      } catch (const std::exception& exception) {
        Fail(&row, PrintableExcerpt(exception.what(), 600), kExitBadInput);
      }
    }
    rows.push_back(row);
  }
  return rows;
}

}  // namespace tessera
