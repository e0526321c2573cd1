// The schema: COLMAP's own, character for character, so that COLMAP reads what Tessera
// writes and Tessera reads what COLMAP writes; older and foreign schemas.

#include "database/database_schema.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>

#include "database/database.h"
#include "database/database_test_support.h"
#include "tessera/errors.h"

namespace tessera {
namespace {

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

}  // namespace
}  // namespace tessera
