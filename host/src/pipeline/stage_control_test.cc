#include "pipeline/stage_control.h"

#include <gtest/gtest.h>

#include <thread>

namespace tessera {
namespace {

TEST(StageControl, StatusNames) {
  EXPECT_STREQ(StageStatusName(StageStatus::kCompleted), "completed");
  EXPECT_STREQ(StageStatusName(StageStatus::kCancelled), "cancelled");
}

TEST(StageControl, WithoutTokenNeverCancelledAndWithoutCallbackSilent) {
  const StageControl control;
  EXPECT_FALSE(control.Cancelled());
  control.Report("extract", 1, 2);  // no callback: nothing happens, nothing throws
}

TEST(StageControl, CancelFromAnotherThreadIsSeen) {
  CancellationToken token;
  StageControl control;
  control.cancel = &token;
  EXPECT_FALSE(control.Cancelled());
  std::thread([&] { token.Cancel(); }).join();
  EXPECT_TRUE(control.Cancelled());
}

TEST(StageControl, ReportPassesItsArguments) {
  std::string stage;
  size_t done = 0, total = 0;
  StageControl control;
  control.progress = [&](const std::string& s, size_t d, size_t t) {
    stage = s;
    done = d;
    total = t;
  };
  control.Report("match", 3, 7);
  EXPECT_EQ(stage, "match");
  EXPECT_EQ(done, 3u);
  EXPECT_EQ(total, 7u);
}

}  // namespace
}  // namespace tessera
