#include "gui/run_controller.h"

#include <spdlog/spdlog.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <nlohmann/json.hpp>
#include <thread>

#include "gui/match_matrix.h"
#include "manifest/manifest.h"
#include "partition/hierarchical_map.h"
#include "pipeline/pipeline_context.h"
#include "pipeline/run_pipeline.h"
#include "plugin/plugin_call.h"
#include "tessera/errors.h"
#include "tessera/io/file_io.h"
#include "util/exit_codes.h"
#include "util/paths.h"
#include "util/workspace_layout.h"

namespace tessera::gui {
namespace {

// The request's manifest: the editor's JSON when given, else the manifest file.
PipelineContext CreateContext(const RunRequest& request) {
  if (request.hierarchical) {
    // The cluster processes read the manifest's file, and clusters.json records which
    // manifest cut them: this run's is that file, the editor's text being the same.
    const std::filesystem::path file =
        request.manifest_file.empty() ? DefaultManifestFile() : request.manifest_file;
    if (!request.manifest_json.empty() && ReadFileContents(file) != request.manifest_json) {
      throw InputError(
          "map in clusters: each cluster's `tessera map --cluster K` process reads the "
          "manifest from its file, and the editor's text differs from " +
          file.string() + ": save it (Save as) first");
    }
    return PipelineContext::Create(file);
  }
  if (request.manifest_json.empty()) return PipelineContext::Create(request.manifest_file);
  const std::filesystem::path file =
      request.manifest_file.empty() ? DefaultManifestFile() : request.manifest_file;
  nlohmann::json json;
  try {
    json = nlohmann::json::parse(request.manifest_json);
  } catch (const nlohmann::json::parse_error& error) {
    throw InputError(std::string("the manifest editor: invalid JSON: ") + error.what());
  }
  return PipelineContext::Create(
      Manifest::FromJson(json, file.parent_path(), "the manifest editor"));
}

// Extract and match here, then map as `tessera map --hierarchical` (the CLI's entry
// point, MapHierarchically): partition, a pool of `tessera map --cluster K` processes
// (the executable beside this one: `tessera gui` is it), the merge. Each process gets
// the manifest file (`context` was made from it: CreateContext); MapHierarchically
// gives it the workspace, the image folder and its share of the cores.
RunResult RunHierarchically(const PipelineContext& context, const RunRequest& request,
                            const StageControl& control) {
  const std::filesystem::path manifest =
      request.manifest_file.empty() ? DefaultManifestFile() : request.manifest_file;
  const RunOptions options(request.image_dir, request.output_dir);
  RunResult run;
  run.summary.extract = RunExtract(context, options, control);
  if (run.summary.extract.status != StageStatus::kCancelled) {
    run.summary.match = RunMatch(context, options, control);
  }
  if (run.summary.extract.status == StageStatus::kCancelled ||
      run.summary.match.status == StageStatus::kCancelled) {
    run.status = StageStatus::kCancelled;
    return run;
  }
  HierarchicalMapOptions hierarchical;
  hierarchical.tessera = ExecutableDir() / "tessera";
  hierarchical.manifest = manifest;
  hierarchical.jobs = request.jobs;                     // 0: the library's default, half the cores
  hierarchical.threads = context.manifest.num_threads;  // 0: the cores / jobs
  run.summary.map = MapHierarchically(context, options, hierarchical, control);
  if (run.summary.map.status == StageStatus::kCancelled) run.status = StageStatus::kCancelled;
  return run;
}

}  // namespace

const char* RunStateName(RunState state) {
  switch (state) {
    case RunState::kIdle:
      return "idle";
    case RunState::kRunning:
      return "running";
    case RunState::kCompleted:
      return "completed";
    case RunState::kCancelled:
      return "cancelled";
    case RunState::kFailed:
      return "failed";
  }
  return "unknown";
}

RunController::RunController(std::function<void()> on_change) : on_change_(std::move(on_change)) {}

RunController::~RunController() {
  Cancel();
  Join();
}

bool RunController::Start(const RunRequest& request) {
  if (running_.exchange(true)) return false;
  if (worker_.joinable()) worker_.join();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    status_ = RunStatus();
    status_.state = RunState::kRunning;
    status_.output_dir = request.output_dir;
    output_dir_ = request.output_dir;
    stage_starts_.clear();
    cancel_ = std::make_unique<CancellationToken>();
  }
  worker_ = std::thread(&RunController::Work, this, request);
  return true;
}

