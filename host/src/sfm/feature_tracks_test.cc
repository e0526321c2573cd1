#include "tessera/sfm/feature_tracks.h"

#include <gtest/gtest.h>

#include "tessera/errors.h"

namespace tessera {
namespace {

ImagePairMatches Pair(image_t image_id1, image_t image_id2, FeatureMatches matches) {
  return {image_id1, image_id2, std::move(matches)};
}

TEST(FeatureTracks, ChainsOfMatchesBecomeOneTrackPerPoint) {
  // Feature 0 of images 1, 2, 3 is one point seen through two pairs; feature 1 of 1
  // and 2 another.
  const FeatureTracks tracks = BuildFeatureTracks(
      {Pair(1, 2, {{0, 0}, {1, 1}}), Pair(2, 3, {{0, 0}})}, {{1, 2}, {2, 2}, {3, 1}});
  ASSERT_EQ(tracks.tracks.size(), 2u);
  EXPECT_EQ(tracks.tracks[0].size(), 3u);
  EXPECT_EQ(tracks.tracks[1].size(), 2u);
  EXPECT_EQ(tracks.TrackOf(1, 0), tracks.TrackOf(3, 0));
  EXPECT_NE(tracks.TrackOf(1, 0), tracks.TrackOf(1, 1));
  EXPECT_EQ(tracks.num_refused_matches, 0u);
  EXPECT_EQ(tracks.TrackOf(3, 5), kInvalidTrackId);
}

TEST(FeatureTracks, AMatchJoiningTwoFeaturesOfOneImageIsRefusedAndKeptAsALink) {
  // 1:0-2:0 and 2:0-3:0 make a track; 3:0-1:1 would add a second feature of image 1.
  // The strongest pair is joined first, so which match is refused does not depend on
  // the input order.
  const std::vector<ImagePairMatches> pairs = {Pair(1, 2, {{0, 0}, {2, 2}, {3, 3}}),
                                               Pair(2, 3, {{0, 0}, {2, 2}}), Pair(1, 3, {{1, 0}})};
  const std::map<image_t, size_t> sizes = {{1, 4}, {2, 4}, {3, 4}};
  const FeatureTracks tracks = BuildFeatureTracks(pairs, sizes);
  EXPECT_EQ(tracks.num_refused_matches, 1u);
  const track_t main_track = tracks.TrackOf(1, 0);
  EXPECT_EQ(tracks.tracks[main_track].size(), 3u);
  EXPECT_EQ(tracks.TrackOf(1, 1), kInvalidTrackId);  // alone: no track, so no link
  for (const Track& track : tracks.tracks) {
    std::set<image_t> images;
    for (const TrackElement& element : track) {
      EXPECT_TRUE(images.insert(element.image_id).second) << "two features of one image";
    }
  }
  const std::vector<ImagePairMatches> reversed(pairs.rbegin(), pairs.rend());
  const FeatureTracks same = BuildFeatureTracks(reversed, sizes);
  ASSERT_EQ(same.tracks.size(), tracks.tracks.size());
  for (size_t t = 0; t < tracks.tracks.size(); ++t) {
    ASSERT_EQ(same.tracks[t].size(), tracks.tracks[t].size());
    for (size_t e = 0; e < tracks.tracks[t].size(); ++e) {
      EXPECT_EQ(same.tracks[t][e].image_id, tracks.tracks[t][e].image_id);
      EXPECT_EQ(same.tracks[t][e].point2D_idx, tracks.tracks[t][e].point2D_idx);
    }
  }
}

TEST(FeatureTracks, RefusedMatchBetweenTwoTracksLinksThem) {
  // Tracks {1:0, 2:0} and {1:1, 3:0}; 2:0-3:0 would join both, putting 1:0 and 1:1 together.
  const FeatureTracks tracks = BuildFeatureTracks(
      {Pair(1, 2, {{0, 0}, {5, 5}}), Pair(1, 3, {{1, 0}, {5, 5}}), Pair(2, 3, {{0, 0}})},
      {{1, 6}, {2, 6}, {3, 6}});
  EXPECT_EQ(tracks.num_refused_matches, 1u);
  ASSERT_EQ(tracks.refused_links.size(), 1u);
  const auto [a, b] = tracks.refused_links[0];
  EXPECT_EQ(std::set<track_t>({a, b}),
            std::set<track_t>({tracks.TrackOf(1, 0), tracks.TrackOf(1, 1)}));

  FeatureTracks merged = tracks;
  merged.Merge(a, b);
  EXPECT_EQ(merged.tracks[a].size(), 4u);
  EXPECT_TRUE(merged.tracks[b].empty());
  EXPECT_EQ(merged.TrackOf(1, 1), a);
  EXPECT_EQ(merged.TrackOf(3, 0), a);
}

TEST(FeatureTracks, MatchPastTheKeypointsThrowsNamingThePair) {
  try {
    BuildFeatureTracks({Pair(4, 7, {{0, 9}})}, {{4, 1}, {7, 2}});
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_STREQ(error.what(),
                 "matches of images 4 and 7 refer to keypoint 9 of image 7, which does not exist");
  }
}

}  // namespace
}  // namespace tessera
