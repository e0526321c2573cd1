#include "database/database.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sqlite3.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <random>
#include <thread>

#include "tessera/errors.h"
#include "test_support.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

// The six tables COLMAP 3.8 reads, and its index on image names.
const std::vector<std::string> kColmapSchemaObjects = {
    "cameras",     "images",  "index_name",         "keypoints",
    "descriptors", "matches", "two_view_geometries"};

fs::path AnchorDatabase() {
  return testing::SharedDir() / "anchors" / "colmap-3.8" / "fountain-P11" / "database.db";
}

bool ColmapAvailable() { return std::system("colmap help > /dev/null 2>&1") == 0; }

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

FeatureKeypoints RandomKeypoints(size_t n, std::mt19937* rng) {
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

FeatureMatches RandomMatches(size_t n, std::mt19937* rng) {
  std::uniform_int_distribution<point2D_t> index(0, 5000);
  FeatureMatches matches(n);
  for (FeatureMatch& match : matches) match = {index(*rng), index(*rng)};
  return matches;
}

bool SameKeypoints(const FeatureKeypoints& a, const FeatureKeypoints& b) {
  return a.size() == b.size() &&
         std::equal(a.begin(), a.end(), b.begin(), [](const auto& p, const auto& q) {
           return std::memcmp(&p, &q, sizeof(FeatureKeypoint)) == 0;
         });
}

Eigen::Matrix3d CrossMatrix(const Eigen::Vector3d& v) {
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

TEST_F(DatabaseTest, CamerasOfAllModelsRoundTrip) {
  std::vector<Camera> written;
  {
    Database database(DatabasePath());
    const std::vector<CalibrationSource> sources = {
        CalibrationSource::kDefault, CalibrationSource::kExifFocalLength,
        CalibrationSource::kExif35mmEquivalent, CalibrationSource::kUser,
        CalibrationSource::kDatabase};
    for (size_t i = 0; i < AllCameraModelIds().size(); ++i) {
      Camera camera = Camera::Create(kInvalidCameraId, AllCameraModelIds()[i], 1000 + 0.125 * i,
                                     4000 + i, 3000 - i);
      for (size_t p = 0; p < camera.params.size(); ++p) camera.params[p] += 1e-7 * (p + 1);
      camera.has_prior_focal_length = i % 2 == 1;
      camera.calibration_source = sources[i % sources.size()];
      camera.camera_id = database.WriteCamera(camera);
      EXPECT_EQ(camera.camera_id, i + 1);
      written.push_back(camera);
    }
    Camera explicit_id = written[0];
    explicit_id.camera_id = 42;
    EXPECT_EQ(database.WriteCamera(explicit_id, /*use_camera_id=*/true), 42u);
    written.push_back(explicit_id);
    EXPECT_EQ(database.NumCameras(), AllCameraModelIds().size() + 1);
  }

  Database database(DatabasePath());  // reopened: what is read comes from the file
  const std::vector<Camera> cameras = database.ReadAllCameras();
  ASSERT_EQ(cameras.size(), written.size());
  for (size_t i = 0; i < cameras.size(); ++i) {
    SCOPED_TRACE(written[i].ModelName());
    EXPECT_EQ(cameras[i].camera_id, written[i].camera_id);
    EXPECT_EQ(cameras[i].model_id, written[i].model_id);
    EXPECT_EQ(cameras[i].width, written[i].width);
    EXPECT_EQ(cameras[i].height, written[i].height);
    EXPECT_EQ(cameras[i].params, written[i].params);  // bit-exact doubles
    EXPECT_EQ(cameras[i].has_prior_focal_length, written[i].has_prior_focal_length);
    EXPECT_EQ(cameras[i].calibration_source, written[i].calibration_source);
  }

  // COLMAP's layout: model as its integer id, params as float64, prior as 0/1.
  RawDatabase raw(DatabasePath());
  const auto row = raw.Row(
      "SELECT model, width, params, prior_focal_length FROM cameras "
      "WHERE camera_id = 5;");
  ASSERT_EQ(row.size(), 4u);
  EXPECT_EQ(row[0], "4");  // OPENCV
  EXPECT_EQ(row[1], "4004");
  EXPECT_EQ(BlobAs<double>(row[2]), written[4].params);
  EXPECT_EQ(row[3], "0");

  Camera updated = cameras[1];
  updated.params[0] = 1234.5;
  updated.calibration_source = CalibrationSource::kUser;
  database.UpdateCamera(updated);
  EXPECT_EQ(database.ReadCamera(2)->params[0], 1234.5);
  EXPECT_EQ(database.ReadCamera(2)->calibration_source, CalibrationSource::kUser);
  EXPECT_FALSE(database.ReadCamera(41).has_value());
  updated.camera_id = 41;
  EXPECT_THROW(database.UpdateCamera(updated), std::runtime_error);

  database.WriteCalibrationSource(3, CalibrationSource::kDefault);
  EXPECT_EQ(database.ReadCamera(3)->calibration_source, CalibrationSource::kDefault);
  // A camera written by COLMAP has no prior row: it came from a database.
  raw.Exec("DELETE FROM tessera_camera_priors WHERE camera_id = 3;");
  EXPECT_EQ(database.ReadCamera(3)->calibration_source, CalibrationSource::kDatabase);
}

TEST_F(DatabaseTest, UnknownCameraModelIsAnInputError) {
  { Database database(DatabasePath()); }
  RawDatabase raw(DatabasePath());
  const double params[4] = {1, 2, 3, 4};
  raw.WriteBlobRow(
      "INSERT INTO cameras(model, width, height, params, prior_focal_length) "
      "VALUES(10, 100, 100, ?, 0);",  // COLMAP's THIN_PRISM_FISHEYE
      params, sizeof(params));
  Database database(DatabasePath());
  try {
    database.ReadAllCameras();
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("camera 1 has camera model id 10"), std::string::npos)
        << error.what();
  }
}

TEST_F(DatabaseTest, ImagesRoundTrip) {
  Database database(DatabasePath());
  AddCamerasAndImages(&database);
  Image explicit_id;
  explicit_id.image_id = 17;
  explicit_id.name = "sub/d.jpg";
  explicit_id.camera_id = 2;
  EXPECT_EQ(database.WriteImage(explicit_id, /*use_image_id=*/true), 17u);
  Image next;
  next.name = "e.jpg";
  next.camera_id = 1;
  EXPECT_EQ(database.WriteImage(next), 18u);  // AUTOINCREMENT continues after the largest
  EXPECT_EQ(database.NumImages(), 5u);

  const std::vector<Image> images = database.ReadAllImages();
  ASSERT_EQ(images.size(), 5u);
  const std::vector<std::pair<image_t, std::string>> expected = {
      {1, "a.jpg"}, {2, "b.jpg"}, {3, "c.jpg"}, {17, "sub/d.jpg"}, {18, "e.jpg"}};
  for (size_t i = 0; i < images.size(); ++i) {
    EXPECT_EQ(images[i].image_id, expected[i].first);
    EXPECT_EQ(images[i].name, expected[i].second);
    EXPECT_TRUE(images[i].points2D.empty());
  }
  EXPECT_EQ(images[2].camera_id, 2u);
  const auto d = database.ReadImageWithName("sub/d.jpg");
  ASSERT_TRUE(d.has_value());
  EXPECT_EQ(d->image_id, 17u);
  EXPECT_EQ(d->camera_id, 2u);
  EXPECT_FALSE(database.ReadImageWithName("missing.jpg").has_value());

  // Pose priors NULL, as COLMAP 3.8 leaves them without priors.
  RawDatabase raw(DatabasePath());
  EXPECT_EQ(raw.Row("SELECT prior_qw, prior_tz FROM images WHERE image_id = 1;"),
            (std::vector<std::string>{"<NULL>", "<NULL>"}));

  try {
    database.WriteImage(next);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find(DatabasePath().string()), std::string::npos) << message;
    EXPECT_NE(message.find("write image 'e.jpg'"), std::string::npos) << message;
    EXPECT_NE(message.find("UNIQUE constraint failed: images.name"), std::string::npos) << message;
  }
  // The foreign key on cameras holds, as in COLMAP.
  Image orphan;
  orphan.name = "orphan.jpg";
  orphan.camera_id = 99;
  EXPECT_THROW(database.WriteImage(orphan), std::runtime_error);
}

