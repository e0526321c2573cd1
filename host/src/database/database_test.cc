// Each table's round trip through Database, and rows that do not decode.

#include "database/database.h"

#include <gtest/gtest.h>

#include <optional>

#include "database/database_test_support.h"
#include "tessera/errors.h"

namespace tessera {
namespace {

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
    // Every model Tessera knows, the fisheye ones among them (they were left out).
    EXPECT_NE(std::string(error.what())
                  .find(", which Tessera does not support (it knows 0 SIMPLE_PINHOLE, 1 PINHOLE, "
                        "2 SIMPLE_RADIAL, 3 RADIAL, 4 OPENCV, 5 OPENCV_FISHEYE, 8 "
                        "SIMPLE_RADIAL_FISHEYE)."),
              std::string::npos)
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

// Matches made while an image had no features (its detector crashed) were reused after it
// was detected: a pair is current only while both its images have the features it was
// matched from.
TEST_F(DatabaseTest, MatchesAreStaleOnceAnImageOfThePairHasOtherFeatures) {
  Database database(DatabasePath());
  AddCamerasAndImages(&database);
  FeatureDescriptors descriptors;
  descriptors.data = FeatureDescriptors::Matrix::Constant(1, 32, 7);
  for (const image_t image_id : {1u, 2u}) {
    database.WriteKeypoints(image_id, {FeatureKeypoint(1, 2)});
    database.WriteDescriptors(image_id, descriptors);
  }
  database.WriteMatches(1, 2, {{0, 0}});
  database.WriteMatches(3, 1, {});  // image 3 has no features yet
  database.WriteMatches(2, 3, {});
  TwoViewGeometry geometry;
  geometry.config = TwoViewGeometry::UNCALIBRATED;
  geometry.inlier_matches = {{0, 0}};
  database.WriteTwoViewGeometry(1, 3, geometry);
  EXPECT_TRUE(database.ReadPairsWithStaleMatches().empty());

  // Image 3 detected: its pairs are stale, the pair (1, 2) is not.
  database.WriteKeypoints(3, {FeatureKeypoint(3, 4)});
  database.WriteDescriptors(3, descriptors);
  EXPECT_EQ(database.ReadPairsWithStaleMatches(),
            (std::vector<image_pair_t>{ImagePairToPairId(1, 3), ImagePairToPairId(2, 3)}));
  database.DeleteMatches(database.ReadPairsWithStaleMatches());
  EXPECT_FALSE(database.ExistsMatches(1, 3));
  EXPECT_FALSE(database.ExistsTwoViewGeometry(1, 3));
  EXPECT_TRUE(database.ExistsMatches(1, 2));
  database.WriteMatches(1, 3, {{0, 0}});
  EXPECT_TRUE(database.ReadPairsWithStaleMatches().empty());

  // The same features written again keep the pair current; other ones do not.
  database.WriteKeypoints(3, {FeatureKeypoint(3, 4)});
  EXPECT_TRUE(database.ReadPairsWithStaleMatches().empty());
  database.WriteKeypoints(1, {FeatureKeypoint(5, 6)});
  EXPECT_EQ(database.ReadPairsWithStaleMatches(),
            (std::vector<image_pair_t>{ImagePairToPairId(1, 2), ImagePairToPairId(1, 3)}));

  // A workspace matched before the records: its pairs count as current until an image is
  // detected again.
  RawDatabase raw(DatabasePath());
  raw.Exec("DELETE FROM tessera_features; DELETE FROM tessera_pair_features;");
  EXPECT_TRUE(database.ReadPairsWithStaleMatches().empty());
  database.ClearKeypointsAndDescriptors();
  EXPECT_EQ(raw.Row("SELECT COUNT(*) FROM tessera_features"), (std::vector<std::string>{"0"}));
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

// A COLMAP database from elsewhere may hold any text as an image name; the names become
// paths (image files, exports), so the unsafe ones are refused on every read, naming the
// database, the image and the name with its control characters escaped.
TEST_F(DatabaseTest, UnsafeImageNamesAreInputErrors) {
  const std::pair<std::string, std::string> cases[] = {
      {"'/etc/passwd'", "'/etc/passwd' is an absolute path"},
      {"'../../outside.jpg'", "'../../outside.jpg' has a '..' component"},
      {"'a' || char(10) || 'b.jpg'", "'a\\nb.jpg' contains a line break"},
      // A NUL inside the text: cut there, the name would read as plain 'a'.
      {"CAST(X'610062' AS TEXT)", "'a\\0b' contains the control character \\0"},
  };
  {
    Database database(DatabasePath());
    AddCamerasAndImages(&database);
  }
  for (const auto& [sql_name, message] : cases) {
    RawDatabase(DatabasePath())
        .Exec("INSERT INTO images(image_id, name, camera_id) VALUES(9, " + sql_name + ", 1);");
    Database database(DatabasePath());
    const std::string expected =
        "Database '" + DatabasePath().string() + "': image 9: the image name " + message;
    try {
      database.ReadAllImages();
      ADD_FAILURE() << "expected an error for " << sql_name;
    } catch (const InputError& error) {
      EXPECT_EQ(std::string(error.what()).substr(0, expected.size()), expected);
    }
    EXPECT_EQ(database.ReadImageWithName("a.jpg")->image_id, 1u);  // the others still read
    RawDatabase(DatabasePath()).Exec("DELETE FROM images WHERE image_id = 9;");
  }
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

}  // namespace
}  // namespace tessera
