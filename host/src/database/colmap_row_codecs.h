#pragma once

// How COLMAP's tables store Tessera's types: the blobs written, and the rows read back
// with every size checked against the blob before anything is allocated. A row that
// does not decode is an InputError naming the file and the row (`what`).

#include <Eigen/Core>
#include <string>
#include <vector>

#include "database/sqlite_statement.h"
#include "tessera/camera.h"
#include "tessera/features.h"
#include "tessera/ids.h"
#include "tessera/reconstruction.h"
#include "tessera/two_view_geometry.h"

namespace tessera {

// cameras (joined with tessera_camera_priors): camera_id, model, width, height, params,
// prior_focal_length, source. A NULL source (a camera COLMAP wrote) is kDatabase.
Camera CameraFromRow(const SqliteStatement::Use& row);

// images: image_id, name, camera_id.
Image ImageFromRow(const SqliteStatement::Use& row);

// keypoints: float32 rows x 6 (x y a11 a12 a21 a22); read with 2, 4 or 6 columns from
// the columns rows, cols, data.
std::vector<float> KeypointsToBlob(const FeatureKeypoints& keypoints);
FeatureKeypoints KeypointsFromRow(const SqliteStatement::Use& row, const std::string& what);

// descriptors: uint8 rows x cols from the columns rows, cols, data. `expected_cols` >= 0:
// a non-empty row of another width is refused.
FeatureDescriptors DescriptorsFromRow(const SqliteStatement::Use& row, const std::string& what,
                                      DescriptorMetric metric, int64_t expected_cols);

// matches (and the inliers of two_view_geometries): uint32 rows x 2, the columns
// swapped when `swap`; read from the columns rows, cols, data from `first_column` on.
std::vector<point2D_t> MatchesToBlob(const FeatureMatches& matches, bool swap);
FeatureMatches SwapMatches(const FeatureMatches& matches);
FeatureMatches MatchesFromColumns(const SqliteStatement::Use& row, int first_column,
                                  const std::string& what);

// two_view_geometries' blobs as COLMAP stores them: the inliers as matches, F, E, H
// float64 3x3 row by row, qvec w x y z, tvec x y z. Bound without a copy, so the
// blobs must outlive the statement's step.
struct TwoViewGeometryBlobs {
  explicit TwoViewGeometryBlobs(const TwoViewGeometry& geometry);
  using Matrix3dRowMajor = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;
  std::vector<point2D_t> inlier_matches;
  Matrix3dRowMajor F, E, H;
  double qvec[4];
  Eigen::Vector3d tvec;
};
// From the columns rows, cols, data, config, F, E, H, qvec, tvec. COLMAP's zero qvec
// ("no relative pose") reads as identity; empty F, E, H read as zero.
TwoViewGeometry TwoViewGeometryFromRow(const SqliteStatement::Use& row, const std::string& what);

}  // namespace tessera