TEST_F(DatabaseTest, KeypointsAndDescriptorsRoundTrip) {
  std::mt19937 rng(7);
  const FeatureKeypoints keypoints = RandomKeypoints(300, &rng);
  FeatureDescriptors descriptors;
  descriptors.data = FeatureDescriptors::Matrix::Random(300, 128);
  {
    Database database(DatabasePath());
    AddCamerasAndImages(&database);
    EXPECT_FALSE(database.ExistsKeypoints(1));
    database.WriteKeypoints(1, RandomKeypoints(5, &rng));
    database.WriteKeypoints(1, keypoints);  // replaces
    database.WriteDescriptors(1, descriptors);
    database.WriteKeypoints(2, {});
    FeatureDescriptors empty;
    empty.data.resize(0, 128);
    database.WriteDescriptors(2, empty);
  }
  Database database(DatabasePath());
  EXPECT_TRUE(database.ExistsKeypoints(1));
  EXPECT_TRUE(database.ExistsKeypoints(2));
  EXPECT_FALSE(database.ExistsKeypoints(3));
  EXPECT_TRUE(database.ExistsDescriptors(1));
  EXPECT_FALSE(database.ExistsDescriptors(3));
  EXPECT_TRUE(SameKeypoints(database.ReadKeypoints(1), keypoints));
  EXPECT_TRUE(database.ReadKeypoints(2).empty());
  EXPECT_TRUE(database.ReadKeypoints(3).empty());
  EXPECT_EQ(database.NumKeypoints(), 300u);

  const FeatureDescriptors read = database.ReadDescriptors(1, DescriptorMetric::kHamming);
  EXPECT_EQ(read.metric, DescriptorMetric::kHamming);
  EXPECT_EQ(read.data, descriptors.data);
  EXPECT_EQ(database.ReadDescriptors(2, DescriptorMetric::kL2).data.rows(), 0);

  // COLMAP's layout: 6 float32 columns row by row, uint8 descriptors row by row.
  RawDatabase raw(DatabasePath());
  const auto row = raw.Row("SELECT rows, cols, data FROM keypoints WHERE image_id = 1;");
  ASSERT_EQ(row.size(), 3u);
  EXPECT_EQ(row[0], "300");
  EXPECT_EQ(row[1], "6");
  const std::vector<float> floats = BlobAs<float>(row[2]);
  ASSERT_EQ(floats.size(), 1800u);
  EXPECT_EQ(floats[6 * 299 + 0], keypoints[299].x);
  EXPECT_EQ(floats[6 * 299 + 3], keypoints[299].a12);
  const auto descriptor_row = raw.Row("SELECT rows, cols, data FROM descriptors WHERE image_id=1;");
  EXPECT_EQ(descriptor_row[1], "128");
  EXPECT_EQ(static_cast<uint8_t>(descriptor_row[2][128 + 5]), descriptors.data(1, 5));
}

TEST_F(DatabaseTest, KeypointsWithTwoOrFourColumnsAreRead) {
  { Database database(DatabasePath()); }
  {
    Database database(DatabasePath());
    AddCamerasAndImages(&database);
  }
  RawDatabase raw(DatabasePath());
  const float two[4] = {1.5f, 2.5f, 3.5f, 4.5f};
  raw.WriteBlobRow("INSERT INTO keypoints VALUES(1, 2, 2, ?);", two, sizeof(two));
  const float four[4] = {10, 20, 2, 0.5f};  // x y scale orientation
  raw.WriteBlobRow("INSERT INTO keypoints VALUES(2, 1, 4, ?);", four, sizeof(four));
  const float three[3] = {1, 2, 3};
  raw.WriteBlobRow("INSERT INTO keypoints VALUES(3, 1, 3, ?);", three, sizeof(three));

  Database database(DatabasePath());
  const FeatureKeypoints from_two = database.ReadKeypoints(1);
  ASSERT_EQ(from_two.size(), 2u);
  EXPECT_EQ(from_two[1].x, 3.5f);
  EXPECT_EQ(from_two[1].y, 4.5f);
  EXPECT_EQ(from_two[1].a11, 1.0f);
  EXPECT_EQ(from_two[1].a12, 0.0f);
  const FeatureKeypoints from_four = database.ReadKeypoints(2);
  ASSERT_EQ(from_four.size(), 1u);
  EXPECT_NEAR(from_four[0].ComputeScale(), 2.0, 1e-6);
  EXPECT_NEAR(from_four[0].ComputeOrientation(), 0.5, 1e-6);
  EXPECT_NEAR(from_four[0].a21, 2 * std::sin(0.5), 1e-6);
  EXPECT_THROW(database.ReadKeypoints(3), InputError);
}

