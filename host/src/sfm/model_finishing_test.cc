#include "tessera/sfm/model_finishing.h"

#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include <Eigen/Geometry>
#include <filesystem>
#include <sstream>

#include "synthetic_scene.h"
#include "tessera/errors.h"
#include "tessera/io/georeference_io.h"
#include "tessera/sfm/gps_anchoring.h"
#include "tessera/sfm/incremental_pipeline.h"
#include "test_support.h"

namespace tessera {
namespace {

using testing::MakeSyntheticScene;
using testing::SyntheticScene;
using testing::SyntheticSceneOptions;

// The true poses of the images of `scene` with ids in [first, last], as a model (no
// points: the self-check needs only the poses and the cameras).
Reconstruction Poses(const SyntheticScene& scene, image_t first = 0,
                     image_t last = kInvalidImageId) {
  Reconstruction model;
  model.cameras = scene.input.cameras;
  for (const auto& [image_id, image] : scene.input.images) {
    if (image_id < first || image_id > last) continue;
    Image copy = image;
    copy.cam_from_world = scene.true_cam_from_world.at(image_id);
    copy.registered = true;
    model.images.emplace(image_id, std::move(copy));
  }
  return model;
}

// The log of `run` (info and above).
template <typename Run>
std::string CaptureLog(const Run& run) {
  std::ostringstream log;
  const auto previous = spdlog::default_logger();
  spdlog::set_default_logger(std::make_shared<spdlog::logger>(
      "test", std::make_shared<spdlog::sinks::ostream_sink_mt>(log)));
  run();
  spdlog::set_default_logger(previous);
  return log.str();
}

// Models handed over smallest first, a stale reason for an image in a model, an image in
// none without a reason: sorted, one self-check each, every reason right.
TEST(ModelFinishing, OrdersChecksAndGivesEveryLeftOutImageAReason) {
  SyntheticSceneOptions scene_options;
  scene_options.num_images = 20;
  const SyntheticScene scene = MakeSyntheticScene(scene_options);
  MapperResult result;
  result.models = {Poses(scene, 1, 6), Poses(scene, 7, 18)};
  result.unregistered_reasons[3] = "stale";
  result.unregistered_reasons[19] = "the mapper's own reason";
  FinishModels(scene.input, testing::CeresAdjusterOnOneThread(), ModelFinishingOptions(), 0,
               &result);
  ASSERT_EQ(result.models.size(), 2u);
  EXPECT_EQ(result.models[0].images.size(), 12u);
  EXPECT_EQ(result.models[1].images.size(), 6u);
  ASSERT_EQ(result.self_checks.size(), 2u);
  for (const ModelSelfCheck& check : result.self_checks) {
    EXPECT_FALSE(check.possibly_folded);
    EXPECT_GT(check.num_pairs, 0u);
    EXPECT_GT(check.agreement, 0.99);
  }
  EXPECT_TRUE(result.georeferences.empty());  // no use_gps_prior
  EXPECT_EQ(result.unregistered_reasons.count(3), 0u);
  EXPECT_EQ(result.unregistered_reasons.at(19), "the mapper's own reason");
  EXPECT_EQ(result.unregistered_reasons.at(20), "in no model");
  EXPECT_EQ(result.unregistered_reasons.size(), 2u);
}

// 24 views on an arc, merged right, and merged with every other run of 3 views turned by
// 180 degrees about the vertical, as a cluster folded by a symmetric object joins views
// of both sides: the check passes the first and flags the second, and says so.
TEST(ModelFinishing, FlagsAModelJoinedWrongly) {
  SyntheticSceneOptions options;
  options.num_images = 24;
  options.arc_deg = 200;
  options.max_pair_gap = 4;
  options.seed = 3;
  const SyntheticScene scene = MakeSyntheticScene(options);
  MapperResult result;
  result.models = {Poses(scene), Poses(scene)};
  const Eigen::Quaterniond turn(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()));
  for (auto& [image_id, image] : result.models[1].images) {
    if ((image_id - 1) / 3 % 2 == 1) {
      image.cam_from_world.rotation = image.cam_from_world.rotation * turn;
    }
  }
  ModelFinishingOptions finishing;
  finishing.log_prefix = "merge";
  const std::string log = CaptureLog([&] {
    FinishModels(scene.input, testing::CeresAdjusterOnOneThread(), finishing, 0, &result);
  });
  const std::vector<ModelSelfCheck>& checks = result.self_checks;
  ASSERT_EQ(checks.size(), 2u);
  EXPECT_FALSE(checks[0].possibly_folded);
  EXPECT_GT(checks[0].agreement, 0.99);
  EXPECT_EQ(checks[0].num_pairs, scene.input.pairs.size());
  EXPECT_TRUE(checks[1].possibly_folded);
  EXPECT_LT(checks[1].agreement, kMinModelAgreement);
  EXPECT_NE(log.find("merge: model 1 may be folded"), std::string::npos) << log;
}

TEST(ModelFinishing, ReadsTheSharedOptionsNamingTheField) {
  const ModelFinishingOptions read = ModelFinishingOptions::FromJson({{"use_gps_prior", true},
                                                                      {"gps_horizontal_sigma", 0.5},
                                                                      {"min_model_agreement", 0.6},
                                                                      {"other", 1}},
                                                                     "pipeline.mapper.options");
  EXPECT_TRUE(read.use_gps_prior);
  EXPECT_EQ(read.gps.horizontal_sigma_m, 0.5);
  EXPECT_EQ(read.min_model_agreement, 0.6);
  EXPECT_EQ(ModelFinishingOptions().min_model_agreement, kMinModelAgreement);
  try {
    ModelFinishingOptions::FromJson({{"gps_horizontal_sigma", 0}}, "pipeline.mapper.options");
    FAIL() << "a sigma of 0 was accepted";
  } catch (const OptionError& error) {
    EXPECT_NE(std::string(error.what()).find("pipeline.mapper.options.gps_horizontal_sigma"),
              std::string::npos)
        << error.what();
  }
}

constexpr double kMetresPerUnit = 40;

// Each image tagged with its true centre, scaled to metres, east-north-up about `origin`.
std::map<image_t, Eigen::Vector3d> Geotag(const Georeference& origin, SyntheticScene* scene) {
  std::map<image_t, Eigen::Vector3d> enu;
  for (const auto& [image_id, pose] : scene->true_cam_from_world) {
    enu[image_id] = kMetresPerUnit * pose.Inverse().translation;
    scene->input.metadata[image_id].gps = Wgs84FromEnu(enu[image_id], origin);
  }
  return enu;
}

// Two phones without a fix (0, 0, 0), an altitude of -1e9 m and a tag 50 km away among
// 12 images: each set aside with a warning naming the image, the origin at the good tags'
// median, the centres at their tags, the coordinates local.
TEST(GpsAnchoring, SetsAsideImpossibleTagsAndTakesTheOriginFromTheAgreeingOnes) {
  SyntheticScene scene = MakeSyntheticScene(SyntheticSceneOptions());
  Georeference truth;
  truth.latitude_deg = 46.52;
  truth.longitude_deg = 6.57;
  truth.altitude_m = 400;
  const std::map<image_t, Eigen::Vector3d> true_enu = Geotag(truth, &scene);
  const std::set<image_t> bad = {2, 5, 8, 11};
  scene.input.metadata[2].gps = GpsPosition{0, 0, 0.0};
  scene.input.metadata[5].gps = GpsPosition{0, 0, 0.0};
  scene.input.metadata[8].gps->altitude_m = -1e9;
  scene.input.metadata[11].gps = Wgs84FromEnu(true_enu.at(11) + Eigen::Vector3d(5e4, 0, 0), truth);
  IncrementalMapperOptions options;
  options.use_gps_prior = true;
  options.gps_horizontal_sigma = 0.5;
  options.gps_vertical_sigma = 0.5;
  MapperResult result;
  const std::string log = CaptureLog([&] {
    result = IncrementalPipeline(options, testing::CeresAdjusterOnOneThread(), 0)
                 .Reconstruct(scene.input);
  });
  for (const image_t image_id : bad) {
    EXPECT_NE(log.find("image '" + scene.input.images.at(image_id).name + "': its GPS tag"),
              std::string::npos)
        << log;
  }
  EXPECT_NE(log.find("0.0000000, 0.0000000, 0 m is set aside: 0, 0 (null island"),
            std::string::npos)
      << log;
  EXPECT_NE(log.find("-1e+09 m is set aside: altitude -1e+09 m is below -500 m"), std::string::npos)
      << log;
  EXPECT_NE(log.find("from the median of the model's tags"), std::string::npos) << log;
  ASSERT_EQ(result.models.size(), 1u);
  ASSERT_EQ(result.georeferences.size(), 1u);
  ASSERT_TRUE(result.georeferences[0].has_value()) << log;
  const Georeference& frame = *result.georeferences[0];
  // The good tags' median position, in the model's frame: its origin (the good tags span
  // 400 m; the bad ones lie 5,000 km to 1e9 m away).
  std::vector<double> east, north, up;
  for (const auto& [image_id, enu] : true_enu) {
    if (bad.count(image_id) > 0) continue;
    const Eigen::Vector3d in_frame = EnuFromWgs84(*scene.input.metadata.at(image_id).gps, frame);
    east.push_back(in_frame.x()), north.push_back(in_frame.y()), up.push_back(in_frame.z());
  }
  const auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  const Eigen::Vector3d median_tag(median(east), median(north), median(up));
  EXPECT_LT(median_tag.norm(), 0.05) << median_tag.transpose();
  // Every camera, those with bad tags too, where its true position is.
  for (const auto& [image_id, image] : result.models[0].images) {
    const Eigen::Vector3d where = EnuFromWgs84(Wgs84FromEnu(true_enu.at(image_id), truth), frame);
    EXPECT_LT((image.ProjectionCenter() - where).norm(), 1.0) << image.name;
    EXPECT_LT(image.ProjectionCenter().norm(), 1000.0) << image.name;
  }
  for (const auto& [point3D_id, point3D] : result.models[0].points3D) {
    ASSERT_LT(point3D.xyz.norm(), 2000.0);
  }
  // What `eval --no-align` reads back.
  const std::filesystem::path dir =
      std::filesystem::path(::testing::TempDir()) / "model_finishing_georeference";
  WriteGeoreference(frame, dir);
  const std::optional<Georeference> read = ReadGeoreference(dir);
  ASSERT_TRUE(read.has_value());
  EXPECT_EQ(read->altitude_m, frame.altitude_m);
  std::filesystem::remove_all(dir);
}

// Every tag at one point: said so, not "on a line".
TEST(GpsAnchoring, TagsAtOnePointAreSaidToBe) {
  SyntheticScene scene = MakeSyntheticScene(SyntheticSceneOptions());
  for (const auto& [image_id, image] : scene.input.images) {
    scene.input.metadata[image_id].gps = GpsPosition{46.52, 6.57, 400.0};
  }
  Reconstruction model = Poses(scene);
  const GpsAnchoringReport report = AnchorModelToGps(
      scene.input.metadata, testing::CeresAdjusterOnOneThread(), GpsAnchoringOptions(), 0, &model);
  EXPECT_FALSE(report.anchored);
  EXPECT_EQ(report.reason,
            "the GPS positions of its 12 geotagged images are all at one point (within the GPS "
            "noise)");
}

}  // namespace
}  // namespace tessera
