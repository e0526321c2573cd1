#include "video/video_frames.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "tessera/errors.h"
#include "tessera/io/file_io.h"
#include "test_support.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

constexpr int kStep = 6;  // px the window moves per frame

// What each frame of the test video shows.
struct TestFrame {
  int position;  // the window's x offset: frames with the same position show the same
  bool blurred;
};

// A pan across a sample photo: a 320x240 window moving kStep px per frame, with a
// blurred copy after every third frame and the camera held still for 10 frames twice.
// H.264 in MP4 (fourcc avc1), as phones write it.
std::vector<TestFrame> WritePanVideo(const fs::path& file, int num_positions, int top = 200) {
  const cv::Mat photo = cv::imread(
      (testing::SourceDir() / "examples" / "fountain-P11-small" / "images" / "0005.jpg").string());
  std::vector<TestFrame> frames;
  cv::VideoWriter writer(file.string(), cv::VideoWriter::fourcc('a', 'v', 'c', '1'), 10,
                         cv::Size(320, 240));
  EXPECT_TRUE(writer.isOpened());
  for (int p = 0; p < num_positions; ++p) {
    const cv::Mat window = photo(cv::Rect(p * kStep, top, 320, 240)).clone();
    writer << window;
    frames.push_back({p, false});
    if (p % 3 == 1) {
      cv::Mat blurred;
      cv::GaussianBlur(window, blurred, cv::Size(), 2.5);
      writer << blurred;
      frames.push_back({p, true});
    }
    if (p == 20 || p == 50) {
      for (int k = 0; k < 10; ++k) {
        writer << window;
        frames.push_back({p, false});
      }
    }
  }
  return frames;
}

TEST(VideoFrames, NamesCarryTheFrameIndexFirstThenTheTime) {
  EXPECT_EQ(VideoFrameName(123, 4.1), "frame_000123_4.100s.jpg");
  EXPECT_EQ(VideoFrameName(0, 0), "frame_000000_0.000s.jpg");
}