TEST_F(DatabaseTest, MatchesInEitherOrder) {
  std::mt19937 rng(3);
  const FeatureMatches matches = RandomMatches(200, &rng);
  Database database(DatabasePath());
  AddCamerasAndImages(&database);
  database.WriteMatches(3, 1, matches);  // stored swapped under pair (1, 3)
  database.WriteMatches(1, 2, {});       // matched, nothing found
  EXPECT_TRUE(database.ExistsMatches(1, 3));
  EXPECT_TRUE(database.ExistsMatches(3, 1));
  EXPECT_TRUE(database.ExistsMatches(2, 1));
  EXPECT_FALSE(database.ExistsMatches(2, 3));
  EXPECT_EQ(database.NumMatchedPairs(), 2u);
  EXPECT_EQ(database.ReadMatchedPairIds(),
            (std::vector<image_pair_t>{ImagePairToPairId(1, 2), ImagePairToPairId(1, 3)}));
  EXPECT_EQ(ImagePairToPairId(1, 3), 2147483650u);

  EXPECT_EQ(database.ReadMatches(3, 1), matches);
  const FeatureMatches forward = database.ReadMatches(1, 3);
  ASSERT_EQ(forward.size(), matches.size());
  for (size_t i = 0; i < matches.size(); ++i) {
    EXPECT_EQ(forward[i].point2D_idx1, matches[i].point2D_idx2);
    EXPECT_EQ(forward[i].point2D_idx2, matches[i].point2D_idx1);
  }
  EXPECT_TRUE(database.ReadMatches(1, 2).empty());
  EXPECT_TRUE(database.ReadMatches(2, 3).empty());

  RawDatabase raw(DatabasePath());
  const auto row = raw.Row("SELECT rows, cols, data FROM matches WHERE pair_id = 2147483650;");
  ASSERT_EQ(row.size(), 3u);
  EXPECT_EQ(row[0], "200");
  EXPECT_EQ(row[1], "2");
  const std::vector<uint32_t> stored = BlobAs<uint32_t>(row[2]);
  ASSERT_EQ(stored.size(), 400u);
  EXPECT_EQ(stored[0], matches[0].point2D_idx2);  // image 1's index first
  EXPECT_EQ(stored[1], matches[0].point2D_idx1);
  EXPECT_EQ(raw.Row("SELECT rows, cols, length(data) FROM matches WHERE pair_id = 2147483649;"),
            (std::vector<std::string>{"0", "2", "0"}));
}

TEST_F(DatabaseTest, TwoViewGeometryInEitherOrder) {
  const SyntheticPair pair;
  Database database(DatabasePath());
  AddCamerasAndImages(&database);
  database.WriteTwoViewGeometry(1, 2, pair.geometry);

  // Read from image 2's side: every relation must hold with the roles exchanged.
  const TwoViewGeometry inverse = database.ReadTwoViewGeometry(2, 1);
  EXPECT_EQ(inverse.config, TwoViewGeometry::CALIBRATED);
  EXPECT_EQ(inverse.F, pair.geometry.F.transpose());
  EXPECT_EQ(inverse.E, pair.geometry.E.transpose());
  for (const Eigen::Vector3d& point : pair.points_in_cam1) {
    const Eigen::Vector3d x1 = pair.Pixel1(point), x2 = pair.Pixel2(point);
    EXPECT_NEAR(x2.dot(pair.geometry.F * x1), 0, 1e-9);  // the truth holds
    EXPECT_NEAR(x1.dot(inverse.F * x2), 0, 1e-9);
    const Eigen::Vector3d h = inverse.H * x2;
    EXPECT_NEAR((h / h.z() - x1).norm(), 0, 1e-9);
    const Eigen::Vector3d point_in_cam2 = pair.cam2_from_cam1 * point;
    EXPECT_NEAR((inverse.cam2_from_cam1 * point_in_cam2 - point).norm(), 0, 1e-12);
  }
  EXPECT_EQ(inverse.inlier_matches, (FeatureMatches{{10, 0}, {11, 1}, {12, 2}, {3, 7}}));

  const TwoViewGeometry same = database.ReadTwoViewGeometry(1, 2);
  EXPECT_EQ(same.F, pair.geometry.F);
  EXPECT_EQ(same.H, pair.geometry.H);
  EXPECT_EQ(same.cam2_from_cam1.rotation.coeffs(), pair.geometry.cam2_from_cam1.rotation.coeffs());
  EXPECT_EQ(same.cam2_from_cam1.translation, pair.geometry.cam2_from_cam1.translation);
  EXPECT_EQ(same.inlier_matches, pair.geometry.inlier_matches);

  // Written from image 2's side, read back from image 2's side: the caller's data.
  database.WriteTwoViewGeometry(3, 2, inverse);
  const TwoViewGeometry back = database.ReadTwoViewGeometry(3, 2);
  EXPECT_TRUE(back.F.isApprox(inverse.F, 1e-12));
  EXPECT_TRUE(back.H.isApprox(inverse.H, 1e-12));
  EXPECT_TRUE(back.cam2_from_cam1.rotation.isApprox(inverse.cam2_from_cam1.rotation, 1e-12));
  EXPECT_TRUE(back.cam2_from_cam1.translation.isApprox(inverse.cam2_from_cam1.translation, 1e-12));
  EXPECT_EQ(back.inlier_matches, inverse.inlier_matches);

  // Stored order: (2, 3) holds the original geometry of the synthetic pair.
  const auto all = database.ReadAllTwoViewGeometries();
  ASSERT_EQ(all.size(), 2u);
  EXPECT_EQ(all[0].first, ImagePairToPairId(1, 2));
  EXPECT_EQ(all[1].first, ImagePairToPairId(2, 3));
  EXPECT_TRUE(all[1].second.F.isApprox(pair.geometry.F, 1e-12));
  EXPECT_EQ(all[1].second.inlier_matches, pair.geometry.inlier_matches);

  // COLMAP's blobs: F row-major float64, qvec w x y z, tvec x y z.
  RawDatabase raw(DatabasePath());
  const auto row = raw.Row(
      "SELECT rows, cols, config, F, qvec, tvec FROM two_view_geometries "
      "WHERE pair_id = 2147483649;");
  ASSERT_EQ(row.size(), 6u);
  EXPECT_EQ(row[0], "4");
  EXPECT_EQ(row[1], "2");
  EXPECT_EQ(row[2], "2");
  const std::vector<double> F = BlobAs<double>(row[3]);
  ASSERT_EQ(F.size(), 9u);
  EXPECT_EQ(F[1], pair.geometry.F(0, 1));
  EXPECT_EQ(F[3], pair.geometry.F(1, 0));
  const std::vector<double> qvec = BlobAs<double>(row[4]);
  ASSERT_EQ(qvec.size(), 4u);
  EXPECT_EQ(qvec[0], pair.cam2_from_cam1.rotation.w());
  EXPECT_EQ(qvec[3], pair.cam2_from_cam1.rotation.z());
  EXPECT_EQ(BlobAs<double>(row[5])[0], pair.cam2_from_cam1.translation.x());

  EXPECT_TRUE(database.ExistsTwoViewGeometry(2, 1));
  EXPECT_FALSE(database.ExistsTwoViewGeometry(1, 3));
  EXPECT_EQ(database.ReadTwoViewGeometry(1, 3).config, TwoViewGeometry::UNDEFINED);
}

TEST_F(DatabaseTest, CountsVerifiedPairs) {
  Database database(DatabasePath());
  AddCamerasAndImages(&database);
  TwoViewGeometry degenerate;
  degenerate.config = TwoViewGeometry::DEGENERATE;
  database.WriteTwoViewGeometry(1, 2, degenerate);
  TwoViewGeometry planar;
  planar.config = TwoViewGeometry::PLANAR;
  planar.H = Eigen::Matrix3d::Identity();
  planar.inlier_matches = {{1, 2}};
  database.WriteTwoViewGeometry(1, 3, planar);
  TwoViewGeometry no_inliers;
  no_inliers.config = TwoViewGeometry::UNCALIBRATED;
  database.WriteTwoViewGeometry(3, 2, no_inliers);
  EXPECT_EQ(database.ReadAllTwoViewGeometries().size(), 3u);
  EXPECT_EQ(database.NumVerifiedPairs(), 1u);
  // A zero H (none estimated) stays zero when inverted, instead of infinities.
  EXPECT_EQ(database.ReadTwoViewGeometry(3, 2).H, Eigen::Matrix3d::Zero());
}