void RunController::Cancel() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (cancel_ != nullptr) cancel_->Cancel();
}

bool RunController::Running() const { return running_.load(); }

bool RunController::Cancelling() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return running_.load() && cancel_ != nullptr && cancel_->IsCancelled();
}

void RunController::Join() {
  if (worker_.joinable()) worker_.join();
}

RunStatus RunController::Status() const {
  std::lock_guard<std::mutex> lock(mutex_);
  RunStatus status = status_;
  const auto now = std::chrono::steady_clock::now();
  if (status.state == RunState::kRunning) {
    // Elapsed time moves on between reports.
    for (size_t i = 0; i < status.stages.size(); ++i) {
      StageProgress& stage = status.stages[i];
      if (stage.total > 0 && stage.done >= stage.total) continue;
      stage.elapsed_s = std::chrono::duration<double>(now - stage_starts_[i]).count();
    }
  }
  return status;
}

std::shared_ptr<const Scene> RunController::TakeScene(uint64_t* version) const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (scene_version_ == *version) return nullptr;
  *version = scene_version_;
  return scene_;
}

void RunController::UpdateLastStage(size_t done, size_t total) {
  const auto now = std::chrono::steady_clock::now();
  StageProgress& progress = status_.stages.back();
  const double elapsed = std::chrono::duration<double>(now - stage_starts_.back()).count();
  progress.done = done;
  progress.total = total;
  progress.elapsed_s = elapsed;
  // No rate from the first second: a stage that starts with work already done (or a
  // burst) would read millions per second.
  progress.rate_per_s = progress.remaining_s = -1;
  if (done > 0 && elapsed >= kMinRateSeconds) {
    progress.rate_per_s = static_cast<double>(done) / elapsed;
    progress.remaining_s = static_cast<double>(total - std::min(done, total)) / progress.rate_per_s;
  }
}

void RunController::OnProgress(const std::string& stage, size_t done, size_t total) {
  // The map stage reports (0, 1) as it starts: its bar counts registered images against
  // the images of the view graph, read here on the worker.
  size_t view_graph_images = 0;
  if (stage == "map" && done == 0) {
    try {
      const MatchMatrix matrix = ReadMatchMatrix(output_dir_);
      for (size_t row = 0; row < matrix.size(); ++row) {
        for (size_t column = 0; column < matrix.size(); ++column) {
          if (matrix.Inliers(row, column) > 0) {
            ++view_graph_images;
            break;
          }
        }
      }
    } catch (const std::exception&) {
      // Unreadable: the bar shows the stage's own (0, 1).
    }
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const bool is_new = status_.stages.empty() || status_.stages.back().stage != stage;
    if (is_new && !status_.stages.empty() && status_.stages.back().finishing) {
      // The stage before this one ended as this one started.
      StageProgress& before = status_.stages.back();
      before.finished = true;
      before.rate_per_s = before.remaining_s = -1;
    }
    if (is_new) {
      StageProgress started;
      started.stage = stage;
      status_.stages.push_back(started);
      stage_starts_.push_back(std::chrono::steady_clock::now());
    }
    StageProgress& progress = status_.stages.back();
    if (stage == "map" && !progress.unit.empty()) {
      // Every image registered, or the mapper returned: done stays what the models
      // registered; the stage goes on (final adjustment, colours, writing) until the
      // next starts or the run ends.
      if (done == total) {
        progress.finishing = true;
        progress.rate_per_s = progress.remaining_s = -1;
      }
    } else if (stage == "map" && view_graph_images > 0) {
      progress.unit = "images registered";
      registered_.clear();
      UpdateLastStage(0, view_graph_images);
    } else {
      UpdateLastStage(done, total);
      progress.finished = total > 0 && done >= total;
    }
  }
  Notify();
}

