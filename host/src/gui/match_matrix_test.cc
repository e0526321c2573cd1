#include "gui/match_matrix.h"

#include <gtest/gtest.h>

#include "database/database.h"
#include "tessera/errors.h"
#include "test_support.h"

namespace tessera::gui {
namespace {

TEST(MatchMatrix, CountsVerifiedInliersPerPairAndReadsAPairsMatches) {
  testing::TemporaryDir dir;
  {
    Database database(dir.path() / "database.db");
    database.WriteCamera(Camera::Create(1, CameraModelId::kPinhole, 100, 64, 48), true);
    for (image_t image_id = 1; image_id <= 3; ++image_id) {
      Image image;
      image.image_id = image_id;
      image.camera_id = 1;
      image.name = "image" + std::to_string(image_id) + ".jpg";
      database.WriteImage(image, true);
      database.WriteKeypoints(
          image_id, {FeatureKeypoint(10.0f * image_id, 1), FeatureKeypoint(20.0f * image_id, 2)});
    }
    TwoViewGeometry geometry;
    geometry.config = TwoViewGeometry::CALIBRATED;
    geometry.inlier_matches = {{0, 1}, {1, 0}};
    database.WriteTwoViewGeometry(1, 3, geometry);
    geometry.inlier_matches = {{1, 1}};
    database.WriteTwoViewGeometry(2, 1, geometry);
  }
  const MatchMatrix matrix = ReadMatchMatrix(dir.path());
  ASSERT_EQ(matrix.size(), 3u);
  EXPECT_EQ(matrix.names[2], "image3.jpg");
  EXPECT_EQ(matrix.max_inliers, 2);
  const std::vector<int> expected = {0, 1, 2,  //
                                     1, 0, 0,  //
                                     2, 0, 0};
  EXPECT_EQ(matrix.inliers, expected);

  // In the order asked: image 3's keypoint of each match first.
  const PairInliers pair = ReadPairInliers(dir.path() / "database.db", 3, 1);
  EXPECT_EQ(pair.name1, "image3.jpg");
  EXPECT_EQ(pair.name2, "image1.jpg");
  ASSERT_EQ(pair.xy1.size(), 2u);
  EXPECT_EQ(pair.xy1[0], Eigen::Vector2f(60, 2));  // match (0, 1) seen from image 3: (1, 0)
  EXPECT_EQ(pair.xy2[0], Eigen::Vector2f(10, 1));
  EXPECT_TRUE(ReadPairInliers(dir.path(), 2, 3).xy1.empty());
}

TEST(MatchMatrix, RefusesAFolderWithoutADatabase) {
  testing::TemporaryDir dir;
  EXPECT_THROW(ReadMatchMatrix(dir.path()), InputError);
}

}  // namespace
}  // namespace tessera::gui
