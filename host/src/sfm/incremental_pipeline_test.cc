#include "tessera/sfm/incremental_pipeline.h"

#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include <memory>
#include <set>
#include <sstream>

#include "eval/evaluation.h"
#include "geometry/essential_matrix.h"
#include "synthetic_scene.h"
#include "tessera/errors.h"
#include "tessera/io/model_statistics.h"
#include "tessera/sfm/first_model_calibration.h"
#include "tessera/sfm/gps_anchoring.h"
#include "test_support.h"

namespace tessera {
namespace {

using testing::MakeSyntheticScene;
using testing::SyntheticScene;
using testing::SyntheticSceneOptions;

MapperResult Map(const SyntheticScene& scene, IncrementalMapperOptions options = {},
                 uint64_t seed = 0) {
  return IncrementalPipeline(options, testing::CeresAdjusterOnOneThread(), seed)
      .Reconstruct(scene.input);
}

// Every observation of every point is a keypoint of one and the same true point.
void ExpectTracksAreTrue(const SyntheticScene& scene, const Reconstruction& model) {
  size_t num_wrong = 0;
  for (const auto& [point3D_id, point3D] : model.points3D) {
    std::set<int> true_points;
    for (const TrackElement& element : point3D.track) {
      true_points.insert(scene.true_point_of_keypoint.at(element.image_id)[element.point2D_idx]);
    }
    if (true_points.size() != 1 || *true_points.begin() < 0) ++num_wrong;
  }
  EXPECT_EQ(num_wrong, 0u) << "points whose track mixes true points or clutter";
}

TEST(IncrementalPipeline, RecoversASyntheticSceneWithNoise) {
  SyntheticSceneOptions options;
  const SyntheticScene scene = MakeSyntheticScene(options);
  const MapperResult result = Map(scene);
  ASSERT_EQ(result.models.size(), 1u);
  const Reconstruction& model = result.models[0];
  EXPECT_EQ(model.images.size(), scene.input.images.size());
  EXPECT_TRUE(result.unregistered_reasons.empty());
  const EvaluationResult evaluation = EvaluateReconstruction(model, scene.GroundTruth());
  ASSERT_TRUE(evaluation.aligned) << evaluation.error;
  // 0.5 px noise at 1000 px focal length and 10 units distance: 5e-3 units per pixel of
  // error along the image plane; the cameras end up within a fraction of that.
  EXPECT_LT(evaluation.position_error_max, 0.01);
  EXPECT_LT(evaluation.rotation_error_max_deg, 0.05);
  EXPECT_LT(ComputeModelStatistics(model).mean_reprojection_error, 0.8);
  EXPECT_GT(model.points3D.size(), 0.9 * options.num_points);
  ExpectTracksAreTrue(scene, model);
}

TEST(IncrementalPipeline, FiltersTwoPercentOutlierMatches) {
  SyntheticSceneOptions options;
  options.outlier_ratio = 0.02;
  options.seed = 2;
  const SyntheticScene scene = MakeSyntheticScene(options);
  ASSERT_GT(scene.num_outlier_matches, 100u);
  // Thresholds at 4 sigma of the 0.5 px keypoint noise. With the default 4 px (8 sigma)
  // an outlier match that happens to lie within a few pixels of its epipolar line and is
  // seen by no third image is indistinguishable from a true two-view point, and whether
  // one survives depends on when bundle adjustment stops.
  IncrementalMapperOptions mapper_options;
  mapper_options.tri_max_error = 4 * options.noise_px;
  mapper_options.filter_max_reproj_error = 4 * options.noise_px;
  const MapperResult result = Map(scene, mapper_options);
  ASSERT_EQ(result.models.size(), 1u);
  const Reconstruction& model = result.models[0];
  EXPECT_EQ(model.images.size(), scene.input.images.size());
  ExpectTracksAreTrue(scene, model);
  const EvaluationResult evaluation = EvaluateReconstruction(model, scene.GroundTruth());
  ASSERT_TRUE(evaluation.aligned) << evaluation.error;
  EXPECT_LT(evaluation.position_error_max, 0.01);
  EXPECT_LT(ComputeModelStatistics(model).mean_reprojection_error, 0.8);
  EXPECT_GT(result.num_refused_matches, 0u);
}

TEST(IncrementalPipeline, RefinesAWrongFocalLengthPriorAndDistortion) {
  SyntheticSceneOptions options;
  options.k1 = -0.05;
  options.prior_focal_factor = 1.1;
  options.seed = 3;
  const SyntheticScene scene = MakeSyntheticScene(options);
  const MapperResult result = Map(scene);
  ASSERT_EQ(result.models.size(), 1u);
  const Reconstruction& model = result.models[0];
  EXPECT_EQ(model.images.size(), scene.input.images.size());
  const Camera& camera = model.cameras.at(1);
  EXPECT_NEAR(camera.FocalLengthX(), options.focal_length, 0.005 * options.focal_length);
  EXPECT_NEAR(camera.params[3], options.k1, 0.005);
  const EvaluationResult evaluation = EvaluateReconstruction(model, scene.GroundTruth());
  EXPECT_LT(evaluation.position_error_max, 0.02);
}

TEST(IncrementalPipeline, RefinesAnOffCentrePrincipalPointWhenAsked) {
  SyntheticSceneOptions options;
  // 1.5% of the width, as Strecha's cameras. Horizontally only: the cameras stand on a
  // level arc, and a vertical offset is all but the same as tilting every one of them.
  options.principal_point_offset_x = 24;
  options.seed = 8;
  const SyntheticScene scene = MakeSyntheticScene(options);
  const double centre_x = 0.5 * options.width, centre_y = 0.5 * options.height;

  // Held at the centre (the default), the principal point stays there.
  const MapperResult held = Map(scene);
  ASSERT_EQ(held.models.size(), 1u);
  EXPECT_EQ(held.models[0].cameras.at(1).PrincipalPointX(), centre_x);
  EXPECT_EQ(held.models[0].cameras.at(1).PrincipalPointY(), centre_y);

  IncrementalMapperOptions mapper_options;
  mapper_options.ba_refine_principal_point = true;
  const MapperResult refined = Map(scene, mapper_options);
  ASSERT_EQ(refined.models.size(), 1u);
  const Camera& camera = refined.models[0].cameras.at(1);
  EXPECT_NEAR(camera.PrincipalPointX(), centre_x + options.principal_point_offset_x, 2.0);
  EXPECT_NEAR(camera.PrincipalPointY(), centre_y, 2.0);

  // And the cameras are where they truly are, better than with the point held.
  const EvaluationResult held_error = EvaluateReconstruction(held.models[0], scene.GroundTruth());
  const EvaluationResult refined_error =
      EvaluateReconstruction(refined.models[0], scene.GroundTruth());
  ASSERT_TRUE(held_error.aligned && refined_error.aligned);
  EXPECT_LT(refined_error.position_error_mean, 0.5 * held_error.position_error_mean);
}

TEST(IncrementalPipeline, AnImplausiblePrincipalPointIsPutBackAtTheCentre) {
  // The true principal point is 15% of the width off centre: beyond the plausible 10%,
  // so the refined one is reset and held at the centre, as if it was never refined.
  SyntheticSceneOptions options;
  options.principal_point_offset_x = 0.15 * options.width;
  options.seed = 9;
  const SyntheticScene scene = MakeSyntheticScene(options);
  IncrementalMapperOptions mapper_options;
  mapper_options.ba_refine_principal_point = true;
  const MapperResult result = Map(scene, mapper_options);
  ASSERT_FALSE(result.models.empty());
  const Camera& camera = result.models[0].cameras.at(1);
  EXPECT_EQ(camera.PrincipalPointX(), 0.5 * options.width);
  EXPECT_EQ(camera.PrincipalPointY(), 0.5 * options.height);
}

TEST(IncrementalPipeline, DisconnectedGroupsBecomeSeparateModelsLargestFirst) {
  // Two scenes of 5 and 8 images with no match between them: ids 1-5 and 6-13.
  SyntheticSceneOptions small_options;
  small_options.num_images = 5;
  small_options.seed = 4;
  SyntheticSceneOptions large_options;
  large_options.num_images = 8;
  large_options.seed = 5;
  SyntheticScene scene = MakeSyntheticScene(small_options);
  testing::AppendScene(MakeSyntheticScene(large_options), 5, "large_", 1, &scene);
  // And one image that matches nothing.
  Image lonely = scene.input.images.at(1);
  lonely.image_id = 100;
  lonely.name = "lonely.png";
  scene.input.images[100] = lonely;

  const MapperResult result = Map(scene);
  ASSERT_EQ(result.models.size(), 2u);
  EXPECT_EQ(result.models[0].images.size(), 8u);
  EXPECT_EQ(result.models[1].images.size(), 5u);
  EXPECT_EQ(result.models[0].images.begin()->first, 6u);
  ASSERT_EQ(result.unregistered_reasons.size(), 1u);
  EXPECT_EQ(result.unregistered_reasons.at(100),
            "no verified pair with at least 15 inlier matches");

  IncrementalMapperOptions single;
  single.multiple_models = false;
  EXPECT_EQ(Map(scene, single).models.size(), 1u);
}

// No image of `model` is more than `max_deg` off its true orientation, once aligned.
void ExpectNoCameraOff(const SyntheticScene& scene, const Reconstruction& model, double max_deg) {
  const EvaluationResult evaluation = EvaluateReconstruction(model, scene.GroundTruth());
  ASSERT_TRUE(evaluation.aligned) << evaluation.error;
  for (const ImageEvaluation& row : evaluation.images) {
    if (row.registered) {
      EXPECT_LT(row.rotation_error_deg, max_deg) << row.name;
    }
  }
}

TEST(IncrementalPipeline, EstimatesTheFocalLengthWhenThereIsNoPrior) {
  SyntheticSceneOptions options;
  options.focal_prior = false;
  options.prior_focal_factor = 1.6;  // far off: 1.2 x 1600 px against 1000 px
  options.seed = 11;
  const SyntheticScene scene = MakeSyntheticScene(options);
  const MapperResult result = Map(scene);
  ASSERT_EQ(result.focal_lengths.size(), 1u);
  EXPECT_NEAR(result.focal_lengths[0].estimated, options.focal_length, 0.02 * options.focal_length);
  ASSERT_EQ(result.models.size(), 1u);
  EXPECT_EQ(result.models[0].images.size(), scene.input.images.size());
  EXPECT_NEAR(result.models[0].cameras.at(1).FocalLengthX(), options.focal_length,
              0.005 * options.focal_length);
  ExpectNoCameraOff(scene, result.models[0], 0.1);
}

// Two unrelated scenes, each with its own camera (1 and 2, true focal lengths 1000 and
// 1400 px) and no prior, their starting focal lengths off by `factor1` and `factor2`
// (SyntheticSceneOptions::prior_focal_factor): a folder that mixes two captures.
SyntheticScene TwoScenesWithoutFocalPrior(double factor1, double factor2,
                                          SyntheticSceneOptions* first,
                                          SyntheticSceneOptions* second) {
  first->focal_prior = false;
  first->prior_focal_factor = factor1;
  first->seed = 11;
  *second = *first;
  second->focal_length = 1400;
  second->prior_focal_factor = factor2;
  second->seed = 13;
  SyntheticScene scene = MakeSyntheticScene(*first);
  testing::AppendScene(MakeSyntheticScene(*second), 100, "second_", 2, &scene);
  return scene;
}

TEST(IncrementalPipeline, EstimatesTheFocalLengthOfEachSceneInAMixedSet) {
  // Where the pairs determine a camera's focal length (many pairs) mapping starts from
  // it; with min_view_graph_focal_pairs 0 every camera is refined in a first model, and a
  // first model holds one scene only, so the other camera needs a first model of its
  // own. Both end at the true focal lengths.
  SyntheticSceneOptions first, second;
  const SyntheticScene scene = TwoScenesWithoutFocalPrior(1.6, 0.7, &first, &second);
  for (const int min_pairs : {10, 0}) {
    SCOPED_TRACE("min_view_graph_focal_pairs " + std::to_string(min_pairs));
    IncrementalMapperOptions options;
    options.min_view_graph_focal_pairs = min_pairs;
    const MapperResult result = Map(scene, options);
    ASSERT_EQ(result.focal_lengths.size(), 2u);
    for (const FocalLengthReport& report : result.focal_lengths) {
      const double truth = report.camera_id == 1 ? first.focal_length : second.focal_length;
      EXPECT_NEAR(report.estimated, truth, 0.02 * truth) << "camera " << report.camera_id;
      if (min_pairs == 0) {
        EXPECT_GE(report.num_images, 5u) << "camera " << report.camera_id << ": " << report.method;
      } else {
        EXPECT_EQ(report.method, "view graph") << "camera " << report.camera_id;
        EXPECT_GE(report.num_pairs, 10u) << "camera " << report.camera_id;
        EXPECT_EQ(report.num_images, 0u) << "camera " << report.camera_id;
      }
    }
    ASSERT_EQ(result.models.size(), 2u);
    for (const Reconstruction& model : result.models) {
      EXPECT_EQ(model.images.size(), 12u);
      const Camera& camera = model.cameras.begin()->second;
      const double truth = camera.camera_id == 1 ? first.focal_length : second.focal_length;
      EXPECT_NEAR(camera.FocalLengthX(), truth, 0.005 * truth);
    }
  }
}

// The building block both mappers calibrate with: a first model of at most 20 images
// refines the focal length of the cameras asked for, here each scene's own.
TEST(FirstModelCalibration, RefinesTheFocalLengthOfEachCameraAskedFor) {
  SyntheticSceneOptions first, second;
  const SyntheticScene scene = TwoScenesWithoutFocalPrior(1.3, 0.9, &first, &second);
  std::vector<const MapperInput::Pair*> pairs;
  for (const MapperInput::Pair& pair : scene.input.pairs) pairs.push_back(&pair);
  MapperRunState run(scene.input, testing::CeresAdjusterOnOneThread(), 7);
  const std::map<camera_t, FirstModelFocalLength> refined =
      FocalLengthsFromFirstModels(IncrementalMapperOptions(), run, {1, 2}, pairs);
  ASSERT_EQ(refined.size(), 2u);
  EXPECT_NEAR(refined.at(1).focal_length, first.focal_length, 0.02 * first.focal_length);
  EXPECT_NEAR(refined.at(2).focal_length, second.focal_length, 0.02 * second.focal_length);
  EXPECT_GE(refined.at(1).num_images, kMinFirstModelImages);
  EXPECT_LE(refined.at(1).num_images, kMaxFirstModelImages);
  // Only the cameras asked for.
  EXPECT_EQ(FocalLengthsFromFirstModels(IncrementalMapperOptions(), run, {2}, pairs).count(1), 0u);
}

// The options of a scene of `num_images` whose one camera has no focal-length prior and
// starts 1.3 times off.
SyntheticSceneOptions WithoutFocalPrior(int num_images, uint64_t seed) {
  SyntheticSceneOptions options;
  options.num_images = num_images;
  options.focal_prior = false;
  options.prior_focal_factor = 1.3;
  options.seed = seed;
  return options;
}

// What first models from every pair of `scene` give camera 1.
std::map<camera_t, FirstModelFocalLength> FirstModelOfCamera1(const SyntheticScene& scene) {
  std::vector<const MapperInput::Pair*> pairs;
  for (const MapperInput::Pair& pair : scene.input.pairs) pairs.push_back(&pair);
  MapperRunState run(scene.input, testing::CeresAdjusterOnOneThread(), 7);
  return FocalLengthsFromFirstModels(IncrementalMapperOptions(), run, {1}, pairs);
}

// A first model stops growing once its focal length has settled: on 30 images it needs
// far fewer than kMaxFirstModelImages to land within 2% of the truth.
TEST(FirstModelCalibration, StopsGrowingOnceTheFocalLengthSettles) {
  const SyntheticSceneOptions options = WithoutFocalPrior(30, 11);
  const std::map<camera_t, FirstModelFocalLength> refined =
      FirstModelOfCamera1(MakeSyntheticScene(options));
  ASSERT_EQ(refined.count(1), 1u);
  EXPECT_NEAR(refined.at(1).focal_length, options.focal_length, 0.02 * options.focal_length);
  EXPECT_GE(refined.at(1).num_images, kMinFirstModelImages);
  EXPECT_LT(refined.at(1).num_images, kMaxFirstModelImages - 5);
}

// Weak pairs (a few of the inliers their images have with their best neighbours) are
// left out of a first model: it maps the same with them as without them, even when their
// matches are wrong.
TEST(FirstModelCalibration, WeakPairsDoNotChangeTheFirstModel) {
  const SyntheticSceneOptions options = WithoutFocalPrior(20, 5);
  SyntheticScene with_weak = MakeSyntheticScene(options);
  SyntheticScene without_weak = with_weak;
  std::vector<MapperInput::Pair> kept;
  size_t num_weakened = 0;
  for (size_t k = 0; k < with_weak.input.pairs.size(); ++k) {
    if (k % 3 != 1) {
      kept.push_back(with_weak.input.pairs[k]);
      continue;
    }
    // 16 wrong matches, as repeated texture gives: each feature with another's partner.
    std::vector<FeatureMatch>& inliers = with_weak.input.pairs[k].geometry.inlier_matches;
    ASSERT_GT(inliers.size(), 100u);
    std::vector<FeatureMatch> wrong(16);
    for (size_t i = 0; i < wrong.size(); ++i) {
      wrong[i].point2D_idx1 = inliers[i].point2D_idx1;
      wrong[i].point2D_idx2 = inliers[(i + 1) % wrong.size()].point2D_idx2;
    }
    inliers = wrong;
    ++num_weakened;
  }
  without_weak.input.pairs = kept;
  ASSERT_GT(num_weakened, 20u);
  // Its view graph (logged at debug level) holds the strong pairs alone.
  std::ostringstream log;
  const auto previous = spdlog::default_logger();
  spdlog::set_default_logger(std::make_shared<spdlog::logger>(
      "test", std::make_shared<spdlog::sinks::ostream_sink_mt>(log)));
  const spdlog::level::level_enum level = spdlog::get_level();
  spdlog::set_level(spdlog::level::debug);
  const std::map<camera_t, FirstModelFocalLength> refined = FirstModelOfCamera1(with_weak);
  spdlog::set_default_logger(previous);
  spdlog::set_level(level);
  EXPECT_NE(log.str().find(" of " + std::to_string(kept.size()) + " verified pairs dropped"),
            std::string::npos)
      << log.str().substr(0, 2000);
  const std::map<camera_t, FirstModelFocalLength> expected = FirstModelOfCamera1(without_weak);
  ASSERT_EQ(refined.count(1), 1u);
  ASSERT_EQ(expected.count(1), 1u);
  EXPECT_EQ(refined.at(1).focal_length, expected.at(1).focal_length);
  EXPECT_EQ(refined.at(1).num_images, expected.at(1).num_images);
  EXPECT_NEAR(refined.at(1).focal_length, options.focal_length, 0.02 * options.focal_length);
}

// GPS for each image of `scene`: its true centre, scaled to metres, in an east-north-up
// frame at `origin`, plus noise; `shuffle` hands each image another's position.
void Geotag(SyntheticScene* scene, const Georeference& origin, double metres_per_unit,
            double horizontal_noise_m, double vertical_noise_m, bool shuffle,
            std::map<image_t, Eigen::Vector3d>* true_enu) {
  RandomEngine engine(3);
  std::normal_distribution<double> horizontal(0, horizontal_noise_m), vertical(0, vertical_noise_m);
  std::vector<image_t> ids;
  for (const auto& [image_id, pose] : scene->true_cam_from_world) ids.push_back(image_id);
  std::vector<image_t> sources = ids;
  if (shuffle) std::rotate(sources.begin(), sources.begin() + sources.size() / 2, sources.end());
  for (size_t k = 0; k < ids.size(); ++k) {
    const Eigen::Vector3d enu =
        metres_per_unit * scene->true_cam_from_world.at(sources[k]).Inverse().translation;
    (*true_enu)[ids[k]] =
        metres_per_unit * scene->true_cam_from_world.at(ids[k]).Inverse().translation;
    const Eigen::Vector3d noisy =
        enu + Eigen::Vector3d(horizontal(engine), horizontal(engine), vertical(engine));
    scene->input.metadata[ids[k]].gps = Wgs84FromEnu(noisy, origin);
  }
}

TEST(IncrementalPipeline, AnchorsTheModelToItsImagesGpsInEastNorthUpMetres) {
  SyntheticScene scene = MakeSyntheticScene(SyntheticSceneOptions());
  Georeference origin;
  origin.latitude_deg = 47.3;
  origin.longitude_deg = 8.5;
  origin.altitude_m = 410;
  std::map<image_t, Eigen::Vector3d> true_enu;
  Geotag(&scene, origin, 40.0, 0.5, 1.0, /*shuffle=*/false, &true_enu);
  IncrementalMapperOptions options;
  options.use_gps_prior = true;
  options.gps_horizontal_sigma = 0.5;
  options.gps_vertical_sigma = 1.0;
  const MapperResult result = Map(scene, options);
  ASSERT_EQ(result.models.size(), 1u);
  ASSERT_EQ(result.georeferences.size(), 1u);
  ASSERT_TRUE(result.georeferences[0].has_value());
  const Georeference& frame = *result.georeferences[0];
  // Without any alignment: each centre where its true position is in the model's frame,
  // within the GPS noise.
  double sum = 0;
  size_t n = 0;
  for (const auto& [image_id, image] : result.models[0].images) {
    const Eigen::Vector3d truth = EnuFromWgs84(Wgs84FromEnu(true_enu.at(image_id), origin), frame);
    const double error = (image.ProjectionCenter() - truth).norm();
    EXPECT_LT(error, 2.0) << image.name;
    sum += error;
    ++n;
  }
  EXPECT_EQ(n, scene.input.images.size());
  EXPECT_LT(sum / n, 1.0);
  // WGS84 and back: well below a millimetre.
  const Eigen::Vector3d point(1234.5, -987.6, 55.5);
  EXPECT_LT((EnuFromWgs84(Wgs84FromEnu(point, origin), origin) - point).norm(), 1e-6);
}

TEST(IncrementalPipeline, GpsThatContradictsTheModelLeavesItInItsOwnFrame) {
  SyntheticScene scene = MakeSyntheticScene(SyntheticSceneOptions());
  Georeference origin;
  origin.latitude_deg = -33.9;
  origin.longitude_deg = 151.2;
  std::map<image_t, Eigen::Vector3d> true_enu;
  Geotag(&scene, origin, 40.0, 0.5, 1.0, /*shuffle=*/true, &true_enu);
  IncrementalMapperOptions options;
  options.use_gps_prior = true;
  options.gps_horizontal_sigma = 0.5;
  options.gps_vertical_sigma = 1.0;
  const MapperResult unanchored = Map(scene, options);
  options.use_gps_prior = false;
  const MapperResult plain = Map(scene, options);
  ASSERT_EQ(unanchored.models.size(), 1u);
  ASSERT_EQ(unanchored.georeferences.size(), 1u);
  EXPECT_FALSE(unanchored.georeferences[0].has_value());
  // The model as mapping left it.
  for (const auto& [image_id, image] : plain.models[0].images) {
    EXPECT_EQ(unanchored.models[0].images.at(image_id).cam_from_world.translation,
              image.cam_from_world.translation);
  }
  // Too few geotagged images: the same.
  SyntheticScene few = MakeSyntheticScene(SyntheticSceneOptions());
  Geotag(&few, origin, 40.0, 0.5, 1.0, false, &true_enu);
  while (few.input.metadata.size() > 2) few.input.metadata.erase(few.input.metadata.begin());
  options.use_gps_prior = true;
  const MapperResult result = Map(few, options);
  ASSERT_EQ(result.georeferences.size(), 1u);
  EXPECT_FALSE(result.georeferences[0].has_value());
}

// An object seen from all around whose back half repeats its front half turned by half a
// turn: pairs of images from nearly opposite sides match on the repeated half, and a
// model that puts one side's cameras onto the other explains those matches exactly.
SyntheticSceneOptions SymmetricObject() {
  SyntheticSceneOptions options;
  options.num_images = 36;
  options.arc_deg = 350;
  options.num_points = 3000;
  options.max_view_angle_deg = 60;
  options.symmetric_fraction = 0.3;
  options.seed = 12;
  return options;
}

TEST(IncrementalPipeline, DoesNotFoldASymmetricObject) {
  const SyntheticScene scene = MakeSyntheticScene(SymmetricObject());
  ASSERT_GT(scene.num_mirror_pairs, 50u);
  const MapperResult result = Map(scene);
  ASSERT_EQ(result.models.size(), 1u);
  EXPECT_EQ(result.models[0].images.size(), scene.input.images.size());
  ExpectNoCameraOff(scene, result.models[0], 5);
  ASSERT_EQ(result.self_checks.size(), 1u);
  EXPECT_FALSE(result.self_checks[0].possibly_folded);
}

TEST(IncrementalPipeline, FlagsAFoldedModel) {
  // Without the view graph, the symmetric object folds; the self-check says so.
  const SyntheticScene scene = MakeSyntheticScene(SymmetricObject());
  IncrementalMapperOptions unchecked;
  unchecked.filter_view_graph = false;
  unchecked.check_registration = false;
  const MapperResult result = Map(scene, unchecked);
  ASSERT_FALSE(result.models.empty());
  const EvaluationResult evaluation = EvaluateReconstruction(result.models[0], scene.GroundTruth());
  ASSERT_TRUE(evaluation.aligned);
  EXPECT_GT(evaluation.num_wrongly_registered, 0u);
  EXPECT_GT(evaluation.rotation_error_max_deg, 90);
  EXPECT_TRUE(result.self_checks[0].possibly_folded);
  EXPECT_FALSE(result.self_checks[0].disagreeing_images.empty());
}

// Gives the pairs of `image_id` with every image more than one position away on the arc
// a wrong relative rotation (their E): the true one turned by 40 degrees about an axis
// that differs per pair (`scattered`), or the one a pose of the image turned by 40
// degrees about the vertical would give (one wrong rotation that they all agree on).
void CorruptRotationsOfPairs(image_t image_id, bool scattered, SyntheticScene* scene) {
  const std::vector<Eigen::Vector3d> axes = {{1, 0, 0},  {0, 1, 0}, {0, 0, 1},  {1, 1, 0},
                                             {1, -1, 0}, {0, 1, 1}, {0, 1, -1}, {1, 0, 1},
                                             {1, 0, -1}, {1, 1, 1}, {-1, 1, 1}};
  const Eigen::Matrix3d turn =
      Eigen::AngleAxisd(40 * M_PI / 180, Eigen::Vector3d::UnitY()).toRotationMatrix();
  size_t k = 0;
  for (MapperInput::Pair& pair : scene->input.pairs) {
    if (pair.image_id1 != image_id && pair.image_id2 != image_id) continue;
    const image_t other = pair.image_id1 == image_id ? pair.image_id2 : pair.image_id1;
    if (std::abs(static_cast<int>(other) - static_cast<int>(image_id)) <= 1) continue;
    const Eigen::Matrix3d R1 =
        scene->true_cam_from_world.at(pair.image_id1).rotation.toRotationMatrix();
    const Eigen::Matrix3d R2 =
        scene->true_cam_from_world.at(pair.image_id2).rotation.toRotationMatrix();
    Eigen::Matrix3d R_cam2_from_cam1;
    if (scattered) {
      const Eigen::Matrix3d wrong =
          Eigen::AngleAxisd(40 * M_PI / 180, axes[k++ % axes.size()].normalized())
              .toRotationMatrix();
      R_cam2_from_cam1 = wrong * R2 * R1.transpose();
    } else if (pair.image_id1 == image_id) {
      R_cam2_from_cam1 = R2 * (turn * R1).transpose();
    } else {
      R_cam2_from_cam1 = turn * R2 * R1.transpose();
    }
    Rigid3d cam2_from_cam1 = pair.geometry.cam2_from_cam1;
    cam2_from_cam1.rotation = Eigen::Quaterniond(R_cam2_from_cam1);
    pair.geometry.E = EssentialMatrixFromPose(cam2_from_cam1);
  }
}

TEST(IncrementalPipeline, KeepsAnImageWhosePairsDisagreeWithoutAnAlternative) {
  // Where the scene barely constrains two-view rotations (a small object filmed with a
  // narrow field of view, a near-planar scene), many pairs give a wrong one, each wrong
  // in its own way: that is no fold, and the image's pose is kept. Pairs that agree on
  // one other rotation are the sign of a fold, and the pose is refused.
  SyntheticSceneOptions options;
  options.seed = 14;
  const image_t image_id = 6;
  IncrementalMapperOptions mapper_options;
  mapper_options.filter_view_graph = false;  // the registration check alone

  SyntheticScene scattered = MakeSyntheticScene(options);
  CorruptRotationsOfPairs(image_id, /*scattered=*/true, &scattered);
  const MapperResult kept = Map(scattered, mapper_options);
  ASSERT_EQ(kept.models.size(), 1u);
  EXPECT_EQ(kept.models[0].images.size(), scattered.input.images.size());
  EXPECT_EQ(kept.num_registrations_refused, 0u);
  ExpectNoCameraOff(scattered, kept.models[0], 0.5);

  SyntheticScene coherent = MakeSyntheticScene(options);
  CorruptRotationsOfPairs(image_id, /*scattered=*/false, &coherent);
  const MapperResult refused = Map(coherent, mapper_options);
  EXPECT_GT(refused.num_registrations_refused, 0u);
  ASSERT_FALSE(refused.models.empty());
  ExpectNoCameraOff(coherent, refused.models[0], 5);
}

TEST(IncrementalPipeline, MergesTwoModelsOfOneScene) {
  // Images 1-7 and 8-14 of an arc; across the cut only the pairs (6, 8), (7, 8) and
  // (7, 9) match, on 40 points each: fewer than a registration needs (100 here), so the
  // images split into two models, which share the tracks of those matches.
  SyntheticSceneOptions options;
  options.num_images = 14;
  options.max_pair_gap = 2;
  options.seed = 13;
  SyntheticScene scene = MakeSyntheticScene(options);
  for (MapperInput::Pair& pair : scene.input.pairs) {
    if (pair.image_id1 <= 7 && pair.image_id2 >= 8) pair.geometry.inlier_matches.resize(40);
  }
  IncrementalMapperOptions mapper_options;
  mapper_options.abs_pose_min_num_inliers = 100;
  IncrementalMapperOptions unmerged = mapper_options;
  unmerged.merge_models = false;
  const MapperResult split = Map(scene, unmerged);
  ASSERT_EQ(split.models.size(), 2u);
  EXPECT_EQ(split.models[0].images.size() + split.models[1].images.size(),
            scene.input.images.size());

  const MapperResult result = Map(scene, mapper_options);
  ASSERT_EQ(result.models.size(), 1u);
  EXPECT_EQ(result.models[0].images.size(), scene.input.images.size());
  ASSERT_EQ(result.merges.size(), 1u);
  EXPECT_NE(result.merges[0].find("merged"), std::string::npos) << result.merges[0];
  ExpectNoCameraOff(scene, result.models[0], 0.5);
  const EvaluationResult evaluation = EvaluateReconstruction(result.models[0], scene.GroundTruth());
  EXPECT_LT(evaluation.position_error_max, 0.05);
}

TEST(IncrementalPipeline, SameSeedSameModel) {
  SyntheticSceneOptions options;
  options.outlier_ratio = 0.02;
  options.num_images = 8;
  options.seed = 6;
  const SyntheticScene scene = MakeSyntheticScene(options);
  const MapperResult a = Map(scene, {}, 7);
  const MapperResult b = Map(scene, {}, 7);
  ASSERT_EQ(a.models.size(), 1u);
  ASSERT_EQ(b.models.size(), 1u);
  const Reconstruction& model_a = a.models[0];
  const Reconstruction& model_b = b.models[0];
  ASSERT_EQ(model_a.points3D.size(), model_b.points3D.size());
  for (const auto& [image_id, image] : model_a.images) {
    const Image& other = model_b.images.at(image_id);
    EXPECT_EQ(image.cam_from_world.translation, other.cam_from_world.translation);
    EXPECT_EQ(image.cam_from_world.rotation.coeffs(), other.cam_from_world.rotation.coeffs());
  }
  for (const auto& [point3D_id, point3D] : model_a.points3D) {
    EXPECT_EQ(point3D.xyz, model_b.points3D.at(point3D_id).xyz);
  }
}

// The adjuster the pipeline calls, recording spdlog's global level at each call.
class LevelRecordingAdjuster : public BundleAdjuster {
 public:
  BundleAdjustmentSummary Adjust(const BundleAdjustmentConfig& config,
                                 Reconstruction* model) const override {
    levels.insert(spdlog::get_level());
    return testing::CeresAdjusterOnOneThread().Adjust(config, model);
  }
  mutable std::set<spdlog::level::level_enum> levels;
};

// The first model mapped for the focal lengths logs its steps at debug, without
// touching the global level (the GUI logs beside a pipeline on a worker thread).
TEST(IncrementalPipeline, TheFirstModelLogsAtDebugWithoutChangingTheGlobalLevel) {
  SyntheticSceneOptions scene_options;
  scene_options.focal_prior = false;
  scene_options.num_images = 8;
  scene_options.seed = 11;
  const SyntheticScene scene = MakeSyntheticScene(scene_options);
  IncrementalMapperOptions options;
  options.min_view_graph_focal_pairs = 0;  // every camera gets a first model
  std::ostringstream log;
  const auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(log);
  sink->set_pattern("%l %v");
  const auto logger = spdlog::default_logger();
  const spdlog::level::level_enum previous = spdlog::get_level();
  logger->sinks().push_back(sink);
  spdlog::set_level(spdlog::level::info);
  const LevelRecordingAdjuster adjuster;
  const MapperResult result = IncrementalPipeline(options, adjuster, 0).Reconstruct(scene.input);
  logger->sinks().pop_back();
  const spdlog::level::level_enum after = spdlog::get_level();
  spdlog::set_level(previous);
  ASSERT_EQ(result.focal_lengths.size(), 1u);
  EXPECT_NE(result.focal_lengths[0].method.find("first model"), std::string::npos);
  EXPECT_EQ(adjuster.levels, std::set<spdlog::level::level_enum>{spdlog::level::info});
  EXPECT_EQ(after, spdlog::level::info);
  // The real pass's registrations are at info, each image once.
  const std::string text = log.str();
  size_t registered = 0;
  for (size_t at = text.find("info map: registered"); at != std::string::npos;
       at = text.find("info map: registered", at + 1)) {
    ++registered;
  }
  EXPECT_GT(registered, 0u) << text;
}

TEST(IncrementalMapperOptions, UnknownKeysAndBadValuesNameTheField) {
  EXPECT_EQ(IncrementalMapperOptions::FromJson(nlohmann::json::object()).init_min_tri_angle, 16.0);
  try {
    IncrementalMapperOptions::FromJson({{"init_min_tri_angel", 8}}, "mapper");
    FAIL();
  } catch (const OptionError& error) {
    EXPECT_NE(std::string(error.what()).find("mapper.init_min_tri_angel"), std::string::npos);
    EXPECT_NE(std::string(error.what()).find("did you mean 'init_min_tri_angle'"),
              std::string::npos);
  }
  EXPECT_THROW(IncrementalMapperOptions::FromJson({{"abs_pose_min_num_inliers", 2}}), OptionError);
  EXPECT_THROW(IncrementalMapperOptions::FromJson({{"multiple_models", 1}}), OptionError);
}

}  // namespace
// The observer sees the model grow one registered image at a time, and stops mapping.
TEST(IncrementalPipeline, ObserverSeesTheModelGrowAndStopsIt) {
  const SyntheticScene scene = MakeSyntheticScene(SyntheticSceneOptions{});
  std::vector<size_t> num_registered;
  MapperControl observer;
  observer.on_model_changed = [&](size_t model_index, const Reconstruction& model) {
    EXPECT_EQ(model_index, 0u);
    size_t n = 0;
    for (const auto& [image_id, image] : model.images) n += image.registered ? 1 : 0;
    num_registered.push_back(n);
  };
  const MapperResult full = IncrementalPipeline({}, testing::CeresAdjusterOnOneThread(), 0)
                                .Reconstruct(scene.input, observer);
  ASSERT_EQ(full.models.size(), 1u);
  EXPECT_FALSE(full.cancelled);
  const size_t num_images = scene.input.images.size();
  ASSERT_EQ(num_registered.size(), num_images - 2) << "one call per image after the pair";
  for (size_t k = 0; k < num_registered.size(); ++k) EXPECT_EQ(num_registered[k], k + 3);

  // Stopped after the third image: no model, and nothing after the stop.
  num_registered.clear();
  observer.should_stop = [&] { return num_registered.size() >= 1; };
  const MapperResult stopped = IncrementalPipeline({}, testing::CeresAdjusterOnOneThread(), 0)
                                   .Reconstruct(scene.input, observer);
  EXPECT_TRUE(stopped.cancelled);
  EXPECT_TRUE(stopped.models.empty());
  EXPECT_EQ(num_registered.size(), 1u);
}

}  // namespace tessera
