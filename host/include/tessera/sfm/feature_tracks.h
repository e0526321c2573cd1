#pragma once

// Feature tracks: the features of all images that see one physical point, joined by
// union-find over every verified match. A track holds at most one feature per image
// (it becomes one 3D point), so a match that would put two features of one image in
// one track is refused; it is kept as a link between the two tracks, which the mapper
// may merge once both are triangulated and agree.

#include <cstdint>
#include <map>
#include <utility>
#include <vector>

#include "tessera/features.h"
#include "tessera/ids.h"
#include "tessera/reconstruction.h"
#include "tessera/sfm/export.h"

namespace tessera {

using track_t = uint32_t;
constexpr track_t kInvalidTrackId = static_cast<track_t>(-1);

// The verified inlier matches of one image pair.
struct ImagePairMatches {
  image_t image_id1 = kInvalidImageId;
  image_t image_id2 = kInvalidImageId;
  FeatureMatches matches;  // point2D_idx1 in image_id1, point2D_idx2 in image_id2
};

struct TESSERA_SFM_EXPORT FeatureTracks {
  // Each with at least two elements from distinct images, elements sorted by image.
  std::vector<Track> tracks;
  // Pairs of tracks (first < second) joined by a refused match, sorted, without repeats.
  std::vector<std::pair<track_t, track_t>> refused_links;
  // Matches refused because they joined two features of one image.
  size_t num_refused_matches = 0;

  // The track of a feature, kInvalidTrackId if it is in none.
  track_t TrackOf(image_t image_id, point2D_t point2D_idx) const;
  // Moves every element of track `from` into track `into` (which may then hold two
  // features of an image; the mapper never observes one image twice per point).
  void Merge(track_t into, track_t from);

  // One entry per image with a feature in a track: the track of each feature.
  std::map<image_t, std::vector<track_t>> track_of_feature;
};

// Builds tracks from the matches of all pairs. `num_points2D` gives the number of
// features of each image; a match past it throws InputError naming the pair. Pairs
// are joined strongest first (most matches, then by image ids), so the result does not
// depend on the input order.
TESSERA_SFM_EXPORT FeatureTracks BuildFeatureTracks(const std::vector<ImagePairMatches>& pairs,
                                                    const std::map<image_t, size_t>& num_points2D);

}  // namespace tessera
