#pragma once

// A model anchored to its images' GPS: moved into a local east-north-up frame in metres
// by the similarity that most geotagged camera centres agree on, then bundle-adjusted
// with each centre held to its GPS position (BundleAdjustmentConfig::position_priors),
// as COLMAP's pose-prior mapper does. A model too few geotagged images define, or
// whose GPS contradicts it, stays as it was, with the reason.
//
// Tags no camera can have taken are set aside first, each with its reason: not finite or
// out of range, 0, 0 ("null island": a camera without a fix writes it), an altitude
// outside [min_altitude_m, max_altitude_m], or a position far from the rest (farther
// from the median of the tags than far_tag_mads robust deviations, and than
// far_tag_floor_m). The frame's origin is the median latitude, longitude and altitude of
// the tags the similarity agrees with, so that coordinates stay local (a float PLY keeps
// its precision) whatever the tags set aside or disagreeing.
#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "tessera/bundle_adjuster.h"
#include "tessera/georeference.h"
#include "tessera/image_metadata.h"
#include "tessera/reconstruction.h"
#include "tessera/sfm/export.h"

namespace tessera {

struct GpsAnchoringOptions {
  // Standard deviations of the GPS positions, metres.
  double horizontal_sigma_m = 5.0;
  double vertical_sigma_m = 10.0;
  // Geotagged registered images a model needs, not all on one line.
  int min_num_images = 3;
  // A geotagged centre agrees with the similarity within this many sigmas.
  double max_error_sigmas = 5.0;
  // Share of the geotagged images that must agree; else the GPS contradicts the model.
  // Real GPS has a few outliers, not a quarter of the images off.
  double min_inlier_ratio = 0.75;
  int ransac_num_trials = 200;
  int ba_max_num_iterations = 50;
  // Altitudes a camera reaches, metres: from below the Dead Sea's shore (-430 m) to above
  // an airliner's cruise; a tag outside is set aside.
  double min_altitude_m = -500;
  double max_altitude_m = 12000;
  // A tag farther from the median tag than max(far_tag_floor_m, median distance +
  // far_tag_mads * the distances' median absolute deviation, scaled as a standard
  // deviation) is set aside (with 3 tags or more).
  double far_tag_mads = 10;
  double far_tag_floor_m = 3000;

  // Throws InputError naming the first field out of its range (e.g. "GpsAnchoringOptions:
  // horizontal_sigma_m = 0 is out of range [0.001, 1e+06]"); AnchorModelToGps calls it.
  TESSERA_SFM_EXPORT void Check() const;
};

// A tag set aside before anchoring, and why.
struct GpsTagSetAside {
  image_t image_id = kInvalidImageId;
  GpsPosition position;
  std::string reason;  // e.g. "0, 0 (null island: a camera without a fix writes it)"
};

struct GpsAnchoringReport {
  bool anchored = false;
  std::string reason;  // why not, when not
  Georeference origin;
  size_t num_geotagged = 0;  // registered images of the model with GPS
  // Tags set aside before anchoring (see above), in image id order.
  std::vector<GpsTagSetAside> set_aside;
  size_t num_agreeing = 0;  // of the others, within max_error_sigmas of the similarity
  // Distances of the centres to their GPS positions after anchoring (the tags not set
  // aside), metres.
  double mean_error_m = 0;
  double median_error_m = 0;
};

// East, north, up of `position` (WGS84) in metres from `origin` (altitude 0 where the
// position has none).
TESSERA_SFM_EXPORT Eigen::Vector3d EnuFromWgs84(const GpsPosition& position,
                                                const Georeference& origin);
// The inverse: the WGS84 position (with altitude) of an east-north-up point.
TESSERA_SFM_EXPORT GpsPosition Wgs84FromEnu(const Eigen::Vector3d& enu, const Georeference& origin);

// Anchors `model` to the GPS in `metadata` (see above). The origin is the median position
// of the tags the similarity agrees with. Every random choice comes from `seed`. The
// model is changed only when the report says anchored.
TESSERA_SFM_EXPORT GpsAnchoringReport AnchorModelToGps(
    const std::map<image_t, ImageMetadata>& metadata, const BundleAdjuster& bundle_adjuster,
    const GpsAnchoringOptions& options, uint64_t seed, Reconstruction* model);

}  // namespace tessera
