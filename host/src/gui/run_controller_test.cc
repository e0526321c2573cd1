#include "gui/run_controller.h"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <thread>

#include "test_support.h"

namespace tessera::gui {
namespace {

int ThreadNiceness() { return getpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid))); }

// The pipeline runs below the window's priority, and the window's thread keeps its own.
// A run of a folder that does not exist fails at once, on the worker.
TEST(RunController, RunsThePipelineBelowTheWindowsPriority) {
  const testing::TemporaryDir dir;
  const int ui_niceness = ThreadNiceness();
  const std::thread::id ui_thread = std::this_thread::get_id();
  std::atomic<int> worker_niceness{-100};
  std::atomic<int> num_worker_calls{0};
  RunController controller([&] {
    if (std::this_thread::get_id() == ui_thread) return;
    worker_niceness = ThreadNiceness();
    ++num_worker_calls;
  });
  ASSERT_TRUE(controller.Start({dir.path() / "no such folder", dir.path() / "out", {}, {}}));
  controller.Join();
  EXPECT_EQ(controller.Status().state, RunState::kFailed);
  ASSERT_GT(num_worker_calls.load(), 0);
  EXPECT_EQ(worker_niceness.load(), std::min(19, ui_niceness + kWorkerNiceness));
  EXPECT_EQ(ThreadNiceness(), ui_niceness);
}

}  // namespace
}  // namespace tessera::gui
