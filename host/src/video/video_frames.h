#pragma once

// Video input: decode videos (OpenCV videoio, FFmpeg), score and select keyframes
// (keyframe_selection.h), write them as images for the pipeline.

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "video/keyframe_selection.h"

namespace tessera {

struct VideoFrameOptions {
  KeyframeSelectionOptions selection;
  int analysis_size = 480;  // longer side of the images that are scored, in pixels
  int jpeg_quality = 95;    // of the written frames

  nlohmann::json ToJson() const;
  // The manifest's "video" object; throws OptionError naming `video.KEY`.
  static VideoFrameOptions FromJson(const nlohmann::json& json);
  // Throws InputError naming the first field out of its range (selection's included);
  // ExtractVideoFrames calls it.
  void Check() const;
};

// Its own fields, after selection's (VisitKeyframeSelectionOptions), with their ranges
// and help: FromJson and Check() read the same list.
template <typename Options, typename Visit>
void VisitVideoFrameOptions(Options& o, const Visit& visit) {
  visit("analysis_size", o.analysis_size, 64, 8192,
        "px: longer side of the copies whose sharpness and motion are scored");
  visit("jpeg_quality", o.jpeg_quality, 1, 100, "JPEG quality of the kept frames");
}

// What one video gave.
struct VideoFrames {
  std::filesystem::path video;
  std::string folder;  // below the frames folder: the video's file stem
  std::vector<FrameScore> frames;
  KeyframeSelection selection;
  std::vector<std::string> images;  // per selected frame, its name below the frames folder
  double fps = 0;
  int width = 0, height = 0;
  double decode_seconds = 0;  // reading and decoding every frame, both passes
  double select_seconds = 0;  // scoring (sharpness, optical flow) and selection
  bool reused = false;        // taken from an earlier run's frames.json
  std::string content_hash;   // XXH3-128 of the video file, as images' (IngestVideos)
};

// The file name of frame `index` at `time_s`: frame_000123_4.100s.jpg (the 0-based frame
// index is the first number, so the natural order is the video's).
std::string VideoFrameName(int index, double time_s);

// Decodes `video` once to score every frame (sharpness of the analysis image, median
// DIS optical flow from the previous frame), selects keyframes, then decodes it again
// and writes the selected frames to `frames_dir / folder` (created; other .jpg files
// there removed). Throws InputError naming the file when it cannot be opened or has no
// decodable frame.
VideoFrames ExtractVideoFrames(const std::filesystem::path& video, const std::string& folder,
                               const std::filesystem::path& frames_dir,
                               const VideoFrameOptions& options);

// Every video of a run into OUTPUT/video_frames/<stem>/, with OUTPUT/frames.json: per
// video its file, size, options and every frame's index, time, sharpness, motion,
// segment and whether it was kept (with its image name). A video whose file, size,
// content hash (as images are keyed: a file replaced by another of the same size and
// modification time is decoded again) and options equal those recorded in frames.json,
// and whose frames are all still there, is not decoded again. Returns the frames folder.
std::filesystem::path IngestVideos(const std::vector<std::filesystem::path>& videos,
                                   const std::filesystem::path& output_dir,
                                   const VideoFrameOptions& options,
                                   std::vector<VideoFrames>* results = nullptr);

}  // namespace tessera