TEST_F(DatabaseTest, ClearsCascade) {
  Database database(DatabasePath());
  AddCamerasAndImages(&database);
  const auto fill = [&] {
    for (const image_t image_id : {1u, 2u, 3u}) {
      database.WriteKeypoints(image_id, {FeatureKeypoint(1, 2)});
      FeatureDescriptors descriptors;
      descriptors.data = FeatureDescriptors::Matrix::Constant(1, 32, 7);
      database.WriteDescriptors(image_id, descriptors);
    }
    database.WriteMatches(1, 2, {{0, 0}});
    database.WriteMatches(2, 3, {{0, 0}});
    TwoViewGeometry geometry;
    geometry.config = TwoViewGeometry::UNCALIBRATED;
    geometry.inlier_matches = {{0, 0}};
    database.WriteTwoViewGeometry(1, 2, geometry);
    for (const char* stage :
         {Database::kFeaturesStage, Database::kMatchesStage, Database::kTwoViewGeometriesStage}) {
      database.WriteStageProvenance(stage, {{"plugin", stage}});
    }
  };

  fill();
  database.ClearTwoViewGeometries();
  EXPECT_EQ(database.NumVerifiedPairs(), 0u);
  EXPECT_EQ(database.NumMatchedPairs(), 2u);
  EXPECT_FALSE(database.ReadStageProvenance("two_view_geometries").has_value());
  EXPECT_TRUE(database.ReadStageProvenance("matches").has_value());

  fill();
  database.ClearMatches();
  EXPECT_EQ(database.NumMatchedPairs(), 0u);
  EXPECT_FALSE(database.ExistsTwoViewGeometry(1, 2));
  EXPECT_TRUE(database.ExistsKeypoints(1));
  EXPECT_FALSE(database.ReadStageProvenance("matches").has_value());
  EXPECT_TRUE(database.ReadStageProvenance("features").has_value());

  fill();
  database.ClearKeypointsAndDescriptors();
  EXPECT_FALSE(database.ExistsKeypoints(1));
  EXPECT_FALSE(database.ExistsDescriptors(2));
  EXPECT_EQ(database.NumKeypoints(), 0u);
  EXPECT_EQ(database.NumMatchedPairs(), 0u);
  EXPECT_FALSE(database.ExistsTwoViewGeometry(1, 2));
  EXPECT_FALSE(database.ReadStageProvenance("features").has_value());
  EXPECT_EQ(database.NumImages(), 3u);  // images and cameras stay
  EXPECT_EQ(database.NumCameras(), 2u);
}

TEST_F(DatabaseTest, StageProvenanceRoundTrip) {
  const nlohmann::json provenance = {
      {"plugin", "sift"}, {"version", "1.2.0"}, {"options", {{"max_num_features", 8192}}}};
  {
    Database database(DatabasePath());
    EXPECT_FALSE(database.ReadStageProvenance("features").has_value());
    database.WriteStageProvenance("features", {{"plugin", "orb"}});
    database.WriteStageProvenance("features", provenance);  // replaces
  }
  Database database(DatabasePath());
  EXPECT_EQ(database.ReadStageProvenance("features"), provenance);
  RawDatabase raw(DatabasePath());
  raw.Exec("UPDATE tessera_stages SET provenance = '{broken' WHERE stage = 'features';");
  EXPECT_THROW(database.ReadStageProvenance("features"), InputError);
}

TEST_F(DatabaseTest, ImageMetadataRoundTripAndOldWorkspacesHaveNone) {
  ImageMetadata full;
  full.make = "Canon";
  full.model = "EOS 5D";
  full.focal_length_mm = 24.5;
  full.focal_length_35mm = 24;
  full.gps = GpsPosition{45.5123456789, -73.25, 31.5};
  full.capture_time_s = 1262304000.25;
  ImageMetadata no_altitude;
  no_altitude.gps = GpsPosition{-33.9, 151.2, std::nullopt};
  {
    Database database(DatabasePath());
    AddCamerasAndImages(&database);
    // A workspace made before the metadata table: no rows, an empty map.
    EXPECT_TRUE(database.ReadAllImageMetadata().empty());
    database.WriteImageMetadata(1, ImageMetadata{});
    database.WriteImageMetadata(2, full);
    database.WriteImageMetadata(3, full);
    database.WriteImageMetadata(3, no_altitude);  // replaces
  }
  Database database(DatabasePath());
  const auto metadata = database.ReadAllImageMetadata();
  ASSERT_EQ(metadata.size(), 3u);
  EXPECT_TRUE(metadata.at(1).make.empty());
  EXPECT_FALSE(metadata.at(1).gps);
  EXPECT_FALSE(metadata.at(1).capture_time_s);
  EXPECT_FALSE(metadata.at(1).focal_length_mm);
  const ImageMetadata& read = metadata.at(2);
  EXPECT_EQ(read.make, "Canon");
  EXPECT_EQ(read.model, "EOS 5D");
  EXPECT_EQ(read.focal_length_mm, 24.5);
  EXPECT_EQ(read.focal_length_35mm, 24);
  ASSERT_TRUE(read.gps);
  EXPECT_EQ(read.gps->latitude_deg, 45.5123456789);  // JSON keeps every digit of a double
  EXPECT_EQ(read.gps->longitude_deg, -73.25);
  EXPECT_EQ(read.gps->altitude_m, 31.5);
  EXPECT_EQ(read.capture_time_s, 1262304000.25);
  ASSERT_TRUE(metadata.at(3).gps);
  EXPECT_EQ(metadata.at(3).gps->latitude_deg, -33.9);
  EXPECT_FALSE(metadata.at(3).gps->altitude_m);

  // Clearing features keeps the metadata: it belongs to the images.
  database.ClearKeypointsAndDescriptors();
  EXPECT_EQ(database.ReadAllImageMetadata().size(), 3u);

  RawDatabase raw(DatabasePath());
  raw.Exec("UPDATE tessera_image_metadata SET metadata = '{\"gps\": 3}' WHERE image_id = 2;");
  try {
    database.ReadAllImageMetadata();
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("the metadata of image 2 is not valid"),
              std::string::npos)
        << error.what();
  }
}

TEST_F(DatabaseTest, DescriptorDimensionFromTheFirstNonEmptyRow) {
  Database database(DatabasePath());
  AddCamerasAndImages(&database);
  EXPECT_FALSE(database.DescriptorDimension());
  FeatureDescriptors empty;
  empty.data.resize(0, 128);
  database.WriteDescriptors(1, empty);
  EXPECT_FALSE(database.DescriptorDimension());
  FeatureDescriptors orb;
  orb.metric = DescriptorMetric::kHamming;
  orb.data.setConstant(5, 32, 7);
  database.WriteDescriptors(2, orb);
  EXPECT_EQ(database.DescriptorDimension(), 32);
}

