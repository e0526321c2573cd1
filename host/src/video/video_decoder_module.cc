// libtessera_video_decoder.so: the only code that uses OpenCV's videoio (see
// video_decoder.h). Its one entry point, tessera_open_video_decoder, is looked up by
// OpenVideoDecoder.

#include <opencv2/videoio.hpp>

#include "video/video_decoder.h"

namespace tessera {
namespace {

class OpenCvVideoDecoder : public VideoDecoder {
 public:
  explicit OpenCvVideoDecoder(cv::VideoCapture capture) : capture_(std::move(capture)) {}

  double FramesPerSecond() const override { return capture_.get(cv::CAP_PROP_FPS); }
  double PositionSeconds() const override { return capture_.get(cv::CAP_PROP_POS_MSEC) / 1000; }

  bool Read(cv::Mat* frame) override {
    try {
      return capture_.read(*frame) && !frame->empty();
    } catch (const cv::Exception&) {
      return false;
    }
  }
  bool Grab() override {
    try {
      return capture_.grab();
    } catch (const cv::Exception&) {
      return false;
    }
  }
  bool Retrieve(cv::Mat* frame) override {
    try {
      return capture_.retrieve(*frame) && !frame->empty();
    } catch (const cv::Exception&) {
      return false;
    }
  }

 private:
  cv::VideoCapture capture_;
};

}  // namespace
}  // namespace tessera

// nullptr when the backend cannot open the file.
extern "C" __attribute__((visibility("default"))) tessera::VideoDecoder* tessera_open_video_decoder(
    const char* path) {
  cv::VideoCapture capture;
  try {
    capture.open(path, cv::CAP_FFMPEG);
  } catch (const cv::Exception&) {
    return nullptr;
  }
  if (!capture.isOpened()) return nullptr;
  return new tessera::OpenCvVideoDecoder(std::move(capture));
}
