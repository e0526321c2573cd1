#pragma once

// A video's frames, decoded by OpenCV's FFmpeg backend (videoio).
//
// videoio brings about a hundred shared libraries (FFmpeg, GStreamer, libdc1394, ...)
// whose loading cost every `tessera` process 85 ms of its 190 ms start-up, videos or
// not: half of what a Slurm shard of three images spent before its first image. So
// the decoder is a module of its own, `libtessera_video_decoder.so` (next to the
// plugins' folder, <exe>/../lib/tessera/), loaded on the first video opened.

#include <filesystem>
#include <memory>
#include <opencv2/core.hpp>

namespace tessera {

class VideoDecoder {
 public:
  virtual ~VideoDecoder() = default;
  // Frames per second as the container states it (0, or nonsense, when it does not).
  virtual double FramesPerSecond() const = 0;
  // The time of the frame read last, in seconds, from the container.
  virtual double PositionSeconds() const = 0;
  // Decodes the next frame into `frame`; false at the end or on a decoding error.
  virtual bool Read(cv::Mat* frame) = 0;
  // Moves to the next frame without converting it to an image; false at the end.
  virtual bool Grab() = 0;
  // Converts the frame Grab moved to; false on a decoding error.
  virtual bool Retrieve(cv::Mat* frame) = 0;
};

// Opens `video`. Throws InputError naming the file when it does not exist or is not a
// format the FFmpeg backend decodes, and naming the module when it cannot be loaded.
std::unique_ptr<VideoDecoder> OpenVideoDecoder(const std::filesystem::path& video);

}  // namespace tessera