TEST_F(DatabaseTest, TransactionsCommitOrRollBack) {
  Database database(DatabasePath());
  AddCamerasAndImages(&database);
  {
    Database::Transaction transaction(&database);
    database.WriteKeypoints(1, {FeatureKeypoint(1, 1)});
    database.WriteMatches(1, 2, {{0, 0}});
    EXPECT_THROW(Database::Transaction nested(&database), std::logic_error);
  }  // not committed
  EXPECT_FALSE(database.ExistsKeypoints(1));
  EXPECT_FALSE(database.ExistsMatches(1, 2));
  {
    Database::Transaction transaction(&database);
    database.WriteKeypoints(1, {FeatureKeypoint(1, 1)});
    database.WriteMatches(1, 2, {{0, 0}});
    // Clearing inside a transaction nests (a savepoint) and rolls back with it.
    database.ClearMatches();
    database.WriteMatches(2, 3, {{0, 0}});
    transaction.Commit();
    EXPECT_THROW(transaction.Commit(), std::logic_error);
  }
  EXPECT_TRUE(database.ExistsKeypoints(1));
  EXPECT_FALSE(database.ExistsMatches(1, 2));
  EXPECT_TRUE(database.ExistsMatches(2, 3));
}

TEST_F(DatabaseTest, ConcurrentWritersShareOneConnection) {
  Database database(DatabasePath());
  Image image;
  image.camera_id = database.WriteCamera(
      Camera::Create(kInvalidCameraId, CameraModelId::kSimplePinhole, 100, 64, 48));
  constexpr image_t kNumImages = 24;
  for (image_t i = 0; i < kNumImages; ++i) {
    image.name = std::to_string(i) + ".jpg";
    database.WriteImage(image);
  }
  // Each thread writes its own pairs, with matches that encode the pair.
  const auto matches_of = [](image_t id1, image_t id2) {
    return FeatureMatches(id1 + id2, FeatureMatch{id1, id2});
  };
  std::vector<std::thread> threads;
  for (image_t t = 0; t < 4; ++t) {
    threads.emplace_back([&, t] {
      for (image_t id1 = 1; id1 <= kNumImages; ++id1) {
        for (image_t id2 = id1 + 1; id2 <= kNumImages; ++id2) {
          if ((id1 + id2) % 4 != t) continue;
          database.WriteMatches(id2, id1, matches_of(id2, id1));
          EXPECT_EQ(database.ReadMatches(id1, id2).size(), id1 + id2);
        }
      }
    });
  }
  for (std::thread& thread : threads) thread.join();
  EXPECT_EQ(database.NumMatchedPairs(), kNumImages * (kNumImages - 1) / 2);
  for (image_t id1 = 1; id1 <= kNumImages; ++id1) {
    for (image_t id2 = id1 + 1; id2 <= kNumImages; ++id2) {
      ASSERT_EQ(database.ReadMatches(id2, id1), matches_of(id2, id1)) << id1 << " " << id2;
    }
  }
}

TEST_F(DatabaseTest, KilledProcessLeavesTheCommittedState) {
  {
    Database database(DatabasePath());
    AddCamerasAndImages(&database);
  }
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    // The child commits one batch, starts a second and is killed in the middle of it.
    Database database(DatabasePath());
    {
      Database::Transaction transaction(&database);
      database.WriteKeypoints(1, {FeatureKeypoint(1, 1), FeatureKeypoint(2, 2)});
      database.WriteMatches(1, 2, {{0, 1}});
      transaction.Commit();
    }
    Database::Transaction transaction(&database);
    database.WriteKeypoints(2, {FeatureKeypoint(3, 3)});
    database.WriteMatches(1, 3, {{0, 1}});
    raise(SIGKILL);
    _exit(0);
  }
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFSIGNALED(status));
  EXPECT_EQ(WTERMSIG(status), SIGKILL);

  Database database(DatabasePath());
  EXPECT_EQ(database.ReadKeypoints(1).size(), 2u);
  EXPECT_EQ(database.ReadMatches(2, 1), (FeatureMatches{{1, 0}}));
  EXPECT_FALSE(database.ExistsKeypoints(2));
  EXPECT_FALSE(database.ExistsMatches(1, 3));
  RawDatabase raw(DatabasePath());
  EXPECT_EQ(raw.Row("PRAGMA integrity_check;"), std::vector<std::string>{"ok"});
}

TEST_F(DatabaseTest, TextFileIsAnInputErrorNamingTheFile) {
  const fs::path path = dir_.path() / "notes.db";
  std::ofstream(path) << "This is a text file, long enough to fill a SQLite header and more of "
                         "it: lorem ipsum dolor sit amet, consectetur adipiscing elit.\n";
  try {
    Database database(path);
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("'" + path.string() + "' is not a valid SQLite database"),
              std::string::npos)
        << message;
  }
}

TEST_F(DatabaseTest, MissingFolderIsAnInputError) {
  const fs::path path = dir_.path() / "no" / "such" / "folder" / "database.db";
  try {
    Database database(path);
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("Cannot open database file '" + path.string()),
              std::string::npos)
        << error.what();
  }
}

TEST_F(DatabaseTest, ForeignSchemaIsAnInputError) {
  {
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open(DatabasePath().c_str(), &db), SQLITE_OK);
    sqlite3_exec(db, "CREATE TABLE matches (id INTEGER PRIMARY KEY, score REAL);", nullptr, nullptr,
                 nullptr);
    sqlite3_close(db);
  }
  try {
    Database database(DatabasePath());
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()),
              "Database '" + DatabasePath().string() +
                  "' has an incompatible schema: table 'matches' has no column 'pair_id'.");
  }
}

