#pragma once

// Geometric verification of putative matches between two images, after COLMAP's
// EstimateCalibratedTwoViewGeometry / EstimateUncalibratedTwoViewGeometry.

#include <cstdint>

#include "geometry/verification_settings.h"
#include "tessera/camera.h"
#include "tessera/features.h"
#include "tessera/two_view_geometry.h"

namespace tessera {

// Verifies putative matches between two images. E (calibrated) when both cameras have a trusted
// focal length (camera.has_prior_focal_length), F otherwise; a homography test flags planar or
// panoramic pairs; fewer than settings.min_num_inliers inliers -> config DEGENERATE and no inliers.
// Deterministic for a given seed.
//
// Calibrated pairs: E, F and H are estimated with LO-RANSAC (E on normalised points,
// with the pixel threshold converted by each camera and averaged). The pair is
// CALIBRATED when E keeps at least 95% of F's inliers; PLANAR or PANORAMIC when H
// explains more than max_H_inlier_ratio of them (PANORAMIC when H, in normalised
// coordinates, is a rotation). cam2_from_cam1 comes from E (from H's rotation for
// PANORAMIC pairs), with unit translation.
// Uncalibrated pairs: F and H only; UNCALIBRATED or PLANAR_OR_PANORAMIC, no pose.
// Each estimation gives up early, as soon as a model with min_num_inliers inliers
// would have been found with the settings' confidence had it existed
// (RANSACOptions::min_num_inliers); the homography does so only when neither E nor F
// holds. A pair whose models reach min_num_inliers before that point is verified
// exactly as without it; non-overlapping pairs cost a fraction of max_num_trials when
// they have few matches (about 60 or fewer at 15 inliers and 0.999 confidence).
// Throws InputError when a match refers to a keypoint that does not exist.
TwoViewGeometry EstimateTwoViewGeometry(const Camera& camera1, const FeatureKeypoints& keypoints1,
                                        const Camera& camera2, const FeatureKeypoints& keypoints2,
                                        const FeatureMatches& matches,
                                        const VerificationSettings& settings, uint64_t seed);

}  // namespace tessera