TEST(VideoFrames, KeepsNoBlurredFrameAndCoversThePan) {
  const testing::TemporaryDir dir;
  const std::vector<TestFrame> truth = WritePanVideo(dir.path() / "pan.mp4", 100);
  VideoFrameOptions options;
  options.selection.keyframe_motion = 0.1;  // 32 px: about 5 positions per keyframe
  std::vector<VideoFrames> results;
  const fs::path frames_dir = IngestVideos({dir.path() / "pan.mp4"}, dir.path(), options, &results);
  EXPECT_EQ(frames_dir, dir.path() / "video_frames");
  ASSERT_EQ(results.size(), 1u);
  const VideoFrames& video = results[0];
  ASSERT_EQ(video.frames.size(), truth.size());  // every frame decoded
  EXPECT_EQ(video.width, 320);
  EXPECT_NEAR(video.fps, 10, 1e-6);
  EXPECT_NEAR(video.frames[5].time_s, 0.5, 1e-9);

  // The flow measures the pan: kStep px per moving frame, none while still.
  size_t num_moving_right = 0, num_moving = 0;
  for (size_t i = 1; i < truth.size(); ++i) {
    if (truth[i].position != truth[i - 1].position && !truth[i].blurred && !truth[i - 1].blurred) {
      ++num_moving;
      num_moving_right += std::abs(video.frames[i].motion - kStep) < 1.0;
    }
    if (truth[i].position == truth[i - 1].position && !truth[i].blurred && !truth[i - 1].blurred) {
      EXPECT_LT(video.frames[i].motion, 0.5) << "frame " << i;
    }
  }
  EXPECT_GT(num_moving_right, 0.9 * num_moving);

  // No blurred frame kept; no gap of more than two keyframe distances; each still
  // stretch gives at most one frame.
  const double total = video.selection.total_motion;
  const int max_gap = static_cast<int>(2 * total / video.selection.num_segments / kStep) + 2;
  EXPECT_GE(video.selection.selected.size(), 15u);
  int previous = -1;
  std::map<int, int> kept_per_position;
  for (const size_t i : video.selection.selected) {
    EXPECT_FALSE(truth[i].blurred) << "blurred frame " << i << " kept";
    const int position = truth[i].position;
    ++kept_per_position[position];
    if (previous >= 0) {
      EXPECT_LE(position - previous, max_gap) << "after position " << previous;
    }
    previous = position;
  }
  EXPECT_LE(truth[video.selection.selected.front()].position, max_gap);
  EXPECT_GE(truth[video.selection.selected.back()].position, 99 - max_gap);
  EXPECT_LE(kept_per_position[20], 1);
  EXPECT_LE(kept_per_position[50], 1);

  // Written as named, and recorded with every frame's scores.
  for (size_t k = 0; k < video.images.size(); ++k) {
    const size_t i = video.selection.selected[k];
    EXPECT_EQ(video.images[k], "pan/" + VideoFrameName(static_cast<int>(i), i / 10.0));
    const cv::Mat image = cv::imread((frames_dir / video.images[k]).string());
    EXPECT_EQ(image.cols, 320);
  }
  const nlohmann::json record = nlohmann::json::parse(ReadFileContents(dir.path() / "frames.json"));
  ASSERT_EQ(record["videos"].size(), 1u);
  const nlohmann::json& recorded = record["videos"][0];
  EXPECT_EQ(recorded["frames"].size(), truth.size());
  EXPECT_EQ(recorded["num_selected"], video.images.size());
  EXPECT_TRUE(recorded["frames"][0].contains("sharpness"));
  EXPECT_TRUE(recorded["frames"][0].contains("motion_px"));

  // A second run with the same video and options decodes nothing again.
  std::vector<VideoFrames> again;
  IngestVideos({dir.path() / "pan.mp4"}, dir.path(), options, &again);
  ASSERT_EQ(again.size(), 1u);
  EXPECT_TRUE(again[0].reused);
  EXPECT_EQ(again[0].images, video.images);
  // Other options: selected again, and the frames of the earlier selection not kept
  // are removed.
  options.selection.target_frames = 12;
  again.clear();
  IngestVideos({dir.path() / "pan.mp4"}, dir.path(), options, &again);
  EXPECT_FALSE(again[0].reused);
  EXPECT_EQ(again[0].images.size(), 12u);
  size_t num_files = 0;
  for (const auto& entry : fs::directory_iterator(frames_dir / "pan"))
    num_files += entry.is_regular_file();
  EXPECT_EQ(num_files, 12u);
}

// A camera's files copied with their times kept: a video replaced by another of the same
// size and modification time is decoded again, as videos are keyed by their content.
TEST(VideoFrames, AVideoReplacedByAnotherOfTheSameSizeAndTimeIsDecodedAgain) {
  const testing::TemporaryDir dir;
  const fs::path first = dir.path() / "first.mp4", second = dir.path() / "second.mp4";
  WritePanVideo(first, 30, 200);
  WritePanVideo(second, 30, 0);  // the same pan, higher up the photo
  // The same size: the shorter one padded at its end, which the demuxer ignores.
  const uintmax_t size = std::max(fs::file_size(first), fs::file_size(second));
  fs::resize_file(first, size);
  fs::resize_file(second, size);
  const fs::file_time_type time = fs::last_write_time(first);
  const fs::path video = dir.path() / "in" / "pan.mp4";
  fs::create_directories(video.parent_path());
  const auto ingest = [&](const fs::path& from) {
    if (!from.empty()) {
      fs::copy_file(from, video, fs::copy_options::overwrite_existing);
      fs::last_write_time(video, time);
    }
    std::vector<VideoFrames> results;
    IngestVideos({video}, dir.path() / "out", {}, &results);
    EXPECT_EQ(results.size(), 1u);
    return results.at(0);
  };
  const auto first_pixels = [&](const VideoFrames& frames) {
    return cv::imread((dir.path() / "out" / "video_frames" / frames.images.at(0)).string());
  };
  const VideoFrames before = ingest(first);
  EXPECT_FALSE(before.reused);
  const cv::Mat before_pixels = first_pixels(before);
  EXPECT_TRUE(ingest({}).reused);  // unchanged: not decoded again

  const VideoFrames after = ingest(second);
  EXPECT_FALSE(after.reused);
  EXPECT_NE(after.content_hash, before.content_hash);
  const cv::Mat after_pixels = first_pixels(after);
  ASSERT_EQ(after_pixels.size(), before_pixels.size());
  EXPECT_GT(cv::norm(after_pixels, before_pixels, cv::NORM_L1) / after_pixels.total(), 10.0)
      << "the first video's frames were kept";
  const nlohmann::json record =
      nlohmann::json::parse(ReadFileContents(dir.path() / "out" / "frames.json"));
  EXPECT_EQ(record["videos"][0]["content_hash"], after.content_hash);
  EXPECT_EQ(after.content_hash.size(), 32u);
}

