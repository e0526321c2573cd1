#pragma once

// Global positioning, after GLOMAP (Pan et al., ECCV 2024): camera centres and 3D
// points together from a random start, with the rotations held. Every observation of
// a track gives the unit ray d (world frame) from its camera's centre c towards the
// point X; its residual is d - s (X - c) with a free scale s >= 1e-5 of its own (BATA's
// formulation, Zhuang et al. CVPR 2018), under a Huber loss. The problem is convex in
// nothing but converges from a random start in practice, which saves the relative
// translations that the older pipelines average and the outliers they bring. Before the
// robust solve, one linear step from that start puts every point at unit depth along
// its rays (the scales held at 1, a squared loss): a long chain of cameras is then laid
// out at once, where the robust solver alone unfolded it a few cameras per iteration.
// Gauge: the first camera's centre (lowest id) is held at the origin; the scale of the
// solution is free, so it is normalised afterwards (median camera-to-point distance 1).

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <map>
#include <vector>

#include "tessera/camera.h"
#include "tessera/reconstruction.h"
#include "tessera/sfm/export.h"

namespace tessera {

struct GlobalPositioningOptions {
  int max_num_iterations = 100;
  double huber_threshold = 0.1;  // on the ray residual (unit ray)
  // Relative cost change to stop at: the cost flattens within a few tens of iterations, then
  // only creeps along the free scale (all positions shrinking, all scales growing).
  double function_tolerance = 1e-5;
  double init_extent = 100;  // random positions uniform in [-extent, extent]^3
  uint64_t seed = 0;
  int num_threads = 1;
  // Levenberg-Marquardt may accept steps that raise the cost for a while (Ceres'
  // non-monotonic steps). From a random start on a long chain of cameras the monotone
  // solver creeps: on the benchmark's path of 1000 images it took 78 iterations, this
  // 14, to a minimum no worse.
  bool use_nonmonotonic_steps = true;

  // Throws InputError naming the first field out of its range (e.g. "GlobalPositioningOptions:
  // huber_threshold = 0 is out of range [0.0001, 10]"); PositionGlobally calls it.
  TESSERA_SFM_EXPORT void Check() const;
};

struct GlobalPositioningResult {
  std::map<image_t, Eigen::Vector3d> centers;  // of every image with an observation
  std::vector<Eigen::Vector3d> points;         // one per track
  int num_iterations = 0;
  double initial_cost = 0, final_cost = 0;
  bool usable = false;
  bool cancelled = false;  // should_stop aborted the solver
};

// Positions the images of `R_cam_from_world` and the points of `tracks` (their
// elements in images without a rotation are ignored; a track then left with fewer than
// two is placed nowhere useful and should not be passed). Keypoints are those of
// `images`, made rays with `cameras`. `should_stop` is polled at each solver iteration.
TESSERA_SFM_EXPORT GlobalPositioningResult PositionGlobally(
    const std::map<camera_t, Camera>& cameras, const std::map<image_t, Image>& images,
    const std::map<image_t, Eigen::Matrix3d>& R_cam_from_world, const std::vector<Track>& tracks,
    const GlobalPositioningOptions& options, const std::function<bool()>& should_stop = {});

}  // namespace tessera
