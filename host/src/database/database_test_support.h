#pragma once

// What the tests of the database folder share: a raw SQLite view of the file, random
// features, a synthetic pair with known geometry and the fixture with its usual setup.

#include <gtest/gtest.h>
#include <sqlite3.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "database/database.h"
#include "test_support.h"

namespace tessera {

namespace fs = std::filesystem;

// The six tables COLMAP 3.8 reads, and its index on image names.
inline const std::vector<std::string> kColmapSchemaObjects = {
    "cameras",     "images",  "index_name",         "keypoints",
    "descriptors", "matches", "two_view_geometries"};

inline fs::path AnchorDatabase() {
  return testing::SharedDir() / "anchors" / "colmap-3.8" / "fountain-P11" / "database.db";
}

inline bool ColmapAvailable() { return std::system("colmap help > /dev/null 2>&1") == 0; }

// Raw access for checking what is stored byte by byte, independently of Database.
class RawDatabase {
 public:
  explicit RawDatabase(const fs::path& path) {
    EXPECT_EQ(sqlite3_open_v2(path.c_str(), &db_, SQLITE_OPEN_READWRITE, nullptr), SQLITE_OK);
  }
  ~RawDatabase() { sqlite3_close_v2(db_); }

  // The columns of the first row of `sql`, as text (blobs as their bytes).
  std::vector<std::string> Row(const std::string& sql) const {
    sqlite3_stmt* stmt = nullptr;
    EXPECT_EQ(sqlite3_prepare_v2(db_, sql.c_str(), -1, &stmt, nullptr), SQLITE_OK) << sql;
    std::vector<std::string> row;
    if (sqlite3_step(stmt) == SQLITE_ROW) {
      for (int i = 0; i < sqlite3_column_count(stmt); ++i) {
        const auto* data = static_cast<const char*>(sqlite3_column_blob(stmt, i));
        row.emplace_back(data != nullptr ? std::string(data, sqlite3_column_bytes(stmt, i))
                                         : std::string("<NULL>"));
      }
    }
    sqlite3_finalize(stmt);
    return row;
  }

  void Exec(const std::string& sql) const {
    EXPECT_EQ(sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, nullptr), SQLITE_OK)
        << sql << ": " << sqlite3_errmsg(db_);
  }

  void WriteBlobRow(const std::string& sql, const void* data, size_t num_bytes) const {
    sqlite3_stmt* stmt = nullptr;
    ASSERT_EQ(sqlite3_prepare_v2(db_, sql.c_str(), -1, &stmt, nullptr), SQLITE_OK) << sql;
    sqlite3_bind_blob(stmt, 1, data, static_cast<int>(num_bytes), SQLITE_TRANSIENT);
    EXPECT_EQ(sqlite3_step(stmt), SQLITE_DONE) << sqlite3_errmsg(db_);
    sqlite3_finalize(stmt);
  }

  // sqlite_master.sql of each named object.
  std::map<std::string, std::string> Schema() const {
    std::map<std::string, std::string> schema;
    for (const std::string& name : kColmapSchemaObjects) {
      const auto row = Row("SELECT sql FROM sqlite_master WHERE name = '" + name + "';");
      schema[name] = row.empty() ? "<missing>" : row[0];
    }
    return schema;
  }

 private:
  sqlite3* db_ = nullptr;
};

template <typename T>
std::vector<T> BlobAs(const std::string& bytes) {
  std::vector<T> values(bytes.size() / sizeof(T));
  std::memcpy(values.data(), bytes.data(), values.size() * sizeof(T));
  return values;
}

inline FeatureKeypoints RandomKeypoints(size_t n, std::mt19937* rng) {
  std::uniform_real_distribution<float> coordinate(0, 1000), shape(-3, 3);
  FeatureKeypoints keypoints(n);
  for (FeatureKeypoint& keypoint : keypoints) {
    keypoint.x = coordinate(*rng);
    keypoint.y = coordinate(*rng);
    keypoint.a11 = shape(*rng);
    keypoint.a12 = shape(*rng);
    keypoint.a21 = shape(*rng);
    keypoint.a22 = shape(*rng);
  }
  return keypoints;
}

inline FeatureMatches RandomMatches(size_t n, std::mt19937* rng) {
  std::uniform_int_distribution<point2D_t> index(0, 5000);
  FeatureMatches matches(n);
  for (FeatureMatch& match : matches) match = {index(*rng), index(*rng)};
  return matches;
}

inline bool SameKeypoints(const FeatureKeypoints& a, const FeatureKeypoints& b) {
  return a.size() == b.size() &&
         std::equal(a.begin(), a.end(), b.begin(), [](const auto& p, const auto& q) {
           return std::memcmp(&p, &q, sizeof(FeatureKeypoint)) == 0;
         });
}

inline Eigen::Matrix3d CrossMatrix(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

// A calibrated pair with known truth: points on the plane z = 5 in camera 1.
struct SyntheticPair {
  Eigen::Matrix3d K;
  Rigid3d cam2_from_cam1;
  TwoViewGeometry geometry;
  std::vector<Eigen::Vector3d> points_in_cam1;

  SyntheticPair() {
    K << 800, 0, 320, 0, 820, 240, 0, 0, 1;
    cam2_from_cam1.rotation =
        Eigen::Quaterniond(Eigen::AngleAxisd(0.2, Eigen::Vector3d(0.3, 1, -0.2).normalized()));
    cam2_from_cam1.translation = Eigen::Vector3d(-1, 0.2, 0.1).normalized();
    const Eigen::Matrix3d R = cam2_from_cam1.rotation.toRotationMatrix();
    const Eigen::Vector3d& t = cam2_from_cam1.translation;
    geometry.config = TwoViewGeometry::CALIBRATED;
    geometry.E = CrossMatrix(t) * R;
    geometry.F = K.inverse().transpose() * geometry.E * K.inverse();
    const Eigen::Vector3d plane_normal(0, 0, 1);
    const double plane_distance = 5;
    geometry.H = K * (R + t * plane_normal.transpose() / plane_distance) * K.inverse();
    geometry.cam2_from_cam1 = cam2_from_cam1;
    geometry.inlier_matches = {{0, 10}, {1, 11}, {2, 12}, {7, 3}};
    for (int i = 0; i < 10; ++i) {
      points_in_cam1.emplace_back(-2 + 0.4 * i, 1.5 - 0.3 * i, plane_distance);
    }
  }

  Eigen::Vector3d Pixel1(const Eigen::Vector3d& point) const { return K * point / point.z(); }
  Eigen::Vector3d Pixel2(const Eigen::Vector3d& point) const {
    const Eigen::Vector3d in_cam2 = cam2_from_cam1 * point;
    return K * in_cam2 / in_cam2.z();
  }
};

class DatabaseTest : public ::testing::Test {
 protected:
  fs::path DatabasePath() const { return dir_.path() / "database.db"; }

  // Two cameras, three images: the setup of most tests.
  void AddCamerasAndImages(Database* database) {
    database->WriteCamera(Camera::Create(kInvalidCameraId, CameraModelId::kPinhole, 500, 640, 480));
    database->WriteCamera(
        Camera::Create(kInvalidCameraId, CameraModelId::kSimpleRadial, 700, 800, 600));
    for (const auto& [name, camera_id] :
         std::vector<std::pair<std::string, camera_t>>{{"a.jpg", 1}, {"b.jpg", 1}, {"c.jpg", 2}}) {
      Image image;
      image.name = name;
      image.camera_id = camera_id;
      database->WriteImage(image);
    }
  }

  testing::TemporaryDir dir_;
};
}  // namespace tessera
