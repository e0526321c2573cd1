#include "toolbox/model_alignment.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <filesystem>

#include "tessera/errors.h"
#include "tessera/io/file_io.h"
#include "tessera/sfm/gps_anchoring.h"
#include "tessera/testing/synthetic_model.h"
#include "test_support.h"
#include "util/angles.h"

namespace tessera {
namespace {

Reconstruction Scene() {
  const Camera camera = Camera::Create(1, CameraModelId::kSimpleRadial, 500, 640, 480);
  return testing::MakeSyntheticModel(camera, 8, 300);
}

Similarity3d KnownSimilarity() {
  Similarity3d sim;
  sim.scale = 2.5;
  sim.rotation =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  sim.translation = Eigen::Vector3d(3, -1, 12);
  return sim;
}

TEST(AlignToReference, RecoversAKnownSimilarity) {
  const Reconstruction model = Scene();
  Reconstruction reference = model;
  const Similarity3d known = KnownSimilarity();
  TransformModel(known, &reference);
  // One image of the reference is elsewhere: an outlier the estimate leaves out.
  Image& moved = reference.images.at(3);
  moved.cam_from_world.translation += Eigen::Vector3d(40, 0, 0);
  const Alignment alignment = AlignToReference(model, reference, "M", "REF");
  EXPECT_NEAR(alignment.new_from_old.scale, known.scale, 1e-6);
  EXPECT_LT((alignment.new_from_old.rotation - known.rotation).norm(), 1e-6);
  EXPECT_LT((alignment.new_from_old.translation - known.translation).norm(), 1e-6);
  EXPECT_EQ(alignment.num_inliers, 7u);
  EXPECT_LT(alignment.residual_max, 1e-6);
  // alignment.json reads back as the same similarity.
  testing::TemporaryDir dir;
  WriteFileAtomically(dir.path() / "alignment.json", alignment.ToJson().dump(2));
  const Similarity3d read = ReadAlignmentFile(dir.path() / "alignment.json");
  EXPECT_NEAR(read.scale, known.scale, 1e-6);
  EXPECT_LT((read.translation - known.translation).norm(), 1e-6);
}

TEST(AlignToReference, RefusesModelsSharingTooFewImagesNamingBoth) {
  const Reconstruction model = Scene();
  Reconstruction reference = model;
  for (auto& [image_id, image] : reference.images) {
    if (image_id > 2) image.name = "other_" + image.name;
  }
  try {
    AlignToReference(model, reference, "MODEL_DIR", "REF_DIR");
    FAIL() << "no error";
  } catch (const InputError& error) {
    const std::string what = error.what();
    EXPECT_NE(what.find("MODEL_DIR and REF_DIR share 2"), std::string::npos) << what;
  }
}

// The scene's cameras are level (up is -Y); turned by a tilt, upright turns them back,
// and puts a ground plane (at y = 1.5, below the points) at z = 0.
TEST(AlignUpright, LevelsTiltedCamerasAndPutsTheGroundAtZero) {
  Reconstruction model = Scene();
  point3D_t next = 100000;
  for (int i = 0; i < 200; ++i) {
    Point3D ground;
    ground.xyz = Eigen::Vector3d(-3 + 0.3 * (i % 20), 1.5, -3 + 0.6 * (i / 20));
    model.points3D[next++] = ground;
  }
  Similarity3d tilt;
  tilt.rotation = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 0, 1).normalized()).toRotationMatrix();
  tilt.translation = Eigen::Vector3d(5, 5, 5);
  TransformModel(tilt, &model);
  const Alignment alignment = AlignUpright(model, "M");
  ASSERT_TRUE(alignment.details["ground_plane"]["found"].get<bool>());
  EXPECT_EQ(alignment.num_inliers, 200u);
  for (const point3D_t id : alignment.inlier_point_ids) {
    EXPECT_NEAR((alignment.new_from_old * model.points3D.at(id).xyz).z(), 0, 1e-9);
  }
  // The cameras' up directions within a few degrees of +Z (each camera looks at the
  // origin from a slightly different height).
  EXPECT_LT(alignment.residual_max, 5);
  EXPECT_LT(alignment.details["mean_up_angle_after_deg"].get<double>(), 2);

  // Without the ground: the cameras' mean up direction exactly on +Z.
  Reconstruction cameras_only = Scene();
  TransformModel(tilt, &cameras_only);
  const Alignment level = AlignUpright(cameras_only, "M");
  EXPECT_FALSE(level.details["ground_plane"]["found"].get<bool>());
  EXPECT_LT(level.details["mean_up_angle_after_deg"].get<double>(), 1e-6);
}

// GPS tags at the camera centres moved by a similarity into metres, one of them far off:
// the similarity agrees with the others, and the far one is not an inlier.
TEST(AlignToGps, PlacesTheCentresOnTheirTagsLeavingAnOutlierOut) {
  const Reconstruction model = Scene();
  Similarity3d enu_from_model = KnownSimilarity();
  enu_from_model.scale = 10;  // an arc of about 40 m, well above the GPS noise
  const Georeference origin{46.5, 6.6, 400, "ENU"};
  std::map<image_t, ImageMetadata> metadata;
  for (const auto& [image_id, image] : model.images) {
    Eigen::Vector3d enu = enu_from_model * image.ProjectionCenter();
    if (image_id == 5) enu += Eigen::Vector3d(300, 0, 0);
    metadata[image_id].gps = Wgs84FromEnu(enu, origin);
  }
  // Tags good to 10 cm: the arc's depth (a few metres here) orients the model.
  GpsAnchoringOptions options;
  options.horizontal_sigma_m = options.vertical_sigma_m = 0.1;
  const Alignment alignment = AlignToGps(model, metadata, "M", options);
  EXPECT_EQ(alignment.num_inliers, 7u);
  EXPECT_NEAR(alignment.new_from_old.scale, 10, 1e-6);
  EXPECT_LT(alignment.residual_max, 1e-3);
  ASSERT_TRUE(alignment.georeference.has_value());
  for (const std::string& name : alignment.inlier_names) EXPECT_NE(name, "img_5.png");
}

}  // namespace
}  // namespace tessera