// The message of the InputError that opening a new database at `path` gives after
// `bytes` are written over its header at `offset`; empty when it opens.
std::string OpenErrorAfterOverwritingHeader(const fs::path& path, std::streamoff offset,
                                            const std::string& bytes) {
  { Database database(path); }
  {
    std::fstream file(path, std::ios::in | std::ios::out | std::ios::binary);
    file.seekp(offset);
    file.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  }
  try {
    Database database(path);
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

// Found by tests/fuzz (database target): a file SQLite refuses to read ("unsupported
// file format": a schema format number above 4) is bad input, not an internal failure.
TEST_F(DatabaseTest, UnsupportedSchemaFormatIsAnInputError) {
  // 44: the schema format number, big-endian.
  const std::string error =
      OpenErrorAfterOverwritingHeader(DatabasePath(), 44, std::string("\0\0\0\x09", 4));
  EXPECT_NE(error.find("unsupported file format"), std::string::npos) << error;
}

// Found by tests/fuzz (database target): a header whose file format write version is
// above 2 makes SQLite open the file read-only without an error; writing the journal
// mode then failed as an internal error. It is bad input, named before any write.
TEST_F(DatabaseTest, AHeaderSQLiteMayNotWriteIsAnInputError) {
  // 18: the file format write version.
  EXPECT_EQ(OpenErrorAfterOverwritingHeader(DatabasePath(), 18, "\x41"),
            "Database file '" + DatabasePath().string() +
                "' can only be read: the file is not writable, or its header names a file "
                "format version that SQLite does not write (a damaged or newer file).");
}

// Found by tests/fuzz (database target): a NULL image name and row counts far beyond
// the stored bytes are refused, not dereferenced or allocated.
TEST_F(DatabaseTest, CorruptRowsAreInputErrors) {
  {
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open(DatabasePath().c_str(), &db), SQLITE_OK);
    // An images table without COLMAP's NOT NULL, as a damaged file may hold.
    sqlite3_exec(db,
                 "CREATE TABLE images (image_id INTEGER PRIMARY KEY, name TEXT, camera_id "
                 "INTEGER);"
                 "INSERT INTO images VALUES(4, NULL, 1);",
                 nullptr, nullptr, nullptr);
    sqlite3_close(db);
  }
  {
    Database database(DatabasePath());
    try {
      database.ReadAllImages();
      FAIL() << "expected an error";
    } catch (const InputError& error) {
      EXPECT_EQ(std::string(error.what()),
                "Database '" + DatabasePath().string() + "': image 4 has no name.");
    }
    database.WriteKeypoints(4, {FeatureKeypoint(1, 2)});
    FeatureDescriptors descriptors;
    descriptors.data = FeatureDescriptors::Matrix::Constant(1, 32, 7);
    database.WriteDescriptors(4, descriptors);
    database.WriteMatches(4, 5, {{0, 0}});
  }
  // 2^61 rows: the byte count of the matches wraps to zero in 64 bits.
  RawDatabase(DatabasePath())
      .Exec(
          "UPDATE keypoints SET rows = 4611686018427387904; "
          "UPDATE descriptors SET rows = 1099511627776, cols = 1099511627776; "
          "UPDATE matches SET rows = 2305843009213693952;");
  Database database(DatabasePath());
  EXPECT_THROW(database.ReadKeypoints(4), InputError);
  EXPECT_THROW(database.ReadDescriptors(4, DescriptorMetric::kHamming), InputError);
  EXPECT_THROW(database.ReadMatches(4, 5), InputError);
}

TEST_F(DatabaseTest, OldColmapGeometryTableGainsItsColumns) {
  {
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open(DatabasePath().c_str(), &db), SQLITE_OK);
    // COLMAP before 3.7: no F, E, H, qvec, tvec.
    sqlite3_exec(db,
                 "CREATE TABLE two_view_geometries (pair_id INTEGER PRIMARY KEY NOT NULL, rows "
                 "INTEGER NOT NULL, cols INTEGER NOT NULL, data BLOB, config INTEGER NOT NULL);"
                 "INSERT INTO two_view_geometries VALUES(2147483650, 0, 2, NULL, 1);",
                 nullptr, nullptr, nullptr);
    sqlite3_close(db);
  }
  Database database(DatabasePath());
  const TwoViewGeometry geometry = database.ReadTwoViewGeometry(1, 3);
  EXPECT_EQ(geometry.config, TwoViewGeometry::DEGENERATE);
  EXPECT_EQ(geometry.F, Eigen::Matrix3d::Zero());
  EXPECT_EQ(geometry.cam2_from_cam1.rotation.w(), 1.0);
}

TEST_F(DatabaseTest, SchemaTextEqualsColmaps) {
  { Database database(DatabasePath()); }
  const auto ours = RawDatabase(DatabasePath()).Schema();
  EXPECT_EQ(RawDatabase(DatabasePath()).Row("PRAGMA user_version;"),
            std::vector<std::string>{"3800"});
  bool compared = false;
  if (fs::exists(AnchorDatabase())) {
    const fs::path anchor = dir_.path() / "anchor.db";
    fs::copy_file(AnchorDatabase(), anchor);
    EXPECT_EQ(ours, RawDatabase(anchor).Schema());
    compared = true;
  } else {
    TESSERA_SKIP_PART_OR_FAIL_IN_CI("COLMAP anchor database not found at " << AnchorDatabase());
  }
  if (ColmapAvailable()) {
    const fs::path fresh = dir_.path() / "colmap.db";
    ASSERT_EQ(std::system(("colmap database_creator --database_path '" + fresh.string() +
                           "' > /dev/null 2>&1")
                              .c_str()),
              0);
    EXPECT_EQ(ours, RawDatabase(fresh).Schema());
    compared = true;
  } else {
    TESSERA_SKIP_PART_OR_FAIL_IN_CI("colmap is not installed; its fresh schema is not compared");
  }
  if (!compared) {
    TESSERA_SKIP_OR_FAIL_IN_CI("neither the COLMAP anchor database nor colmap is available");
  }
}

TEST_F(DatabaseTest, ColmapReadsWhatTesseraWrote) {
  if (!ColmapAvailable()) TESSERA_SKIP_OR_FAIL_IN_CI("colmap is not installed");
  std::mt19937 rng(11);
  const FeatureKeypoints keypoints = RandomKeypoints(50, &rng);
  const FeatureMatches matches = RandomMatches(20, &rng);
  const SyntheticPair pair;
  {
    Database database(DatabasePath());
    AddCamerasAndImages(&database);
    for (const image_t image_id : {1u, 2u, 3u}) {
      database.WriteKeypoints(image_id, keypoints);
      FeatureDescriptors descriptors;
      descriptors.data = FeatureDescriptors::Matrix::Constant(50, 128, image_id);
      database.WriteDescriptors(image_id, descriptors);
    }
    database.WriteMatches(2, 1, matches);
    database.WriteMatches(2, 3, {});
    database.WriteTwoViewGeometry(2, 1, pair.geometry);
  }
  // database_merger reads every table of both inputs with COLMAP's own reader and
  // writes them out again with its writer.
  const fs::path empty = dir_.path() / "empty.db";
  const fs::path merged = dir_.path() / "merged.db";
  const fs::path log = dir_.path() / "colmap.log";
  ASSERT_EQ(std::system(("colmap database_creator --database_path '" + empty.string() +
                         "' > /dev/null 2>&1")
                            .c_str()),
            0);
  const int status =
      std::system(("colmap database_merger --database_path1 '" + DatabasePath().string() +
                   "' --database_path2 '" + empty.string() + "' --merged_database_path '" +
                   merged.string() + "' > '" + log.string() + "' 2>&1")
                      .c_str());
  ASSERT_EQ(status, 0) << std::ifstream(log).rdbuf();

  Database database(merged);
  const std::vector<Camera> cameras = database.ReadAllCameras();
  ASSERT_EQ(cameras.size(), 2u);
  EXPECT_EQ(cameras[1].model_id, CameraModelId::kSimpleRadial);
  EXPECT_EQ(cameras[1].params[0], 700);
  const auto a = database.ReadImageWithName("a.jpg");
  const auto b = database.ReadImageWithName("b.jpg");
  const auto c = database.ReadImageWithName("c.jpg");
  ASSERT_TRUE(a && b && c);
  EXPECT_TRUE(SameKeypoints(database.ReadKeypoints(b->image_id), keypoints));
  EXPECT_EQ(database.ReadDescriptors(c->image_id, DescriptorMetric::kL2).data(49, 127), 3);
  EXPECT_EQ(database.ReadMatches(b->image_id, a->image_id), matches);
  // COLMAP reads only pairs with rows > 0 (ReadAllMatches), so the empty one is gone:
  // an empty row marks "matched, nothing found" for Tessera and is harmless to COLMAP.
  EXPECT_EQ(database.NumMatchedPairs(), 1u);
  const TwoViewGeometry geometry = database.ReadTwoViewGeometry(b->image_id, a->image_id);
  EXPECT_EQ(geometry.config, TwoViewGeometry::CALIBRATED);
  EXPECT_TRUE(geometry.F.isApprox(pair.geometry.F, 1e-12));
  EXPECT_TRUE(geometry.H.isApprox(pair.geometry.H, 1e-12));
  EXPECT_TRUE(geometry.cam2_from_cam1.rotation.isApprox(pair.cam2_from_cam1.rotation, 1e-12));
  EXPECT_TRUE(geometry.cam2_from_cam1.translation.isApprox(pair.cam2_from_cam1.translation, 1e-12));
  EXPECT_EQ(geometry.inlier_matches, pair.geometry.inlier_matches);
}

