#pragma once

// What a caller (CLI, bench, GUI, a Slurm shard) gives every stage: a progress callback
// and a cancellation token, both checked between units of work (images, pairs, models).

#include <atomic>
#include <cstddef>
#include <functional>
#include <string>

#include "tessera/reconstruction.h"

namespace tessera {

// How a stage ended. A cancelled stage leaves the workspace consistent: every unit it
// finished is committed, none is half-written, and a re-run does only the rest.
enum class StageStatus { kCompleted, kCancelled };

// "completed" or "cancelled".
const char* StageStatusName(StageStatus status);

// Set by any thread (a GUI button, a signal handler); stages poll it.
class CancellationToken {
 public:
  void Cancel() { cancelled_.store(true, std::memory_order_relaxed); }
  bool IsCancelled() const { return cancelled_.load(std::memory_order_relaxed); }

 private:
  std::atomic<bool> cancelled_{false};
};

// Called with the stage's name ("extract", "match", "map", "export"), the units done
// and the units in all. Calls of one stage come one at a time (never concurrently) and
// `done` never decreases: extract, match and export count 1, 2, ... up to `total` (a
// cancelled stage stops short), map reports (0, 1) as the mapper starts and (1, 1) when
// it ends; a stage with nothing to do calls it once with (0, 0).
using ProgressCallback = std::function<void(const std::string& stage, size_t done, size_t total)>;

struct StageControl {
  ProgressCallback progress;                  // may be empty
  const CancellationToken* cancel = nullptr;  // may be null: never cancelled
  // The map stage's model as it grows, after each image registered (see
  // MapperControl::on_model_changed); may be empty. Called on the stage's thread.
  std::function<void(size_t model_index, const Reconstruction& model)> model_changed;
  // The mapper's steps as it reports them (MapperControl::on_progress: "rotation
  // averaging", "registration", ...); may be empty. Called on the stage's thread.
  std::function<void(const std::string& step, size_t done, size_t total)> map_step;

  bool Cancelled() const { return cancel != nullptr && cancel->IsCancelled(); }
  void Report(const std::string& stage, size_t done, size_t total) const {
    if (progress) progress(stage, done, total);
  }
};

}  // namespace tessera
