#pragma once

// The colour at every keypoint of the images to be mapped, sampled on a thread of its own
// while the mapper runs: the mappers leave a core idle (Ceres and global positioning run
// on one thread), and colouring the models afterwards then decodes none of those images
// again. On Herz-Jesus-P8 (8 images of 3072x2048) that decoding was 0.32 s of the global
// mapper's 1.2 s map stage. Compiled into libtessera_io, but host only, like names.h: this
// header is not part of the SDK, and no plugin may include it.

#include <Eigen/Core>
#include <atomic>
#include <cstddef>
#include <filesystem>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "tessera/io/export.h"
#include "tessera/reconstruction.h"

namespace tessera {

class TESSERA_IO_EXPORT KeypointColorSampler {
 public:
  // Starts sampling, in image id order, each image of `images` read from `image_dir` by its
  // name, with the bilinear colour at each of its keypoints (as ColorPointsFromImages
  // samples them), while the samples fit in `max_bytes`. An image that cannot be read, or
  // whose size is not its camera's in `cameras`, is skipped. `images` and `cameras` must
  // outlive the sampler.
  KeypointColorSampler(std::filesystem::path image_dir, const std::map<image_t, Image>& images,
                       const std::map<camera_t, Camera>& cameras, size_t max_bytes);
  ~KeypointColorSampler();  // Stop()
  KeypointColorSampler(const KeypointColorSampler&) = delete;
  KeypointColorSampler& operator=(const KeypointColorSampler&) = delete;

  // Lets the image being sampled finish, samples no other, and waits for the thread.
  void Stop();
  // Waits until every image is sampled or the budget is reached.
  void Wait();

  // After Stop or Wait: the colour (RGB, 0 to 255) at each keypoint of `image`, or nullptr when it
  // was not sampled (not reached before Stop, over the budget, unreadable, or not its
  // camera's size) or its keypoints are not those sampled (same number and positions).
  const std::vector<Eigen::Vector3d>* Samples(const Image& image) const;
  size_t num_sampled() const { return samples_.size(); }  // after Stop or Wait

 private:
  void Run();

  const std::filesystem::path image_dir_;
  const std::map<image_t, Image>& images_;
  const std::map<camera_t, Camera>& cameras_;
  const size_t max_bytes_;
  std::map<image_t, std::vector<Eigen::Vector3d>> samples_;  // the thread's until Stop
  std::atomic<bool> stop_{false};
  std::thread thread_;  // last: it starts once the members above are set
};

// ColorPointsFromImages, with the samples of `sampler` (stopped; may be null) for the
// images it has them for, when their keypoints are those of the model's image: the same
// colours and warnings, without decoding those images again.
TESSERA_IO_EXPORT std::vector<std::string> ColorPointsFromImages(
    const std::filesystem::path& image_dir, Reconstruction* reconstruction, int num_threads,
    const KeypointColorSampler* sampler);

}  // namespace tessera
