#include "database/two_view_geometries_table.h"

#include <Eigen/LU>
#include <cmath>
#include <string>

#include "database/colmap_row_codecs.h"
#include "database/database.h"

namespace tessera {
namespace {

std::string GeometryOfImages(image_t image_id1, image_t image_id2) {
  return "the two-view geometry of images " + std::to_string(image_id1) + " and " +
         std::to_string(image_id2);
}

}  // namespace

TwoViewGeometry InvertTwoViewGeometry(const TwoViewGeometry& geometry) {
  TwoViewGeometry inverted;
  inverted.config = geometry.config;
  inverted.F = geometry.F.transpose();
  inverted.E = geometry.E.transpose();
  // COLMAP inverts H unconditionally; a zero H (no homography estimated) would become
  // infinities, so a singular one is kept as it is.
  const double det = geometry.H.determinant();
  inverted.H =
      (det != 0 && std::isfinite(det)) ? Eigen::Matrix3d(geometry.H.inverse()) : geometry.H;
  inverted.cam2_from_cam1 = geometry.cam2_from_cam1.Inverse();
  inverted.inlier_matches = SwapMatches(geometry.inlier_matches);
  return inverted;
}

bool TwoViewGeometriesTable::Exists(image_t image_id1, image_t image_id2) const {
  return exists_.QueryExists(static_cast<int64_t>(ImagePairToPairId(image_id1, image_id2)),
                             "look up " + GeometryOfImages(image_id1, image_id2));
}

void TwoViewGeometriesTable::Write(image_t image_id1, image_t image_id2,
                                   const TwoViewGeometry& geometry) const {
  const TwoViewGeometry stored =
      SwapImagePair(image_id1, image_id2) ? InvertTwoViewGeometry(geometry) : geometry;
  const TwoViewGeometryBlobs blobs(stored);
  SqliteStatement::Use use(write_, "write " + GeometryOfImages(image_id1, image_id2));
  use.BindInt64(1, static_cast<int64_t>(ImagePairToPairId(image_id1, image_id2)));
  use.BindInt64(2, static_cast<int64_t>(stored.inlier_matches.size()));
  use.BindInt64(3, 2);
  use.BindBlob(4, blobs.inlier_matches.data(), sizeof(point2D_t) * blobs.inlier_matches.size());
  use.BindInt64(5, stored.config);
  use.BindBlob(6, blobs.F.data(), sizeof(double) * 9);
  use.BindBlob(7, blobs.E.data(), sizeof(double) * 9);
  use.BindBlob(8, blobs.H.data(), sizeof(double) * 9);
  use.BindBlob(9, blobs.qvec, sizeof(blobs.qvec));
  use.BindBlob(10, blobs.tvec.data(), sizeof(double) * 3);
  use.Step();
}

TwoViewGeometry TwoViewGeometriesTable::Read(image_t image_id1, image_t image_id2) const {
  const std::string what = GeometryOfImages(image_id1, image_id2);
  SqliteStatement::Use use(read_, "read " + what);
  use.BindInt64(1, static_cast<int64_t>(ImagePairToPairId(image_id1, image_id2)));
  if (!use.Step()) return TwoViewGeometry();
  const TwoViewGeometry geometry = TwoViewGeometryFromRow(use, what);
  return SwapImagePair(image_id1, image_id2) ? InvertTwoViewGeometry(geometry) : geometry;
}

std::vector<std::pair<image_pair_t, TwoViewGeometry>> TwoViewGeometriesTable::ReadAll() const {
  SqliteStatement::Use use(read_all_, "read the two-view geometries");
  std::vector<std::pair<image_pair_t, TwoViewGeometry>> geometries;
  while (use.Step()) {
    const auto pair_id = static_cast<image_pair_t>(use.ColumnInt64(9));
    const auto [image_id1, image_id2] = PairIdToImagePair(pair_id);
    geometries.emplace_back(pair_id,
                            TwoViewGeometryFromRow(use, GeometryOfImages(image_id1, image_id2)));
  }
  return geometries;
}

size_t TwoViewGeometriesTable::NumVerifiedPairs() const {
  return static_cast<size_t>(num_verified_pairs_.QueryInt64("count the verified pairs"));
}

void TwoViewGeometriesTable::Delete(image_pair_t pair_id) const {
  const auto [image_id1, image_id2] = PairIdToImagePair(pair_id);
  SqliteStatement::Use use(delete_, "delete " + GeometryOfImages(image_id1, image_id2));
  use.BindInt64(1, static_cast<int64_t>(pair_id));
  use.Step();
}

}  // namespace tessera
