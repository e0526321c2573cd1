// The helpers that Tessera's rows and COLMAP's rows of `tessera bench` share.

#include "bench/bench_rows.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <sstream>

#include "database/sqlite_connection.h"
#include "database/sqlite_statement.h"
#include "eval/evaluation.h"
#include "tessera/errors.h"
#include "tessera/io/file_io.h"
#include "tessera/io/model_statistics.h"
#include "util/strings.h"
#include "util/workspace_layout.h"

namespace tessera {

namespace fs = std::filesystem;

namespace {

// A row's workspace is bench's own scratch folder, marked with this file when made: a
// rerun replaces it whole. A folder without the mark is never deleted.
constexpr const char* kBenchMark = workspace_layout::kBenchMark;

}  // namespace

// Pairs matched, pairs verified and their mean number of inliers, from a workspace.
void ReadMatchingFigures(const fs::path& database_file, BenchRow* row) {
  // Plain SQL on COLMAP's own tables, read-only: the database may be COLMAP's (3.8 or 4,
  // without Tessera's tables), which Database would refuse read-only.
  const SqliteConnection connection(database_file, SqliteConnection::Access::kReadOnly);
  const auto count = [&](const std::string& sql, const std::string& what) {
    return SqliteStatement(connection, sql, false).QueryInt64(what);
  };
  row->num_images = static_cast<size_t>(count("SELECT COUNT(*) FROM images;", "count the images"));
  row->num_pairs =
      static_cast<size_t>(count("SELECT COUNT(*) FROM matches;", "count the matched pairs"));
  // Verified: a configuration other than UNDEFINED (0) and DEGENERATE (1).
  const std::string verified = " FROM two_view_geometries WHERE config NOT IN (0, 1);";
  row->num_verified =
      static_cast<size_t>(count("SELECT COUNT(*)" + verified, "count the verified pairs"));
  const int64_t num_inliers = count("SELECT COALESCE(SUM(rows), 0)" + verified, "sum the inliers");
  row->mean_inliers =
      row->num_verified > 0 ? static_cast<double>(num_inliers) / row->num_verified : kBenchNaN;
}

// A model scored against the ground truth, when there is one (nullptr: none).
void ScoreModel(const Reconstruction& model, const BenchGroundTruth* ground_truth, BenchRow* row) {
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

void ReadModelFigures(const Reconstruction& model, const BenchGroundTruth* ground_truth,
                      BenchRow* row) {
  row->num_models = std::max<size_t>(row->num_models, 1);
  row->num_registered = model.images.size();
  row->num_points = model.points3D.size();
  // The same figures, computed the same way, as Tessera's rows (mapping_summary.json).
  const ModelStatistics statistics = ComputeModelStatistics(model);
  row->mean_track_length = statistics.mean_track_length;
  row->mean_reprojection_error = statistics.mean_reprojection_error;
  ScoreModel(model, ground_truth, row);
}

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

void CheckBenchFolder(const fs::path& folder) {
  std::error_code error;
  const fs::file_type type = fs::symlink_status(folder, error).type();
  if (type == fs::file_type::not_found || type == fs::file_type::directory) return;
  throw InputError(folder.string() +
                   ": exists and is not a folder that tessera bench made (a link or a file), "
                   "so nothing is written through it; choose another --output or move it away");
}

std::string LastLogLine(const fs::path& log, const std::string& marker) {
  std::ifstream file(log, std::ios::binary);
  if (!file) return "";
  constexpr std::streamoff kTail = 64 * 1024;
  file.seekg(0, std::ios::end);
  const std::streamoff size = file.tellg();
  file.seekg(std::max<std::streamoff>(0, size - kTail));
  std::string text(static_cast<size_t>(std::min(size, kTail)), '\0');
  file.read(text.data(), static_cast<std::streamsize>(text.size()));
  text.resize(static_cast<size_t>(file.gcount()));
  size_t end = text.size();
  while (end > 0) {
    const size_t start = text.rfind('\n', end - 1);
    const size_t begin = start == std::string::npos ? 0 : start + 1;
    const std::string_view line = std::string_view(text).substr(begin, end - begin);
    const bool blank = line.find_first_not_of(" \t\r") == std::string_view::npos;
    if (!blank && (marker.empty() || line.find(marker) != std::string_view::npos)) {
      return PrintableExcerpt(line, 300);
    }
    if (start == std::string::npos) break;
    end = start;
  }
  return "";
}

double BenchChildTimeout(const BenchOptions& options) {
  return options.child_timeout > 0 ? options.child_timeout : kBenchChildTimeoutSeconds;
}

RunChildOptions BenchChildOptions(const BenchOptions& options, const fs::path& log) {
  RunChildOptions child;
  child.output_file = log;
  child.timeout_seconds = BenchChildTimeout(options);
  child.stop_requested = options.stop_requested;
  return child;
}

std::string ChildFailure(const ChildRun& child, double timeout_seconds, const std::string& detail) {
  std::string what;
  if (child.timed_out) {
    std::ostringstream seconds;
    seconds << timeout_seconds;
    what = "timed out after " + seconds.str() + " s (--child-timeout)";
  } else if (child.stopped) {
    what = "interrupted";
  } else if (!child.started) {
    what = std::string("could not be started: ") + std::strerror(child.error);
  } else if (child.exit_code > 128) {
    what = "crashed (signal " + std::to_string(child.exit_code - 128) + ")";
  } else {
    what = "exited with code " + std::to_string(child.exit_code);
  }
  return detail.empty() ? what : what + ": " + detail;
}

}  // namespace tessera
