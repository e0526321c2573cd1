#pragma once

// The first half of GPS anchoring (tessera/sfm/gps_anchoring.h), public so that a model
// can be aligned to its GPS after the fact (`tessera align --gps`) with the mappers' own
// outlier handling: impossible and far tags set aside, the similarity most geotagged
// centres agree on (LO-RANSAC over triples), the frame's origin at the median of the
// agreeing tags. AnchorModelToGps calls it, then adjusts with the GPS priors.

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <vector>

#include "tessera/image_metadata.h"
#include "tessera/reconstruction.h"
#include "tessera/sfm/export.h"
#include "tessera/sfm/gps_anchoring.h"

namespace tessera {

struct GpsSimilarity {
  // anchored: a similarity was found (the model itself is not moved); else reason says
  // why not. origin, num_geotagged, set_aside and num_agreeing as AnchorModelToGps reports
  // them; mean_error_m and median_error_m: the moved centres' distances to their tags
  // (those not set aside), before any adjustment.
  GpsAnchoringReport report;
  // enu_from_model: x_enu = scale * rotation * x_model + translation.
  double scale = 1;
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  // The geotagged images not set aside, in image id order, with their tags in the
  // origin's frame; `agreeing` marks those within the threshold of the similarity.
  std::vector<image_t> images;
  std::vector<Eigen::Vector3d> enu;
  std::vector<bool> agreeing;
  double threshold_m = 0;  // max_error_sigmas times the larger sigma
};

// The similarity from the model's frame to east-north-up metres about the median of
// the tags it agrees with. Every random choice comes from `seed`.
TESSERA_SFM_EXPORT GpsSimilarity EstimateGpsSimilarity(
    const std::map<image_t, ImageMetadata>& metadata, const GpsAnchoringOptions& options,
    uint64_t seed, const Reconstruction& model);

}  // namespace tessera
