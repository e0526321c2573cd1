// Issue 30 items 6 and 7 in the window, on COLMAP's fountain-P11 model: a click anywhere
// on a camera's frustum picks it; the picked point and its track are drawn highlighted;
// the ground grid and the axes toggle; the view snaps to a camera from its window; the
// point size follows the model's density.

#include <cmath>

#include "gui/gui_window_test_fixture.h"
#include "gui/view_overlay.h"
#include "small_colmap_model.h"

namespace tessera::gui {
namespace {
namespace fs = std::filesystem;

size_t CountColor(const RgbImage& image, const WidgetRect& view, const std::array<uint8_t, 3>& c) {
  size_t count = 0;
  for (int y = static_cast<int>(view.min_y); y < static_cast<int>(view.max_y); ++y) {
    for (int x = static_cast<int>(view.min_x); x < static_cast<int>(view.max_x); ++x) {
      const uint8_t* p = &image.pixels[(static_cast<size_t>(y) * image.width + x) * 3];
      count += p[0] == c[0] && p[1] == c[1] && p[2] == c[2] ? 1 : 0;
    }
  }
  return count;
}

class GuiNavigationTest : public GuiWindowTest {
 protected:
  void SetUp() override {
    GuiWindowTest::SetUp();
    if (IsSkipped()) return;
    model_ =
        tessera::testing::SharedDir() / "anchors" / "colmap-3.8" / "fountain-P11" / "sparse" / "0";
    if (!fs::exists(model_ / "points3D.bin")) TESSERA_SKIP_OR_FAIL_IN_CI(model_ << " is missing");
  }
  fs::path model_;
};

TEST_F(GuiNavigationTest, AClickOnAFrustumAwayFromItsCentrePicksTheCamera) {
  GuiOptions options;
  options.model = model_;
  GuiApp app(options);
  app.Frame();
  app.Frame();
  const Scene& scene = *app.scene();
  const SceneCamera& camera = scene.cameras.at(5);
  // The middle of the frustum's image rectangle, as drawn.
  const float depth = app.FrustumSize() * scene.radius;
  Eigen::Vector3f middle = Eigen::Vector3f::Zero();
  for (const Eigen::Vector3f& ray : camera.corner_rays_in_world) {
    middle += (camera.center_in_world + depth * ray) / 4;
  }
  const auto click = app.ProjectToWindow(middle);
  const auto centre = app.ProjectToWindow(camera.center_in_world);
  ASSERT_TRUE(click && centre);
  const float away = std::hypot((*click)[0] - (*centre)[0], (*click)[1] - (*centre)[1]);
  std::printf("the click is %.1f px from the camera's centre\n", away);
  ASSERT_GT(away, 12.0f);  // farther than a click on the centre reaches
  Click(&app, WidgetRect{(*click)[0], (*click)[1], (*click)[0], (*click)[1]});
  EXPECT_EQ(app.selected_image(), camera.image_id);
}

TEST_F(GuiNavigationTest, ThePickedPointAndItsTrackAreHighlighted) {
  GuiOptions options;
  options.model = model_;
  GuiApp app(options);
  app.Frame();
  RgbImage before;
  app.Frame(nullptr, &before);
  const WidgetRect view = app.ViewRect();
  EXPECT_EQ(CountColor(before, view, kSelectedPointColor), 0u);
  // A point in the middle of the view with a long track, away from the cameras.
  const Scene& scene = *app.scene();
  std::optional<std::array<float, 2>> pixel;
  for (const auto& [id, point] : scene.model->points3D) {
    if (point.track.size() < 4) continue;
    const auto at = app.ProjectToWindow(point.xyz.cast<float>());
    if (!at) continue;
    const float cx = (view.min_x + view.max_x) / 2, cy = (view.min_y + view.max_y) / 2;
    if (std::abs((*at)[0] - cx) < 120 && std::abs((*at)[1] - cy) < 120) {
      pixel = at;
      break;
    }
  }
  ASSERT_TRUE(pixel.has_value());
  Click(&app, WidgetRect{(*pixel)[0], (*pixel)[1], (*pixel)[0], (*pixel)[1]});
  ASSERT_NE(app.selected_point(), kInvalidPoint3DId);
  ASSERT_EQ(app.selected_image(), kInvalidImageId);
  app.Frame();
  RgbImage after;
  app.Frame(nullptr, &after);
  const size_t highlighted = CountColor(after, view, kSelectedPointColor);
  const size_t track = scene.model->points3D.at(app.selected_point()).track.size();
  std::printf("the picked point's track of %zu: %zu highlighted pixels\n", track, highlighted);
  // The point (8x8 pixels at least) and a line of tens of pixels to each camera.
  EXPECT_GT(highlighted, 64 + 30 * track);
}

TEST_F(GuiNavigationTest, GridAndAxesToggleAndTheViewSnapsToACamera) {
  GuiOptions options;
  options.model = model_;
  GuiApp app(options);
  app.Frame();
  RgbImage image;
  app.Frame(nullptr, &image);
  const WidgetRect view = app.ViewRect();
  EXPECT_EQ(app.PointSize(), 2.0f);  // 14777 points: DefaultPointSize
  EXPECT_EQ(CountColor(image, view, kGridColor), 0u);
  Click(&app, "grid");
  Click(&app, "axes");
  app.Frame(nullptr, &image);
  const size_t grid = CountColor(image, view, kGridColor);
  const size_t axes = CountColor(image, view, kAxisXColor) + CountColor(image, view, kAxisYColor) +
                      CountColor(image, view, kAxisZColor);
  std::printf("grid: %zu pixels, axes: %zu pixels\n", grid, axes);
  EXPECT_GT(grid, 2000u);
  EXPECT_GT(axes, 30u);
  Click(&app, "grid");
  Click(&app, "axes");
  app.Frame(nullptr, &image);
  EXPECT_EQ(CountColor(image, view, kGridColor), 0u);

  // Snap to camera 3 from its window: what is straight ahead of it is in the middle.
  const SceneCamera& camera = app.scene()->cameras.at(3);
  const auto centre = app.ProjectToWindow(camera.center_in_world);
  ASSERT_TRUE(centre.has_value());
  Click(&app, WidgetRect{(*centre)[0], (*centre)[1], (*centre)[0], (*centre)[1]});
  ASSERT_EQ(app.selected_image(), camera.image_id);
  app.Frame();
  app.Frame();
  Click(&app, "look through");
  app.Frame();
  const Eigen::Vector3f ahead =
      camera.center_in_world + app.scene()->radius * camera.world_from_cam.col(2);
  const auto at = app.ProjectToWindow(ahead);
  ASSERT_TRUE(at.has_value());
  EXPECT_NEAR((*at)[0], (view.min_x + view.max_x) / 2, 1.0f);
  EXPECT_NEAR((*at)[1], (view.min_y + view.max_y) / 2, 1.0f);
  // The camera's own up is up: a point below its centre in its image shows lower.
  const auto below =
      app.ProjectToWindow(ahead + 0.1f * app.scene()->radius * camera.world_from_cam.col(1));
  ASSERT_TRUE(below.has_value());
  EXPECT_GT((*below)[1], (*at)[1]);
}

}  // namespace
}  // namespace tessera::gui
