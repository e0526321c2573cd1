#include "tessera/sfm/track_selection.h"

#include <algorithm>
#include <map>
#include <numeric>

namespace tessera {

Track RestrictTrack(const Track& track, const std::set<image_t>& images) {
  Track restricted;
  for (const TrackElement& element : track) {
    if (images.count(element.image_id) > 0) restricted.push_back(element);
  }
  return restricted;
}

std::vector<size_t> SelectTracks(const std::vector<Track>& tracks, const std::set<image_t>& images,
                                 size_t min_length, size_t max_per_image) {
  std::vector<size_t> length(tracks.size(), 0);
  std::vector<size_t> candidates;
  for (size_t t = 0; t < tracks.size(); ++t) {
    for (const TrackElement& element : tracks[t]) length[t] += images.count(element.image_id);
    if (length[t] >= min_length) candidates.push_back(t);
  }
  std::stable_sort(candidates.begin(), candidates.end(),
                   [&](size_t a, size_t b) { return length[a] > length[b]; });
  std::map<image_t, size_t> num_taken;
  std::vector<size_t> selected;
  for (const size_t t : candidates) {
    bool needed = false;
    for (const TrackElement& element : tracks[t]) {
      if (images.count(element.image_id) > 0 && num_taken[element.image_id] < max_per_image) {
        needed = true;
      }
    }
    if (!needed) continue;
    selected.push_back(t);
    for (const TrackElement& element : tracks[t]) {
      if (images.count(element.image_id) > 0) ++num_taken[element.image_id];
    }
  }
  return selected;
}

}  // namespace tessera
