#include "video/video_decoder.h"

#include <dlfcn.h>

#include <mutex>
#include <string>

#include "tessera/errors.h"
#include "util/paths.h"

namespace tessera {
namespace {

using OpenFunction = VideoDecoder* (*)(const char*);

// The module's entry point, loaded once per process (and never unloaded: decoders made
// by it may live until the end).
OpenFunction LoadDecoderModule() {
  static std::once_flag once;
  static OpenFunction open = nullptr;
  static std::string problem;
  std::call_once(once, [] {
    const std::filesystem::path file =
        (ExecutableDir() / ".." / TESSERA_VIDEO_DECODER_FILE).lexically_normal();
    void* module = dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (module == nullptr) {
      const char* why = dlerror();
      problem = file.string() + ": cannot load the video decoder (" +
                (why != nullptr ? why : "unknown error") + ")";
      return;
    }
    open = reinterpret_cast<OpenFunction>(dlsym(module, "tessera_open_video_decoder"));
    if (open == nullptr) {
      problem = file.string() + ": not Tessera's video decoder (no tessera_open_video_decoder)";
    }
  });
  if (open == nullptr) throw InputError(problem);
  return open;
}

}  // namespace

std::unique_ptr<VideoDecoder> OpenVideoDecoder(const std::filesystem::path& video) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(video, error)) {
    throw InputError(video.string() + ": no such video file");
  }
  std::unique_ptr<VideoDecoder> decoder(LoadDecoderModule()(video.c_str()));
  if (decoder == nullptr) {
    throw InputError(video.string() +
                     ": cannot open the video (not a format OpenCV's FFmpeg backend decodes)");
  }
  return decoder;
}

}  // namespace tessera