void RunController::OnModelChanged(size_t model_index, const Reconstruction& model) {
  // Copied and flattened here, on the worker; the UI thread only swaps the pointer.
  std::shared_ptr<const Scene> scene = MakeScene(std::make_shared<const Reconstruction>(model));
  {
    std::lock_guard<std::mutex> lock(mutex_);
    scene_ = std::move(scene);
    ++scene_version_;
    if (!status_.stages.empty() && status_.stages.back().stage == "map" &&
        !status_.stages.back().unit.empty()) {
      if (registered_.size() <= model_index) registered_.resize(model_index + 1, 0);
      registered_[model_index] = model.NumRegisteredImages();
      size_t done = 0;
      for (const size_t each : registered_) done += each;
      const StageProgress& map = status_.stages.back();
      UpdateLastStage(std::min(done, map.total), map.total);
    }
  }
  Notify();
}

void RunController::OnMapStep(const std::string& step, size_t done, size_t total) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (status_.stages.empty() || status_.stages.back().stage != "map") return;
    StageProgress& map = status_.stages.back();
    map.step = step;
    if (step == "registration" && !map.unit.empty() && total > 0) {
      const size_t count = std::min(std::max(map.done, done), map.total);
      if (count != map.done) UpdateLastStage(count, map.total);
    }
  }
  Notify();
}

void RunController::Notify() {
  if (on_change_) on_change_();
}

void RunController::Work(RunRequest request) {
  // The window comes first: on a machine with few cores the renderer (with Mesa's
  // llvmpipe, its rasteriser threads too) must not queue behind the pipeline. Linux
  // keeps the nice value per thread, and the threads the pipeline starts inherit it.
  const auto thread_id = static_cast<id_t>(syscall(SYS_gettid));
  errno = 0;
  const int niceness = getpriority(PRIO_PROCESS, thread_id);
  if (errno != 0 ||
      setpriority(PRIO_PROCESS, thread_id, std::min(19, niceness + kWorkerNiceness)) != 0) {
    spdlog::debug("gui: the pipeline's worker keeps its priority (setpriority failed)");
  }
  StageControl control;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    control.cancel = cancel_.get();
  }
  control.progress = [this](const std::string& stage, size_t done, size_t total) {
    OnProgress(stage, done, total);
  };
  control.model_changed = [this](size_t model_index, const Reconstruction& model) {
    OnModelChanged(model_index, model);
  };
  control.map_step = [this](const std::string& step, size_t done, size_t total) {
    OnMapStep(step, done, total);
  };

  RunState state = RunState::kFailed;
  std::string error;
  size_t num_models = 0;
  int exit_code = kExitInternalError;
  try {
    const PipelineContext context = CreateContext(request);
    context.LimitLibraryThreads();
    const RunResult result =
        request.hierarchical
            ? RunHierarchically(context, request, control)
            : RunPipeline(context, {request.image_dir, request.output_dir}, control);
    num_models = result.summary.map.num_models;
    if (result.status == StageStatus::kCancelled) {
      state = RunState::kCancelled;
      exit_code = kExitSuccess;
      spdlog::info("run cancelled: the finished work is kept in {}; Run again resumes it",
                   request.output_dir.string());
    } else if (num_models == 0) {
      error = (request.output_dir / workspace_layout::kDatabase).string() +
              ": no model could be built: no pair of images initialised a model";
      spdlog::error("{}", error);
      exit_code = kExitNoModel;
    } else {
      state = RunState::kCompleted;
      exit_code = kExitSuccess;
    }
  } catch (const PluginError& exception) {
    error = exception.what();
    exit_code = exception.input_error() ? kExitBadInput : kExitInternalError;
    spdlog::error("{}", error);
  } catch (const InputError& exception) {
    error = exception.what();
    exit_code = kExitBadInput;
    spdlog::error("{}", error);
  } catch (const std::exception& exception) {
    error = std::string("internal error: ") + exception.what();
    spdlog::error("{}", error);
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    status_.state = state;
    status_.error = error;
    // A stopped stage has no rate nor time left.
    for (StageProgress& stage : status_.stages) {
      if (state == RunState::kCompleted && stage.finishing) stage.finished = true;
      if (!stage.finished) stage.rate_per_s = stage.remaining_s = -1;
    }
    status_.num_models = num_models;
    status_.exit_code = exit_code;
  }
  running_.store(false);
  Notify();
}

}  // namespace tessera::gui
