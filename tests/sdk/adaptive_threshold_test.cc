#include "tessera/adaptive_threshold.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace tessera {
namespace {

struct Captured {
  Logger logger;
  std::vector<std::string> lines;
  Captured() {
    logger.SetSink([this](LogLevel level, const std::string& text) {
      lines.push_back((level == LogLevel::kWarning ? "warn: " : "info: ") + text);
    });
  }
};

// A detector that finds 2000 / threshold keypoints.
TEST(DetectWithAdaptiveThreshold, HalvesDownToTheFloorAndLogsOnce) {
  Captured log;
  std::vector<int> tried;
  const auto detect = [&](int threshold) {
    tried.push_back(threshold);
    return static_cast<size_t>(2000 / threshold);
  };
  EXPECT_EQ(DetectWithAdaptiveThreshold(size_t{500}, 20, 2, detect, log.logger, "FAST threshold",
                                        "min_fast_threshold"),
            2);
  EXPECT_EQ(tried, (std::vector<int>{20, 10, 5, 2}));
  EXPECT_EQ(log.lines,
            (std::vector<std::string>{"info: 100 features at FAST threshold 20, fewer than "
                                      "min_num_features 500: 1000 at 2"}));
  // Enough at once: one detection, no line; 0 wanted: the same.
  tried.clear();
  log.lines.clear();
  EXPECT_EQ(DetectWithAdaptiveThreshold(size_t{100}, 20, 2, detect, log.logger, "FAST threshold",
                                        "min_fast_threshold"),
            20);
  EXPECT_EQ(DetectWithAdaptiveThreshold(size_t{0}, 20, 2, detect, log.logger, "FAST threshold",
                                        "min_fast_threshold"),
            20);
  EXPECT_EQ(tried, (std::vector<int>{20, 20}));
  EXPECT_TRUE(log.lines.empty());
  // The floor stops it short: a warning names the floor's option.
  EXPECT_EQ(DetectWithAdaptiveThreshold(
                size_t{5000}, 0.04, 0.01, [](double t) { return static_cast<size_t>(20 / t); },
                log.logger, "contrast threshold", "min_contrast_threshold"),
            0.01);
  EXPECT_EQ(log.lines,
            (std::vector<std::string>{"warn: 500 features at contrast threshold 0.04, fewer than "
                                      "min_num_features 5000: 2000 at 0.01, the floor "
                                      "min_contrast_threshold"}));
}

}  // namespace
}  // namespace tessera
