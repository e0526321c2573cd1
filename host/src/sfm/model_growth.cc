#include "sfm/model_growth.h"

#include "sfm/rig_poses.h"

namespace tessera {

void Grow(IncrementalMapper* mapper, RunControl* control, size_t max_images) {
  bool refined_since_failure = false;
  while (mapper->NumRegisteredImages() < max_images) {
    if (control->ShouldStop()) return;
    image_t next_image = kInvalidImageId;
    for (const image_t candidate : mapper->NextImages()) {
      if (mapper->RegisterImage(candidate) == IncrementalMapper::Status::kSuccess) {
        next_image = candidate;
        break;
      }
    }
    if (next_image == kInvalidImageId) {
      // A global refinement may add the points a failed image needed; once, and only
      // when the model changed since the last one.
      if (refined_since_failure || !mapper->ChangedSinceGlobalBundleAdjustment()) break;
      mapper->GlobalRefinement();
      refined_since_failure = true;
      continue;
    }
    refined_since_failure = false;
    mapper->TriangulateImage(next_image);
    // The rest of its frame, in the pose the rig gives it, once the rig's poses are known.
    if (control->rigs != nullptr) {
      for (const image_t mate : FrameMates(*control->rigs, next_image)) {
        if (mapper->observations().IsRegistered(mate) ||
            !RigPoseOfImage(*control->rigs, mapper->model(), mate)) {
          continue;
        }
        if (mapper->RegisterImage(mate) == IncrementalMapper::Status::kSuccess) {
          mapper->TriangulateImage(mate);
        }
      }
    }
    if (control->observer != nullptr && control->observer->on_model_changed) {
      control->observer->on_model_changed(control->model_index, mapper->model());
    }
    if (control->observer != nullptr && control->observer->on_progress) {
      control->observer->on_progress("registration", mapper->NumRegisteredImages(),
                                     control->num_images);
    }
    mapper->LocalBundleAdjustment(next_image);
    if (mapper->GlobalRefinementDue()) mapper->GlobalRefinement();
  }
}

}  // namespace tessera
