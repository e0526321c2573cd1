// Frame time of the GUI (1280x800, panels and the 3D view) with 1 and 5 million points
// on the display this benchmark starts (Xvfb; Mesa's llvmpipe renders on the CPU): idle,
// and while the pipeline runs on the worker thread (8 images of the sample at 400 px,
// ORB, every pair, 1 thread; restarted into a fresh workspace whenever it ends). Each
// iteration draws one frame (Frame(), as after an input event) and waits for it to finish.
// Also the time from Cancel, pressed while the matcher runs, to the worker's end.

#include <benchmark/benchmark.h>

#include <chrono>
#include <fstream>
#include <random>
#include <thread>

#include "gui/gl.h"
#include "gui/gui_app.h"
#include "gui/xvfb.h"
#include "pipeline/stage_test_util.h"
#include "test_support.h"

namespace tessera::gui {
namespace {

std::shared_ptr<const Scene> RandomScene(size_t num_points) {
  auto scene = std::make_shared<Scene>();
  scene->model = std::make_shared<const Reconstruction>();
  std::mt19937 random(7);
  std::normal_distribution<float> normal(0, 1);
  std::uniform_int_distribution<int> channel(0, 255);
  scene->positions.resize(3 * num_points);
  scene->colors.resize(3 * num_points);
  scene->point_ids.resize(num_points);
  for (size_t i = 0; i < num_points; ++i) {
    for (size_t axis = 0; axis < 3; ++axis) {
      scene->positions[3 * i + axis] = normal(random);
      scene->colors[3 * i + axis] = static_cast<uint8_t>(channel(random));
    }
    scene->point_ids[i] = i + 1;
  }
  scene->center = Eigen::Vector3f::Zero();
  scene->radius = 2;
  return scene;
}

struct Display {
  testing::Xvfb xvfb;
  bool ok = false;
  std::string why;
  Display() { ok = xvfb.Start(&why); }
};

void FrameTime(benchmark::State& state, bool while_running) {
  static Display display;
  if (!display.ok) {
    state.SkipWithError(display.why.c_str());
    return;
  }
  tessera::testing::TemporaryDir dir;
  tessera::testing::WriteSampleImages(dir.path() / "images", 8);
  std::ofstream(dir.path() / "manifest.json") << R"({"pipeline": {
      "detector": {"plugin": "orb", "options": {"max_num_features": 2000}},
      "pair_selector": {"plugin": "exhaustive"}, "matcher": {"plugin": "brute_force"},
      "bundle_adjuster": {"plugin": "ceres"}}, "threads": 1})";
  GuiOptions options;
  options.images = dir.path() / "images";
  options.manifest = dir.path() / "manifest.json";
  options.follow_run = false;  // keep showing the big scene
  GuiApp app(options);
  app.SetScene(RandomScene(static_cast<size_t>(state.range(0))));
  app.Frame();
  app.Frame();
  int runs = 0;
  for (auto _ : state) {
    if (while_running && !app.controller().Running()) {
      app.controller().Join();
      app.controller().Start(
          {options.images, dir.path() / ("out" + std::to_string(runs++)), options.manifest, {}});
    }
    app.Frame();
    glFinish();
  }
  state.counters["runs_started"] = runs;
  app.controller().Cancel();
}

void BM_FrameIdle(benchmark::State& state) { FrameTime(state, false); }
void BM_FrameWhileRunning(benchmark::State& state) { FrameTime(state, true); }

// Seconds from Cancel to the end of the worker, cancelled once the matcher has finished a
// pair (the run of the GUI test; a fresh workspace each iteration). No window: the worker never
// waits on the UI.
void BM_CancelDuringMatching(benchmark::State& state) {
  tessera::testing::TemporaryDir dir;
  tessera::testing::WriteSampleImages(dir.path() / "images", 8);
  std::ofstream(dir.path() / "manifest.json") << R"({"pipeline": {
      "detector": {"plugin": "orb", "options": {"max_num_features": 2000}},
      "pair_selector": {"plugin": "exhaustive"}, "matcher": {"plugin": "brute_force"},
      "bundle_adjuster": {"plugin": "ceres"}}, "threads": 2})";
  RunController controller;
  int runs = 0;
  auto matching = [&] {
    const RunStatus status = controller.Status();
    return !status.stages.empty() && status.stages.back().stage == "match" &&
           status.stages.back().done >= 1;
  };
  for (auto _ : state) {
    controller.Start({dir.path() / "images",
                      dir.path() / ("out" + std::to_string(runs++)),
                      dir.path() / "manifest.json",
                      {}});
    while (controller.Running() && !matching()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    const auto cancelled_at = std::chrono::steady_clock::now();
    controller.Cancel();
    controller.Join();
    state.SetIterationTime(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - cancelled_at).count());
    if (controller.Status().state != RunState::kCancelled) {
      state.SkipWithError("the run ended before it was cancelled during matching");
      break;
    }
  }
}

BENCHMARK(BM_FrameIdle)->Arg(1000000)->Arg(5000000)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_FrameWhileRunning)
    ->Arg(1000000)
    ->Arg(5000000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_CancelDuringMatching)->Iterations(5)->UseManualTime()->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace tessera::gui
