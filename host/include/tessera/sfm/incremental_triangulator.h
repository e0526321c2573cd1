#pragma once

// Triangulation of the incremental mapper: new points from the feature tracks of a
// registered image, track completion (observations of registered images that a point
// explains), the merging of tracks that a refused match links, and retriangulation of
// the tracks without a point.

#include <cstddef>
#include <set>

#include "tessera/sfm/export.h"
#include "tessera/sfm/observation_manager.h"

namespace tessera {

struct IncrementalTriangulatorOptions {
  // Every observation of a point projects within this many pixels of its keypoint.
  double max_error = 4.0;
  // Degrees: the largest angle between two of a new point's rays is at least this.
  double min_angle = 1.5;
  // Pairs of observations tried when a track's observations disagree with their
  // all-view solution.
  size_t max_num_pairs = 200;

  // Throws InputError naming the first field out of its range (e.g.
  // "IncrementalTriangulatorOptions: max_error = 0 is out of range [0.001, 1000]"); the
  // triangulator's constructor calls it.
  TESSERA_SFM_EXPORT void Check() const;
};

class TESSERA_SFM_EXPORT IncrementalTriangulator {
 public:
  // `observations` must outlive the triangulator.
  IncrementalTriangulator(const IncrementalTriangulatorOptions& options,
                          ObservationManager* observations);

  // Each keypoint of a registered image without a 3D point: its track is triangulated
  // when it has no point, or the keypoint joins its track's point when consistent with
  // it. Returns the points created plus the observations added.
  size_t TriangulateImage(image_t image_id);
  // A point for a canonical track without one, from its features in registered images
  // that no point uses yet (one per image): the all-view solution when every feature
  // agrees with it, else the pair of features most others agree with; false when
  // fewer than two agree or the rays meet at too small an angle.
  bool TriangulateTrack(track_t track_id);
  // Adds to each of the points the consistent features of registered images in its
  // track; returns how many.
  size_t CompleteTracks(const std::set<point3D_t>& point3D_ids);
  // Joins the points of two tracks that a refused match links, where they share no
  // image and their weighted mean is consistent with every observation of both;
  // returns how many were joined.
  size_t MergeTracks();
  // Triangulates every canonical track without a point that two registered images
  // see; returns the points created.
  size_t Retriangulate();

 private:
  IncrementalTriangulatorOptions options_;
  ObservationManager& obs_;
};

}  // namespace tessera
