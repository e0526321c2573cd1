#pragma once

// The match matrix of a workspace: images by images, each cell the number of verified
// inlier matches of the pair (its two-view geometry), and one pair's inlier matches as
// keypoint positions, read from the workspace database.

#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "tessera/camera.h"
#include "tessera/ids.h"

namespace tessera::gui {

struct MatchMatrix {
  std::filesystem::path database;
  std::vector<image_t> image_ids;  // ascending
  std::vector<std::string> names;
  std::vector<int> inliers;  // row-major, size n*n, symmetric; 0 without a verified pair
  int max_inliers = 0;

  size_t size() const { return image_ids.size(); }
  int Inliers(size_t row, size_t column) const { return inliers[row * size() + column]; }
};

// `path`: a database.db or the workspace folder holding one. Throws InputError naming the
// file when there is none or it cannot be read.
MatchMatrix ReadMatchMatrix(const std::filesystem::path& path);

struct PairInliers {
  std::string name1, name2;
  // The images' cameras as the workspace records them (their photographs are checked
  // against their sizes); nothing when the database has none.
  std::optional<Camera> camera1, camera2;
  std::vector<Eigen::Vector2f> xy1, xy2;  // keypoint positions, one per inlier match
  // The putative matches (before geometric verification), likewise.
  std::vector<Eigen::Vector2f> putative_xy1, putative_xy2;
};

// The inlier and putative matches of the pair (image_id1, image_id2), in that order.
PairInliers ReadPairInliers(const std::filesystem::path& database, image_t image_id1,
                            image_t image_id2);

}  // namespace tessera::gui
