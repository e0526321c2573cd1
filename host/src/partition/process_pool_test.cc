#include "partition/process_pool.h"

#include <gtest/gtest.h>
#include <signal.h>

namespace tessera {
namespace {

TEST(ProcessPool, ReturnsEachCommandsExitCodeInOrder) {
  const std::vector<int> codes = RunProcessPool(
      {{"/bin/sh", "-c", "exit 3"}, {"/bin/true"}, {"/nonexistent/program"}, {"/bin/false"}}, 2);
  EXPECT_EQ(codes, (std::vector<int>{3, 0, 127, 1}));
}

TEST(ProcessPool, AStopReachesTheRunningChildrenAndStartsNoOther) {
  // Asked before the pool starts two, after it waited on them twice: stop.
  int asked = 0;
  // Without the stop, this would run for 20 minutes and return {0, 0, 0}.
  const std::vector<int> codes =
      RunProcessPool({{"/bin/sleep", "600"}, {"/bin/sleep", "600"}, {"/bin/sleep", "600"}}, 2,
                     [&] { return ++asked > 2; });
  EXPECT_EQ(codes, (std::vector<int>{128 + SIGTERM, 128 + SIGTERM, kNotStarted}));
}

}  // namespace
}  // namespace tessera
