#include "pipeline/mapper_result_check.h"

#include <gtest/gtest.h>

#include "plugin/plugin_call.h"

namespace tessera {
namespace {

// Two input images of one camera with 3 keypoints each, and a model of both with one
// point seen by keypoint 0 of each.
struct Fixture {
  MapperInput input;
  MapperResult result;

  Fixture() {
    Camera camera;
    camera.camera_id = 1;
    camera.model_id = CameraModelId::kSimplePinhole;
    camera.width = 640;
    camera.height = 480;
    camera.params = {500, 320, 240};
    input.cameras[1] = camera;
    for (image_t id : {1, 2, 3}) {
      Image image;
      image.image_id = id;
      image.camera_id = 1;
      image.name = "im" + std::to_string(id) + ".jpg";
      image.points2D.resize(3);
      input.images[id] = image;
    }
    Reconstruction model;
    model.cameras[1] = camera;
    for (image_t id : {1, 2}) {
      Image image = input.images.at(id);
      image.registered = true;
      image.points2D[0].point3D_id = 7;
      model.images[id] = image;
    }
    Point3D point;
    point.xyz = Eigen::Vector3d(0, 0, 5);
    point.track = {{1, 0}, {2, 0}};
    model.points3D[7] = point;
    result.models.push_back(model);
    result.self_checks.resize(1);
    result.unregistered_reasons[3] = "no pair";
  }

  std::string Fault() {
    try {
      CheckMapperResult("m", input, &result);
    } catch (const PluginError& error) {
      EXPECT_FALSE(error.input_error());
      EXPECT_EQ(error.plugin(), "m");
      return error.what();
    }
    return "";
  }
};

TEST(CheckMapperResult, AcceptsASoundResultAndSortsModelsLargestFirst) {
  Fixture f;
  Reconstruction small;
  small.cameras = f.result.models[0].cameras;
  f.result.models.insert(f.result.models.begin(), small);
  f.result.self_checks.resize(2);
  EXPECT_EQ(f.Fault(), "");
  EXPECT_EQ(f.result.models[0].images.size(), 2u);
  EXPECT_EQ(f.result.models[1].images.size(), 0u);
}

TEST(CheckMapperResult, GivesAReasonWhereTheMapperGaveNone) {
  Fixture f;
  f.result.unregistered_reasons.clear();
  EXPECT_EQ(f.Fault(), "");
  EXPECT_EQ(f.result.unregistered_reasons.at(3), "the mapper 'm' gave no reason");
}

TEST(CheckMapperResult, RefusesEachFaultNamingIt) {
  const auto fault = [](const std::function<void(Fixture&)>& spoil) {
    Fixture f;
    spoil(f);
    return f.Fault();
  };
  EXPECT_NE(fault([](Fixture& f) {
              f.result.models[0].images[1].name = "../x.jpg";
            }).find("model 0 where image 1 ('im1.jpg') comes back with another id, name or camera"),
            std::string::npos);
  EXPECT_NE(fault([](Fixture& f) {
              f.result.models[0].images[9] = f.result.models[0].images[1];
            }).find("image 9 is not an input image"),
            std::string::npos);
  EXPECT_NE(fault([](Fixture& f) {
              f.result.models[0].images[1].registered = false;
            }).find("not registered"),
            std::string::npos);
  EXPECT_NE(fault([](Fixture& f) {
              f.result.models[0].images[1].points2D.resize(2);
            }).find("has 2 keypoints, the input 3"),
            std::string::npos);
  EXPECT_NE(fault([](Fixture& f) {
              f.result.models[0].images[1].cam_from_world.translation.x() = NAN;
            }).find("pose that is not finite"),
            std::string::npos);
  EXPECT_NE(fault([](Fixture& f) {
              f.result.models[0].points3D[7].track.push_back({2, 5});
            }).find("the track of point 7 names a keypoint that is not in the model"),
            std::string::npos);
  EXPECT_NE(fault([](Fixture& f) {
              f.result.models[0].images[2].points2D[1].point3D_id = 8;
            }).find("names point 8"),
            std::string::npos);
  EXPECT_NE(fault([](Fixture& f) {
              f.result.models[0].cameras[1].width = 10;
            }).find("camera 1 is not an input camera"),
            std::string::npos);
  EXPECT_NE(
      fault([](Fixture& f) { f.result.self_checks.clear(); }).find("1 models but 0 self-checks"),
      std::string::npos);
  EXPECT_NE(
      fault([](Fixture& f) { f.result.unregistered_reasons[1] = "?"; }).find("which is in a model"),
      std::string::npos);
  EXPECT_NE(fault([](Fixture& f) {
              f.result.models.push_back(f.result.models[0]);
              f.result.self_checks.resize(2);
            }).find("in two models"),
            std::string::npos);
  // A georeference that `eval --no-align` would refuse is never written.
  EXPECT_NE(fault([](Fixture& f) {
              f.result.georeferences = {Georeference{38.06, 5.375, -9.09e7, "ENU"}};
            }).find("model 0's georeference with altitude: "),
            std::string::npos);
  EXPECT_NE(fault([](Fixture& f) {
              f.result.cancelled = true;
            }).find("plugin 'm' failed while mapping: it returned 'cancelled' without being asked"),
            std::string::npos);
}

}  // namespace
}  // namespace tessera
