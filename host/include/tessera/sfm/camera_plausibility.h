#pragma once

// Checks of camera intrinsics that bundle adjustment refined: the values a
// degenerate configuration can push the solver to, which a real lens never has.

#include "tessera/camera.h"
#include "tessera/sfm/export.h"

namespace tessera {

// Whether the principal point lies within `max_offset_ratio` of the image width
// (horizontally) and height (vertically) of the image centre. A camera model without a
// principal point always passes.
TESSERA_SFM_EXPORT bool IsPrincipalPointPlausible(const Camera& camera, double max_offset_ratio);

// Puts the principal point back at the image centre.
TESSERA_SFM_EXPORT void ResetPrincipalPoint(Camera* camera);

}  // namespace tessera
