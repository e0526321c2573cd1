#include "tessera/sfm/track_selection.h"

#include <gtest/gtest.h>

namespace tessera {
namespace {

Track MakeTrack(const std::vector<image_t>& image_ids) {
  Track track;
  for (const image_t image_id : image_ids) track.push_back({image_id, 0});
  return track;
}

TEST(TrackSelection, LongestFirstWhileAnImageNeedsMore) {
  const std::vector<Track> tracks = {MakeTrack({1, 2}),    MakeTrack({1, 2, 3, 4}),
                                     MakeTrack({1, 2, 3}), MakeTrack({3, 4}),
                                     MakeTrack({5, 6}),    MakeTrack({1})};
  const std::set<image_t> images = {1, 2, 3, 4, 5, 6};
  // One per image: the 4-track covers 1-4; then only {5, 6} is needed.
  EXPECT_EQ(SelectTracks(tracks, images, 2, 1), (std::vector<size_t>{1, 4}));
  // Two per image: 4-track, 3-track (1-3 need a second), {3, 4} is not needed by 3 but by
  // 4, {5, 6}; {1, 2} is not needed.
  EXPECT_EQ(SelectTracks(tracks, images, 2, 2), (std::vector<size_t>{1, 2, 3, 4}));
  // At least three images.
  EXPECT_EQ(SelectTracks(tracks, images, 3, 100), (std::vector<size_t>{1, 2}));
}

TEST(TrackSelection, OnlyTheGivenImagesCount) {
  const std::vector<Track> tracks = {MakeTrack({1, 2, 7, 8}), MakeTrack({1, 2, 3})};
  const std::set<image_t> images = {1, 2, 3};
  EXPECT_EQ(SelectTracks(tracks, images, 2, 100), (std::vector<size_t>{1, 0}));
  EXPECT_EQ(RestrictTrack(tracks[0], images).size(), 2u);
}

}  // namespace
}  // namespace tessera
