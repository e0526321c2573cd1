// Video input speed: frames decoded per second and keyframe selection time (scoring:
// sharpness and DIS optical flow, then selection) per frame, on a pan across a sample
// photo written here as H.264 MP4 (the window size is the argument: 320x240, 640x480;
// 150 frames). Each run decodes the video twice (scoring, then writing the kept frames).
//
//   video_frames_benchmark
//   video_frames_benchmark --benchmark_filter='/320'

#include <benchmark/benchmark.h>
#include <spdlog/spdlog.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "test_support.h"
#include "video/video_frames.h"

namespace tessera {
namespace {

constexpr int kNumFrames = 150;

std::filesystem::path WritePan(const std::filesystem::path& dir, int width) {
  const int height = width * 3 / 4;
  cv::Mat photo = cv::imread(
      (testing::SourceDir() / "examples" / "fountain-P11-small" / "images" / "0005.jpg").string());
  cv::resize(photo, photo, cv::Size(), 2.0 * width / 640, 2.0 * width / 640, cv::INTER_LINEAR);
  const std::filesystem::path file = dir / ("pan_" + std::to_string(width) + ".mp4");
  cv::VideoWriter writer(file.string(), cv::VideoWriter::fourcc('a', 'v', 'c', '1'), 30,
                         cv::Size(width, height));
  const double step = static_cast<double>(photo.cols - width) / kNumFrames;
  for (int i = 0; i < kNumFrames; ++i) {
    writer << photo(cv::Rect(static_cast<int>(i * step), (photo.rows - height) / 2, width, height));
  }
  return file;
}

void BM_VideoFrames(benchmark::State& state) {
  spdlog::set_level(spdlog::level::warn);
  const int width = static_cast<int>(state.range(0));
  const testing::TemporaryDir dir;
  const std::filesystem::path video = WritePan(dir.path(), width);
  double decode_seconds = 0, select_seconds = 0;
  size_t num_frames = 0, num_kept = 0;
  for (auto _ : state) {
    const VideoFrames result = ExtractVideoFrames(video, "pan", dir.path() / "frames", {});
    decode_seconds += result.decode_seconds;
    select_seconds += result.select_seconds;
    num_frames += result.frames.size();
    num_kept = result.images.size();
  }
  // Both passes decode every frame up to the last kept one: count them both.
  state.counters["frames_decoded_per_s"] = 2.0 * num_frames / decode_seconds;
  state.counters["selection_ms_per_frame"] = 1000 * select_seconds / num_frames;
  state.counters["frames_kept"] = static_cast<double>(num_kept);
}
BENCHMARK(BM_VideoFrames)->Arg(320)->Arg(640)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace tessera

BENCHMARK_MAIN();