TEST_F(DatabaseTest, ReadsColmapsAnchorDatabase) {
  if (!fs::exists(AnchorDatabase())) {
    TESSERA_SKIP_OR_FAIL_IN_CI("COLMAP anchor database not found at " << AnchorDatabase());
  }
  const fs::path path = dir_.path() / "database.db";
  fs::copy_file(AnchorDatabase(), path);
  Database database(path);

  const std::vector<Camera> cameras = database.ReadAllCameras();
  ASSERT_EQ(cameras.size(), 1u);
  EXPECT_EQ(cameras[0].model_id, CameraModelId::kSimpleRadial);
  EXPECT_EQ(cameras[0].width, 3072u);
  EXPECT_EQ(cameras[0].height, 2048u);
  EXPECT_EQ(cameras[0].calibration_source, CalibrationSource::kDatabase);

  const std::vector<Image> images = database.ReadAllImages();
  ASSERT_EQ(images.size(), 11u);
  for (size_t i = 0; i < images.size(); ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "%04zu.jpg", i);
    EXPECT_EQ(images[i].image_id, i + 1);
    EXPECT_EQ(images[i].name, name);
    EXPECT_EQ(images[i].camera_id, 1u);
  }

  const FeatureKeypoints keypoints1 = database.ReadKeypoints(1);
  const FeatureKeypoints keypoints2 = database.ReadKeypoints(2);
  EXPECT_EQ(keypoints1.size(), 10496u);
  EXPECT_EQ(RawDatabase(path).Row("SELECT cols FROM keypoints WHERE image_id = 1;"),
            std::vector<std::string>{"6"});
  const FeatureDescriptors descriptors = database.ReadDescriptors(1, DescriptorMetric::kL2);
  EXPECT_EQ(descriptors.data.rows(), 10496);
  EXPECT_EQ(descriptors.data.cols(), 128);

  const FeatureMatches matches12 = database.ReadMatches(1, 2);
  const FeatureMatches matches21 = database.ReadMatches(2, 1);
  EXPECT_EQ(matches12.size(), 5181u);
  ASSERT_EQ(matches21.size(), matches12.size());
  for (size_t i = 0; i < matches12.size(); ++i) {
    ASSERT_EQ(matches21[i].point2D_idx1, matches12[i].point2D_idx2) << i;
    ASSERT_EQ(matches21[i].point2D_idx2, matches12[i].point2D_idx1) << i;
  }
  EXPECT_EQ(database.NumMatchedPairs(), 55u);
  EXPECT_EQ(database.ReadMatchedPairIds().size(), 55u);

  const auto geometries = database.ReadAllTwoViewGeometries();
  ASSERT_EQ(geometries.size(), 55u);
  std::map<int, int> configs;
  for (const auto& [pair_id, geometry] : geometries) ++configs[geometry.config];
  // COLMAP verified these pairs as UNCALIBRATED (F) or PLANAR_OR_PANORAMIC (H).
  EXPECT_EQ(configs, (std::map<int, int>{{TwoViewGeometry::UNCALIBRATED, 40},
                                         {TwoViewGeometry::PLANAR_OR_PANORAMIC, 15}}));
  EXPECT_EQ(database.NumVerifiedPairs(), 55u);

  // F read row-major relates image 1 to image 2: the inliers' Sampson distance is
  // within COLMAP's 4 px RANSAC threshold; the transposed matrix would not fit them.
  const TwoViewGeometry geometry12 = database.ReadTwoViewGeometry(1, 2);
  ASSERT_EQ(geometry12.inlier_matches.size(), 5142u);
  const auto sampson = [&](const Eigen::Matrix3d& F, const FeatureMatch& match) {
    const Eigen::Vector3d x1(keypoints1[match.point2D_idx1].x, keypoints1[match.point2D_idx1].y, 1);
    const Eigen::Vector3d x2(keypoints2[match.point2D_idx2].x, keypoints2[match.point2D_idx2].y, 1);
    const Eigen::Vector3d Fx1 = F * x1, Ftx2 = F.transpose() * x2;
    const double c = x2.dot(Fx1);
    return c * c / (Fx1.head<2>().squaredNorm() + Ftx2.head<2>().squaredNorm());
  };
  size_t within = 0, within_transposed = 0;
  for (const FeatureMatch& match : geometry12.inlier_matches) {
    within += sampson(geometry12.F, match) < 16 ? 1 : 0;
    within_transposed += sampson(geometry12.F.transpose(), match) < 16 ? 1 : 0;
  }
  EXPECT_GE(within, geometry12.inlier_matches.size() * 99 / 100);
  EXPECT_LT(within_transposed, geometry12.inlier_matches.size() / 2);

  const TwoViewGeometry geometry21 = database.ReadTwoViewGeometry(2, 1);
  EXPECT_EQ(geometry21.F, geometry12.F.transpose());
  EXPECT_EQ(geometry21.inlier_matches.front().point2D_idx1,
            geometry12.inlier_matches.front().point2D_idx2);
}

