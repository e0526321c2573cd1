#pragma once

// Skips for missing shared data (../shared, TESSERA_SHARED_DIR) or a missing colmap: a
// visible skip on a developer's machine, a failure in CI (CI=true), where both are always
// installed and a skip would hide a broken path. Skips for what a machine may lack for
// good (a display, Slurm, Open3D) stay plain GTEST_SKIPs with their reason.

#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <iostream>

namespace tessera::testing {

// CI=true: set by GitHub Actions, GitLab CI and most others, and by hand to try it.
inline bool InContinuousIntegration() {
  const char* ci = std::getenv("CI");
  return ci != nullptr && std::strcmp(ci, "true") == 0;
}

}  // namespace tessera::testing

// Skips the test with REASON, streamed (`TESSERA_SKIP_OR_FAIL_IN_CI(path << " not found")`),
// or fails it in CI. Returns from the test body either way.
#define TESSERA_SKIP_OR_FAIL_IN_CI(reason)                             \
  do {                                                                 \
    if (::tessera::testing::InContinuousIntegration()) {               \
      FAIL() << "CI: " << reason << "; this test must not skip in CI"; \
    }                                                                  \
    GTEST_SKIP() << reason;                                            \
  } while (false)

// For one part of a test that cannot run while the rest can: a line in the output, or a
// failure in CI; the test goes on either way.
#define TESSERA_SKIP_PART_OR_FAIL_IN_CI(reason)                               \
  do {                                                                        \
    if (::tessera::testing::InContinuousIntegration()) {                      \
      ADD_FAILURE() << "CI: " << reason << "; this test must not skip in CI"; \
    } else {                                                                  \
      std::cout << "[   NOTE   ] part not run: " << reason << std::endl;      \
    }                                                                         \
  } while (false)
