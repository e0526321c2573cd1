#pragma once

// Runs the pipeline (RunPipeline, as `tessera run`) on a worker thread for the GUI:
// progress of each stage with its rate and remaining time, Cancel, the growing model
// (StageControl::model_changed) and the error of a run that failed. The UI thread only
// copies small state under a mutex the worker holds briefly; it never waits on a stage.

#include <atomic>
#include <chrono>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "gui/scene.h"
#include "pipeline/stage_control.h"

namespace tessera::gui {

struct RunRequest {
  std::filesystem::path image_dir;
  std::filesystem::path output_dir;
  std::filesystem::path manifest_file;  // empty: the default manifest
  // Not empty: the manifest editor's JSON, run in place of manifest_file's contents
  // (whose folder still resolves the manifest's relative paths).
  std::string manifest_json;
  // Map as `tessera map --hierarchical` does (partition/hierarchical_map.h): the view
  // graph cut into clusters (the manifest's distributed settings), each mapped by a
  // `tessera map --cluster K` process beside this executable, `jobs` at once (0: half
  // the cores), then merged. The processes read manifest_file (or the default), so an
  // editor's text that differs from it is refused (save it first).
  bool hierarchical = false;
  int jobs = 0;
};

struct StageProgress {
  std::string stage;
  size_t done = 0;
  size_t total = 0;
  double elapsed_s = 0;  // since the stage's first report
  // Units per second and seconds left, from the units done since the stage started;
  // negative when not known yet.
  double rate_per_s = -1;
  double remaining_s = -1;
  // What done and total count when not the stage's own units ("images registered": the
  // map stage counts the images its models registered against the images of the view
  // graph, those with a verified pair).
  std::string unit;
  bool finished = false;  // the stage ended (map: done stays what its models registered)
  // The map stage: every image registered, or the mapper done, and the stage still going
  // (the final bundle adjustment, the points' colours, the model written): its bar says
  // so until the next stage starts or the run completes.
  bool finishing = false;
  // The map stage: the mapper's step last reported (MapperControl::on_progress, e.g.
  // "rotation averaging"); empty before its first.
  std::string step;
};

enum class RunState { kIdle, kRunning, kCompleted, kCancelled, kFailed };
const char* RunStateName(RunState state);

struct RunStatus {
  RunState state = RunState::kIdle;
  std::vector<StageProgress> stages;  // in the order they started
  std::string error;                  // kFailed: the one-line message
  size_t num_models = 0;              // kCompleted: models written
  // As `tessera run` would exit: 0, 1 (internal), 2 (bad input), 3 (no model).
  int exit_code = 0;
  std::filesystem::path output_dir;
};

// Added to the nice value of the worker thread, and so of the threads the pipeline
// starts from it (at most 19; the UI thread keeps its own): rendering never waits
// behind the pipeline for a core.
inline constexpr int kWorkerNiceness = 10;
// A stage's rate is shown from this many seconds after its start.
inline constexpr double kMinRateSeconds = 0.5;

class RunController {
 public:
  // on_change is called from the worker thread whenever the status or scene changed.
  explicit RunController(std::function<void()> on_change = {});
  ~RunController();  // cancels a run and joins the worker

  // Starts a run; false (and nothing started) while one is running.
  bool Start(const RunRequest& request);
  void Cancel();
  bool Running() const;
  // Cancel was asked and the worker has not ended yet (the stage stops at its next check).
  bool Cancelling() const;
  // Waits for the worker to end (tests and the screenshot mode).
  void Join();

  RunStatus Status() const;
  // The latest model the mapper reported, when newer than *version (then updated).
  std::shared_ptr<const Scene> TakeScene(uint64_t* version) const;

 private:
  void Work(RunRequest request);
  // The stage's report; for "map", its start and end (its registrations come from
  // OnModelChanged).
  void OnProgress(const std::string& stage, size_t done, size_t total);
  void OnModelChanged(size_t model_index, const Reconstruction& model);
  // The mapper's step (StageControl::map_step): named on the map bar; a registration
  // count moves the bar as OnModelChanged does (a mapper that reports no growing model,
  // the global one, still counts).
  void OnMapStep(const std::string& step, size_t done, size_t total);
  // The last stage's done, rate and time left from `done` (under the mutex).
  void UpdateLastStage(size_t done, size_t total);
  void Notify();

  std::function<void()> on_change_;
  mutable std::mutex mutex_;
  RunStatus status_;
  std::vector<std::chrono::steady_clock::time_point> stage_starts_;
  std::filesystem::path output_dir_;  // of the run going on
  std::vector<size_t> registered_;    // per model of the map stage going on
  std::shared_ptr<const Scene> scene_;
  uint64_t scene_version_ = 0;
  std::unique_ptr<CancellationToken> cancel_;
  std::atomic<bool> running_{false};
  std::thread worker_;
};

}  // namespace tessera::gui