TEST_F(DatabaseTest, ImageFilesRoundTripAndDeleteImageRemovesAllItsRows) {
  Database database(DatabasePath());
  AddCamerasAndImages(&database);  // a, b on camera 1; c on camera 2
  database.WriteImageFile({"a.jpg", 1, 100, "aa", ""});
  database.WriteImageFile({"c.jpg", 3, 300, "cc", ""});
  database.WriteImageFile({"bad.png", std::nullopt, 7, "ff", "cannot decode the image"});
  const auto files = database.ReadImageFiles();
  ASSERT_EQ(files.size(), 3u);
  EXPECT_EQ(files[0].name, "a.jpg");
  EXPECT_EQ(files[0].image_id, std::optional<image_t>(1));
  EXPECT_EQ(files[0].size, 100u);
  EXPECT_EQ(files[0].content_hash, "aa");
  EXPECT_EQ(files[1].name, "bad.png");
  EXPECT_FALSE(files[1].image_id.has_value());
  EXPECT_EQ(files[1].skip_reason, "cannot decode the image");
  for (const image_t image_id : {1u, 2u, 3u}) {
    database.WriteKeypoints(image_id, {FeatureKeypoint(1, 2)});
    FeatureDescriptors descriptors;
    descriptors.data = FeatureDescriptors::Matrix::Constant(1, 32, 7);
    database.WriteDescriptors(image_id, descriptors);
  }
  TwoViewGeometry geometry;
  geometry.config = TwoViewGeometry::UNCALIBRATED;
  geometry.inlier_matches = {{0, 0}};
  for (const auto& [id1, id2] : std::vector<std::pair<image_t, image_t>>{{1, 2}, {2, 3}, {3, 1}}) {
    database.WriteMatches(id1, id2, {{0, 0}});
    database.WriteTwoViewGeometry(id1, id2, geometry);
  }

  database.DeleteImage(3);  // the only image of camera 2, in pairs (2, 3) and (1, 3)
  EXPECT_EQ(database.NumImages(), 2u);
  EXPECT_FALSE(database.ExistsKeypoints(3));
  EXPECT_FALSE(database.ExistsDescriptors(3));
  EXPECT_EQ(database.ReadMatchedPairIds(), std::vector<image_pair_t>{ImagePairToPairId(1, 2)});
  EXPECT_EQ(database.ReadAllTwoViewGeometries().size(), 1u);
  EXPECT_EQ(database.NumCameras(), 1u);
  EXPECT_EQ(database.ReadImageFiles().size(), 2u);  // a.jpg and bad.png
  database.DeleteImage(1);                          // camera 1 still has b.jpg
  EXPECT_EQ(database.NumCameras(), 1u);
  EXPECT_EQ(database.NumMatchedPairs(), 0u);
  database.DeleteImageFile("bad.png");
  EXPECT_TRUE(database.ReadImageFiles().empty());
}

TEST_F(DatabaseTest, DescriptorWidthsAreCheckedOnRead) {
  Database database(DatabasePath());
  AddCamerasAndImages(&database);
  FeatureDescriptors orb, sift;
  orb.data = FeatureDescriptors::Matrix::Constant(2, 32, 1);
  sift.data = FeatureDescriptors::Matrix::Constant(2, 128, 1);
  database.WriteDescriptors(1, orb);
  EXPECT_EQ(database.DescriptorWidths(), std::vector<int64_t>{32});
  database.WriteDescriptors(2, sift);
  EXPECT_EQ(database.DescriptorWidths(), (std::vector<int64_t>{32, 128}));
  EXPECT_EQ(database.ReadDescriptors(1, DescriptorMetric::kHamming, 32).data.cols(), 32);
  try {
    database.ReadDescriptors(2, DescriptorMetric::kHamming, 32);
    FAIL() << "a descriptor row of the wrong width was read";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what())
                  .find("the descriptors of image 2 are 128 bytes wide, "
                        "expected 32"),
              std::string::npos)
        << error.what();
  }
}

// A full disk (here a file size limit, as `ulimit -f`) is an InputError naming the
// file, and the database keeps its last committed state.
TEST_F(DatabaseTest, AFullDiskIsAnInputErrorAndKeepsTheCommittedState) {
  {
    Database database(DatabasePath());
    AddCamerasAndImages(&database);
  }
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    signal(SIGXFSZ, SIG_IGN);
    const rlimit limit = {256 * 1024, 256 * 1024};
    if (setrlimit(RLIMIT_FSIZE, &limit) != 0) _exit(3);
    try {
      Database database(DatabasePath());
      FeatureDescriptors descriptors;
      descriptors.data = FeatureDescriptors::Matrix::Constant(20000, 128, 1);  // 2.5 MB
      Database::Transaction transaction(&database);
      database.WriteDescriptors(1, descriptors);
      transaction.Commit();
      _exit(4);  // written past the limit
    } catch (const InputError& error) {
      const std::string message = error.what();
      const bool named = message.find(DatabasePath().string()) != std::string::npos &&
                         message.find("is the disk full?") != std::string::npos;
      _exit(named ? 0 : 5);
    } catch (...) {
      _exit(6);
    }
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "3: setrlimit, 4: no error, 5: message, 6: other error";
  Database database(DatabasePath());
  EXPECT_EQ(database.NumImages(), 3u);
  EXPECT_FALSE(database.ExistsDescriptors(1));
}

TEST(DatabaseReadOnly, ReadsWithoutWritingAndRefusesWrites) {
  testing::TemporaryDir dir;
  const fs::path path = dir.path() / "what?#%.db";  // characters a URI must encode
  std::mt19937 rng(3);
  {
    Database database(path);
    database.WriteCamera(Camera::Create(kInvalidCameraId, CameraModelId::kPinhole, 500, 640, 480));
    Image image;
    image.name = "a.jpg";
    image.camera_id = 1;
    database.WriteImage(image);
    database.WriteKeypoints(1, RandomKeypoints(7, &rng));
    database.WriteStageProvenance("x", {{"a", 1}});
    database.WriteStageProvenance("y", {{"b", 2}});
    database.DeleteStageProvenance("y");
  }
  ASSERT_FALSE(fs::exists(path.string() + "-wal"));
  const auto modified = fs::last_write_time(path);
  {
    const Database reader(path, Database::Mode::kReadOnly);
    const Database other(path, Database::Mode::kReadOnly);
    EXPECT_EQ(reader.ReadAllImages().size(), 1u);
    EXPECT_EQ(reader.ReadNumKeypointsPerImage(), (std::map<image_t, size_t>{{1, 7}}));
    EXPECT_EQ(other.ReadKeypoints(1).size(), 7u);
    EXPECT_EQ(reader.ReadStageProvenance("x"), nlohmann::json({{"a", 1}}));
    EXPECT_FALSE(reader.ReadStageProvenance("y"));
    Database writer(path, Database::Mode::kReadOnly);
    EXPECT_THROW(writer.WriteKeypoints(1, RandomKeypoints(2, &rng)), std::exception);
    EXPECT_FALSE(fs::exists(path.string() + "-wal"));
    EXPECT_FALSE(fs::exists(path.string() + "-shm"));
  }
  EXPECT_EQ(fs::last_write_time(path), modified);
  EXPECT_EQ(Database(path).ReadKeypoints(1).size(), 7u);
  EXPECT_THROW(Database(dir.path() / "missing.db", Database::Mode::kReadOnly), InputError);
  EXPECT_FALSE(fs::exists(dir.path() / "missing.db"));
}

}  // namespace
}  // namespace tessera
