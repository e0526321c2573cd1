#include "database/colmap_row_codecs.h"

#include <Eigen/Geometry>
#include <cstring>
#include <optional>

#include "database/database.h"
#include "io/names.h"
#include "tessera/errors.h"

namespace tessera {
namespace {

Eigen::Matrix3d ColumnMatrix3d(const SqliteStatement::Use& row, int column,
                               const std::string& what) {
  if (row.ColumnBytes(column) == 0) return Eigen::Matrix3d::Zero();
  TwoViewGeometryBlobs::Matrix3dRowMajor matrix;
  std::memcpy(matrix.data(), row.ColumnBlob(column, sizeof(double) * 9, what), sizeof(double) * 9);
  return matrix;
}

}  // namespace

Camera CameraFromRow(const SqliteStatement::Use& row) {
  Camera camera;
  camera.camera_id = static_cast<camera_t>(row.ColumnInt64(0));
  const std::string what = "camera " + std::to_string(camera.camera_id);
  const int64_t model = row.ColumnInt64(1);
  if (!ExistsCameraModelWithId(static_cast<int>(model))) {
    // The list comes from the model registry, so that it names every model there is.
    std::string known;
    for (const CameraModelId id : AllCameraModelIds()) {
      known += (known.empty() ? "" : ", ") + std::to_string(static_cast<int>(id)) + " " +
               CameraModelIdToName(id);
    }
    throw InputError("Database '" + row.path().string() + "': " + what + " has camera model id " +
                     std::to_string(model) + ", which Tessera does not support (it knows " + known +
                     ").");
  }
  camera.model_id = static_cast<CameraModelId>(model);
  camera.width = static_cast<size_t>(row.ColumnInt64(2));
  camera.height = static_cast<size_t>(row.ColumnInt64(3));
  const size_t num_params = static_cast<size_t>(CameraModelNumParams(camera.model_id));
  camera.params.resize(num_params);
  std::memcpy(
      camera.params.data(),
      row.ColumnBlob(4, sizeof(double) * num_params, what + " (" + camera.ModelName() + ") params"),
      sizeof(double) * num_params);
  camera.has_prior_focal_length = row.ColumnInt64(5) != 0;
  if (row.ColumnIsNull(6)) {
    camera.calibration_source = CalibrationSource::kDatabase;
  } else {
    const std::string name = row.ColumnText(6);
    const auto source = CalibrationSourceFromName(name);
    if (!source) {
      throw InputError("Database '" + row.path().string() + "': " + what +
                       " has an unknown calibration source '" + name + "'.");
    }
    camera.calibration_source = *source;
  }
  return camera;
}

Image ImageFromRow(const SqliteStatement::Use& row) {
  Image image;
  image.image_id = static_cast<image_t>(row.ColumnInt64(0));
  const char* name = row.ColumnText(1);
  if (name == nullptr) {
    throw InputError("Database '" + row.path().string() + "': image " +
                     std::to_string(image.image_id) + " has no name.");
  }
  // Every byte, so that a NUL inside the name is refused, not cut off.
  image.name.assign(name, row.ColumnBytes(1));
  CheckImageName(image.name,
                 "Database '" + row.path().string() + "': image " + std::to_string(image.image_id));
  image.camera_id = static_cast<camera_t>(row.ColumnInt64(2));
  return image;
}

std::vector<float> KeypointsToBlob(const FeatureKeypoints& keypoints) {
  std::vector<float> blob;
  blob.reserve(6 * keypoints.size());
  for (const FeatureKeypoint& keypoint : keypoints) {
    blob.insert(blob.end(),
                {keypoint.x, keypoint.y, keypoint.a11, keypoint.a12, keypoint.a21, keypoint.a22});
  }
  return blob;
}

FeatureKeypoints KeypointsFromRow(const SqliteStatement::Use& row, const std::string& what) {
  const int64_t rows = row.ColumnInt64(0);
  const int64_t cols = row.ColumnInt64(1);
  if (rows < 0 || (rows > 0 && cols != 2 && cols != 4 && cols != 6)) {
    throw InputError("Database '" + row.path().string() + "': " + what + " have " +
                     std::to_string(cols) + " columns, expected 2, 4 or 6.");
  }
  if (rows == 0) return {};
  row.CheckColumnArray(2, rows, cols, sizeof(float), what);
  FeatureKeypoints keypoints(static_cast<size_t>(rows));
  std::vector<float> blob(static_cast<size_t>(rows * cols));
  std::memcpy(blob.data(), row.ColumnBlob(2, sizeof(float) * blob.size(), what),
              sizeof(float) * blob.size());
  for (size_t i = 0; i < keypoints.size(); ++i) {
    const float* values = blob.data() + i * static_cast<size_t>(cols);
    if (cols == 2) {
      keypoints[i] = FeatureKeypoint(values[0], values[1]);
    } else if (cols == 4) {
      keypoints[i] = FeatureKeypoint(values[0], values[1], values[2], values[3]);
    } else {
      FeatureKeypoint& keypoint = keypoints[i];
      keypoint.x = values[0];
      keypoint.y = values[1];
      keypoint.a11 = values[2];
      keypoint.a12 = values[3];
      keypoint.a21 = values[4];
      keypoint.a22 = values[5];
    }
  }
  return keypoints;
}

FeatureDescriptors DescriptorsFromRow(const SqliteStatement::Use& row, const std::string& what,
                                      DescriptorMetric metric, int64_t expected_cols) {
  FeatureDescriptors descriptors;
  descriptors.metric = metric;
  const int64_t rows = row.ColumnInt64(0);
  const int64_t cols = row.ColumnInt64(1);
  if (rows < 0 || cols < 0) {
    throw InputError("Database '" + row.path().string() + "': " + what + " have " +
                     std::to_string(rows) + " rows and " + std::to_string(cols) + " columns.");
  }
  if (expected_cols >= 0 && rows > 0 && cols != expected_cols) {
    throw InputError("Database '" + row.path().string() + "': " + what + " are " +
                     std::to_string(cols) + " bytes wide, expected " +
                     std::to_string(expected_cols) +
                     " (features of another detector); run `tessera extract` again.");
  }
  if (rows > 0 && cols > 0) row.CheckColumnArray(2, rows, cols, 1, what);
  descriptors.data.resize(rows, cols);
  if (descriptors.data.size() > 0) {
    std::memcpy(descriptors.data.data(),
                row.ColumnBlob(2, static_cast<size_t>(descriptors.data.size()), what),
                static_cast<size_t>(descriptors.data.size()));
  }
  return descriptors;
}

std::vector<point2D_t> MatchesToBlob(const FeatureMatches& matches, bool swap) {
  std::vector<point2D_t> blob;
  blob.reserve(2 * matches.size());
  for (const FeatureMatch& match : matches) {
    if (swap) {
      blob.insert(blob.end(), {match.point2D_idx2, match.point2D_idx1});
    } else {
      blob.insert(blob.end(), {match.point2D_idx1, match.point2D_idx2});
    }
  }
  return blob;
}

FeatureMatches SwapMatches(const FeatureMatches& matches) {
  FeatureMatches swapped;
  swapped.reserve(matches.size());
  for (const FeatureMatch& match : matches) {
    swapped.push_back({match.point2D_idx2, match.point2D_idx1});
  }
  return swapped;
}

FeatureMatches MatchesFromColumns(const SqliteStatement::Use& row, int first_column,
                                  const std::string& what) {
  const int64_t rows = row.ColumnInt64(first_column);
  const int64_t cols = row.ColumnInt64(first_column + 1);
  if (rows < 0 || (rows > 0 && cols != 2)) {
    throw InputError("Database '" + row.path().string() + "': " + what + " has " +
                     std::to_string(rows) + " rows of " + std::to_string(cols) +
                     " columns, expected rows of 2 columns.");
  }
  if (rows == 0) return {};
  row.CheckColumnArray(first_column + 2, rows, 2, sizeof(point2D_t), what);
  FeatureMatches matches(static_cast<size_t>(rows));
  const auto* data = static_cast<const point2D_t*>(
      row.ColumnBlob(first_column + 2, sizeof(point2D_t) * 2 * static_cast<size_t>(rows), what));
  for (size_t i = 0; i < matches.size(); ++i) {
    std::memcpy(&matches[i].point2D_idx1, data + 2 * i, sizeof(point2D_t));
    std::memcpy(&matches[i].point2D_idx2, data + 2 * i + 1, sizeof(point2D_t));
  }
  return matches;
}

TwoViewGeometryBlobs::TwoViewGeometryBlobs(const TwoViewGeometry& geometry)
    : inlier_matches(MatchesToBlob(geometry.inlier_matches, false)),
      F(geometry.F),
      E(geometry.E),
      H(geometry.H),
      qvec{geometry.cam2_from_cam1.rotation.w(), geometry.cam2_from_cam1.rotation.x(),
           geometry.cam2_from_cam1.rotation.y(), geometry.cam2_from_cam1.rotation.z()},
      tvec(geometry.cam2_from_cam1.translation) {}

TwoViewGeometry TwoViewGeometryFromRow(const SqliteStatement::Use& row, const std::string& what) {
  TwoViewGeometry geometry;
  geometry.inlier_matches = MatchesFromColumns(row, 0, what + " inlier matches");
  geometry.config = static_cast<int>(row.ColumnInt64(3));
  geometry.F = ColumnMatrix3d(row, 4, what + " F");
  geometry.E = ColumnMatrix3d(row, 5, what + " E");
  geometry.H = ColumnMatrix3d(row, 6, what + " H");
  if (row.ColumnBytes(7) > 0) {
    double qvec[4];
    std::memcpy(qvec, row.ColumnBlob(7, sizeof(qvec), what + " qvec"), sizeof(qvec));
    // COLMAP leaves qvec at zero when it has no relative pose; that is identity here.
    if (qvec[0] != 0 || qvec[1] != 0 || qvec[2] != 0 || qvec[3] != 0) {
      geometry.cam2_from_cam1.rotation = Eigen::Quaterniond(qvec[0], qvec[1], qvec[2], qvec[3]);
    }
  }
  if (row.ColumnBytes(8) > 0) {
    std::memcpy(geometry.cam2_from_cam1.translation.data(),
                row.ColumnBlob(8, sizeof(double) * 3, what + " tvec"), sizeof(double) * 3);
  }
  return geometry;
}

}  // namespace tessera
