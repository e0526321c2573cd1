#pragma once

// One focal length per camera for every cluster. A camera without a focal prior (no
// EXIF) is calibrated once, on the whole view graph, before the cut, and every cluster
// maps with it: calibrated within a cluster, from its few pairs, it can be far off (fox
// in clusters of 30: one cluster of 19 images took 671 px against 1,376 px and its model
// came out folded, so its merge was refused), and clusters with different focal lengths
// do not fit one another in the merge. The calibration is the global mapper's: the view
// graph's estimate where the pairs determine it, a first model otherwise (cameras aimed
// at one point: tessera/sfm/focal_length_estimation.h, first_model_calibration.h).

#include <cstdint>
#include <vector>

#include "tessera/bundle_adjuster.h"
#include "tessera/mapper.h"
#include "tessera/sfm/focal_length_estimation.h"

namespace tessera {

// The focal length of each camera of `input` without a prior, and how it was found
// (FocalLengthReport::method "view graph" or "first model"). A camera that neither
// determines is left out: each cluster then calibrates it as a whole set would.
// `view_graph` sets which pairs the view graph's estimate takes.
std::vector<FocalLengthReport> CalibrateCamerasWithoutPrior(
    const MapperInput& input, const BundleAdjuster& adjuster, uint64_t seed,
    const FocalLengthEstimationOptions& view_graph = FocalLengthEstimationOptions());

// `input` with those focal lengths, held as priors: the mappers start from them and
// refine them in bundle adjustment, but do not estimate them again.
void ApplyCalibration(const std::vector<FocalLengthReport>& calibration, MapperInput* input);

}  // namespace tessera
