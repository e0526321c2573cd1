#pragma once

// The tracks that global positioning works on, as GLOMAP's track establishment chooses
// them: tracks of at least min_length images (of those given), the longest first, each
// taken while one of its images has fewer than max_per_image tracks taken. Long tracks
// constrain most and are least likely wrong; the limit keeps the problem small on images
// with many features while every image keeps its share.

#include <cstddef>
#include <set>
#include <vector>

#include "tessera/reconstruction.h"
#include "tessera/sfm/export.h"

namespace tessera {

// Indices into `tracks` of those chosen, in the order taken; elements in images outside
// `images` do not count (and the tracks are returned whole).
TESSERA_SFM_EXPORT std::vector<size_t> SelectTracks(const std::vector<Track>& tracks,
                                                    const std::set<image_t>& images,
                                                    size_t min_length, size_t max_per_image);

// The track with only its elements in `images`.
TESSERA_SFM_EXPORT Track RestrictTrack(const Track& track, const std::set<image_t>& images);

}  // namespace tessera