TEST(VideoFrames, AShortVideoKeepsEveryFrame) {
  const testing::TemporaryDir dir;
  WritePanVideo(dir.path() / "short.mp4", 4);  // 4 positions, one blurred copy: 5 frames
  std::vector<VideoFrames> results;
  IngestVideos({dir.path() / "short.mp4"}, dir.path(), {}, &results);  // min_frames 10
  ASSERT_EQ(results.size(), 1u);
  EXPECT_TRUE(results[0].selection.too_few_frames);
  EXPECT_EQ(results[0].images.size(), 5u);
}

TEST(VideoFrames, AnUnreadableOrEmptyVideoIsAnInputErrorNamingTheFile) {
  const testing::TemporaryDir dir;
  const auto error_of = [&](const fs::path& file) {
    try {
      IngestVideos({file}, dir.path() / "out", {});
    } catch (const InputError& error) {
      return std::string(error.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(error_of(dir.path() / "missing.mp4"),
            (dir.path() / "missing.mp4").string() + ": no such video file");
  std::ofstream(dir.path() / "text.mp4") << "not a video";
  EXPECT_EQ(error_of(dir.path() / "text.mp4").rfind((dir.path() / "text.mp4").string() + ": ", 0),
            0u);
  std::ofstream(dir.path() / "empty.mp4");
  EXPECT_EQ(error_of(dir.path() / "empty.mp4").rfind((dir.path() / "empty.mp4").string() + ": ", 0),
            0u);
}

// A video's frames are images named <video stem>/frame_...jpg: a line break in the
// video's name would be in each of them (a COLMAP text model cannot hold it).
TEST(VideoFrames, AControlCharacterInAVideoNameIsAnInputError) {
  const testing::TemporaryDir dir;
  const fs::path video = dir.path() / "pan\nrm.mp4";
  try {
    IngestVideos({video}, dir.path() / "out", {});
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()),
              "video '" + dir.path().string() +
                  "/pan\\nrm.mp4': the image name 'pan\\nrm/frame_000000_0.000s.jpg' contains "
                  "a line break, which a COLMAP text model cannot hold.");
  }
  // Refused before anything is written.
  EXPECT_FALSE(fs::exists(dir.path() / "out" / "video_frames"));
}

// frames.json is read back to reuse a selection: the image names it holds are checked as
// every image name from outside is.
TEST(VideoFrames, AnUnsafeImageNameInFramesJsonIsAnInputError) {
  const testing::TemporaryDir dir;
  WritePanVideo(dir.path() / "short.mp4", 4);
  IngestVideos({dir.path() / "short.mp4"}, dir.path(), {});
  const fs::path record_file = dir.path() / "frames.json";
  nlohmann::json record = nlohmann::json::parse(ReadFileContents(record_file));
  record["videos"][0]["frames"][0]["image"] = "../../outside.jpg";
  WriteFileAtomically(record_file, record.dump(2));
  try {
    IngestVideos({dir.path() / "short.mp4"}, dir.path(), {});
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()),
              record_file.string() +
                  ": the path '../../outside.jpg' has a '..' component, which leads out of its "
                  "folder");
  }
  // A frame of another folder (another video's) is not one Tessera wrote for this one.
  record["videos"][0]["frames"][0]["image"] = "other/frame_000000_0.000s.jpg";
  WriteFileAtomically(record_file, record.dump(2));
  try {
    IngestVideos({dir.path() / "short.mp4"}, dir.path(), {});
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what())
                  .find("the frame 'other/frame_000000_0.000s.jpg' does not "
                        "lie in " +
                        (dir.path() / "video_frames/short").string()),
              std::string::npos)
        << error.what();
  }
}

