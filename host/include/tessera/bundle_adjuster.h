#pragma once

#include <set>
#include <string>

#include "tessera/ids.h"
#include "tessera/plugin.h"
#include "tessera/reconstruction.h"

namespace tessera {

// What a bundle adjustment may change.
struct BundleAdjustmentConfig {
  // Images whose observations enter the problem; empty means every registered image.
  std::set<image_t> images;
  // Images whose pose stays fixed (e.g. the neighbours' neighbours in local BA).
  std::set<image_t> constant_poses;
  // Points whose position stays fixed.
  std::set<point3D_t> constant_points;
  bool refine_focal_length = true;
  bool refine_principal_point = false;
  bool refine_extra_params = true;  // distortion
  // Fix the gauge: the first pose entirely and one translation coordinate of the
  // second, as COLMAP does, when no pose is constant otherwise.
  bool fix_gauge = true;
  // Iterations at most for this call (e.g. fewer for local BA); 0: the adjuster's own
  // setting.
  int max_num_iterations = 0;
  // Stop once an iteration lowers the cost by less than this fraction; negative: the
  // adjuster's own setting. Lets the mapper stop local adjustments, which only have
  // to be good enough for the next registration, earlier than global ones.
  double function_tolerance = -1;
};

struct BundleAdjustmentSummary {
  double initial_cost = 0;  // sum of squared (robustified) residuals, pixels^2
  double final_cost = 0;
  int num_iterations = 0;
  int num_residuals = 0;
  double seconds = 0;
  bool usable = false;
  std::string message;

  std::string BriefReport() const;
};

inline std::string BundleAdjustmentSummary::BriefReport() const {
  return std::string(usable ? "usable" : "NOT usable") + ", " + std::to_string(num_residuals) +
         " residuals, cost " + std::to_string(initial_cost) + " -> " + std::to_string(final_cost) +
         " in " + std::to_string(num_iterations) + " iterations, " + std::to_string(seconds) +
         " s" + (message.empty() ? "" : " (" + message + ")");
}

// Refines cameras, poses and points of a reconstruction by minimizing reprojection
// error.
class TESSERA_API BundleAdjuster : public Plugin {
 public:
  virtual BundleAdjustmentSummary Adjust(const BundleAdjustmentConfig& config,
                                         Reconstruction* reconstruction) const = 0;
};

}  // namespace tessera
