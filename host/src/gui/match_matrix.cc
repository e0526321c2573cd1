#include "gui/match_matrix.h"

#include <algorithm>

#include "database/database.h"
#include "tessera/errors.h"
#include "util/workspace_layout.h"

namespace tessera::gui {
namespace fs = std::filesystem;
namespace {

fs::path DatabaseFile(const fs::path& path) {
  std::error_code error;
  const fs::path file = fs::is_directory(path, error) ? path / workspace_layout::kDatabase : path;
  if (!fs::is_regular_file(file, error)) {
    throw InputError(file.string() + ": no workspace database (run the pipeline first)");
  }
  return file;
}

}  // namespace

MatchMatrix ReadMatchMatrix(const fs::path& path) {
  MatchMatrix matrix;
  matrix.database = DatabaseFile(path);
  const Database database(matrix.database, Database::Mode::kReadOnly);
  std::vector<Image> images = database.ReadAllImages();
  std::sort(images.begin(), images.end(),
            [](const Image& a, const Image& b) { return a.image_id < b.image_id; });
  for (const Image& image : images) {
    matrix.image_ids.push_back(image.image_id);
    matrix.names.push_back(image.name);
  }
  const size_t n = matrix.size();
  matrix.inliers.assign(n * n, 0);
  auto index_of = [&](image_t image_id) {
    const auto found = std::lower_bound(matrix.image_ids.begin(), matrix.image_ids.end(), image_id);
    return found != matrix.image_ids.end() && *found == image_id
               ? static_cast<size_t>(found - matrix.image_ids.begin())
               : n;
  };
  for (const auto& [pair_id, geometry] : database.ReadAllTwoViewGeometries()) {
    const auto [image_id1, image_id2] = PairIdToImagePair(pair_id);
    const size_t row = index_of(image_id1);
    const size_t column = index_of(image_id2);
    if (row == n || column == n) continue;
    const int count = static_cast<int>(geometry.inlier_matches.size());
    matrix.inliers[row * n + column] = count;
    matrix.inliers[column * n + row] = count;
    matrix.max_inliers = std::max(matrix.max_inliers, count);
  }
  return matrix;
}

PairInliers ReadPairInliers(const fs::path& path, image_t image_id1, image_t image_id2) {
  const Database database(DatabaseFile(path), Database::Mode::kReadOnly);
  PairInliers pair;
  for (const Image& image : database.ReadAllImages()) {
    if (image.image_id == image_id1) {
      pair.name1 = image.name;
      pair.camera1 = database.ReadCamera(image.camera_id);
    }
    if (image.image_id == image_id2) {
      pair.name2 = image.name;
      pair.camera2 = database.ReadCamera(image.camera_id);
    }
  }
  if (!database.ExistsTwoViewGeometry(image_id1, image_id2)) return pair;
  const TwoViewGeometry geometry = database.ReadTwoViewGeometry(image_id1, image_id2);
  const FeatureKeypoints keypoints1 = database.ReadKeypoints(image_id1);
  const FeatureKeypoints keypoints2 = database.ReadKeypoints(image_id2);
  if (database.ExistsMatches(image_id1, image_id2)) {
    for (const FeatureMatch& match : database.ReadMatches(image_id1, image_id2)) {
      if (match.point2D_idx1 >= keypoints1.size() || match.point2D_idx2 >= keypoints2.size()) {
        continue;
      }
      pair.putative_xy1.emplace_back(keypoints1[match.point2D_idx1].x,
                                     keypoints1[match.point2D_idx1].y);
      pair.putative_xy2.emplace_back(keypoints2[match.point2D_idx2].x,
                                     keypoints2[match.point2D_idx2].y);
    }
  }
  for (const FeatureMatch& match : geometry.inlier_matches) {
    if (match.point2D_idx1 >= keypoints1.size() || match.point2D_idx2 >= keypoints2.size()) {
      continue;
    }
    pair.xy1.emplace_back(keypoints1[match.point2D_idx1].x, keypoints1[match.point2D_idx1].y);
    pair.xy2.emplace_back(keypoints2[match.point2D_idx2].x, keypoints2[match.point2D_idx2].y);
  }
  return pair;
}

}  // namespace tessera::gui