// OUTPUT/video_frames, or a video's folder in it, a link to another folder: no frame is
// written or removed through it.
TEST(VideoFrames, NothingIsWrittenOrRemovedThroughALink) {
  const testing::TemporaryDir dir;
  WritePanVideo(dir.path() / "short.mp4", 4);
  fs::create_directories(dir.path() / "elsewhere");
  std::ofstream(dir.path() / "elsewhere/holiday.jpg") << "precious";
  fs::create_directories(dir.path() / "out/video_frames");
  fs::create_directory_symlink(dir.path() / "elsewhere", dir.path() / "out/video_frames/short");
  try {
    IngestVideos({dir.path() / "short.mp4"}, dir.path() / "out", {});
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what())
                  .find((dir.path() / "out/video_frames/short").string() + " is a symbolic link"),
              std::string::npos)
        << error.what();
  }
  fs::remove(dir.path() / "out/video_frames/short");
  fs::remove(dir.path() / "out/video_frames");
  fs::create_directory_symlink(dir.path() / "elsewhere", dir.path() / "out/video_frames");
  EXPECT_THROW(IngestVideos({dir.path() / "short.mp4"}, dir.path() / "out", {}), InputError);
  EXPECT_EQ(ReadFileContents(dir.path() / "elsewhere/holiday.jpg"), "precious");
  EXPECT_EQ(
      std::distance(fs::directory_iterator(dir.path() / "elsewhere"), fs::directory_iterator()), 1);
}

TEST(VideoFrames, OptionsComeFromTheManifestsVideoObject) {
  const VideoFrameOptions options = VideoFrameOptions::FromJson(
      {{"min_frames", 5}, {"max_frames", 50}, {"target_frames", 20}, {"analysis_size", 320}});
  EXPECT_EQ(options.selection.min_frames, 5);
  EXPECT_EQ(options.selection.target_frames, 20);
  EXPECT_EQ(options.analysis_size, 320);
  try {
    VideoFrameOptions::FromJson({{"min_frame", 5}});
    ADD_FAILURE();
  } catch (const OptionError& error) {
    EXPECT_NE(std::string(error.what()).find("video.min_frame"), std::string::npos) << error.what();
  }
  EXPECT_THROW(VideoFrameOptions::FromJson({{"min_frames", 60}, {"max_frames", 50}}), OptionError);
}

// Check(), which ExtractVideoFrames calls, refuses what FromJson refuses, naming the
// struct and the field; the same list gives both their ranges.
TEST(VideoFrames, CheckNamesTheStructAndTheField) {
  EXPECT_NO_THROW(VideoFrameOptions().Check());
  VideoFrameOptions options;
  options.jpeg_quality = 0;
  try {
    options.Check();
    ADD_FAILURE() << "jpeg_quality = 0 passed";
  } catch (const InputError& error) {
    EXPECT_STREQ(error.what(), "VideoFrameOptions: jpeg_quality = 0 is out of range [1, 100]");
  }
  options = VideoFrameOptions();
  options.selection.keyframe_motion = 0;
  try {
    options.Check();
    ADD_FAILURE() << "keyframe_motion = 0 passed";
  } catch (const InputError& error) {
    EXPECT_STREQ(error.what(),
                 "KeyframeSelectionOptions: keyframe_motion = 0 is out of range [0.001, 10]");
  }
  EXPECT_THROW(VideoFrameOptions::FromJson({{"keyframe_motion", 0}}), OptionError);
}

}  // namespace
}  // namespace tessera
