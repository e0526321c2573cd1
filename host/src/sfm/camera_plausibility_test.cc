#include "tessera/sfm/camera_plausibility.h"

#include <gtest/gtest.h>

namespace tessera {
namespace {

TEST(CameraPlausibility, PrincipalPointWithinTheOffsetRatioOfTheCentre) {
  Camera camera = Camera::Create(1, CameraModelId::kSimpleRadial, 1000, 400, 300);
  EXPECT_TRUE(IsPrincipalPointPlausible(camera, 0.1));
  // 40 px of 400 is exactly 10%: still plausible; one more pixel is not.
  camera.params[camera.PrincipalPointIdx()[0]] = 240;
  EXPECT_TRUE(IsPrincipalPointPlausible(camera, 0.1));
  camera.params[camera.PrincipalPointIdx()[0]] = 241;
  EXPECT_FALSE(IsPrincipalPointPlausible(camera, 0.1));
  // The vertical offset is measured against the height.
  camera.params[camera.PrincipalPointIdx()[0]] = 200;
  camera.params[camera.PrincipalPointIdx()[1]] = 150 - 31;
  EXPECT_FALSE(IsPrincipalPointPlausible(camera, 0.1));
  EXPECT_TRUE(IsPrincipalPointPlausible(camera, 0.11));
}

TEST(CameraPlausibility, ResetPutsThePrincipalPointAtTheCentreAndNothingElse) {
  Camera camera = Camera::Create(1, CameraModelId::kSimpleRadial, 1000, 400, 300);
  std::vector<double> expected = camera.params;
  camera.params[camera.PrincipalPointIdx()[0]] = 390;
  camera.params[camera.PrincipalPointIdx()[1]] = -5;
  ResetPrincipalPoint(&camera);
  EXPECT_EQ(camera.params, expected);
  EXPECT_TRUE(IsPrincipalPointPlausible(camera, 0.0));
}

}  // namespace
}  // namespace tessera
