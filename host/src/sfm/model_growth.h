#pragma once

// Growing one model image by image (host-internal to Tessera::sfm): the loop that both
// the incremental pipeline and the first models of first_model_calibration.h run.

#include <cstddef>
#include <limits>
#include <vector>

#include "tessera/camera_rig.h"
#include "tessera/mapper.h"
#include "tessera/sfm/incremental_mapper.h"

namespace tessera {

// The caller's observer (null: none, as in the calibration pass), the index of the
// model being grown, and whether the observer asked to stop.
struct RunControl {
  const MapperControl* observer = nullptr;
  size_t model_index = 0;
  size_t num_images = 0;  // of the input, for progress
  // The input's camera rigs: a registered image's frame follows it (null: none).
  const std::vector<CameraRig>* rigs = nullptr;
  bool cancelled = false;

  // Asks the observer; once true, stays true.
  bool ShouldStop() {
    if (!cancelled && observer != nullptr && observer->should_stop)
      cancelled = observer->should_stop();
    return cancelled;
  }
};

// Registers images while any registers, or until the model has `max_images`: each one
// triangulated, its frame mates registered in the pose the rig gives them, then local
// bundle adjustment and, when due, global refinement. Stops when `control` says so.
void Grow(IncrementalMapper* mapper, RunControl* control,
          size_t max_images = std::numeric_limits<size_t>::max());

}  // namespace tessera
