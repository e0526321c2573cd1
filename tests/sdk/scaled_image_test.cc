#include "tessera/scaled_image.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace tessera {
namespace {

ImageView ViewOf(std::vector<uint8_t>& pixels, int width, int height, size_t stride) {
  ImageView view;
  view.width = width;
  view.height = height;
  view.stride = stride;
  view.data = pixels.data();
  return view;
}

TEST(ScaleToMaxSize, ASmallEnoughImageIsTheViewItself) {
  std::vector<uint8_t> pixels(12 * 8, 7);
  const ScaledImage scaled = ScaleToMaxSize(ViewOf(pixels, 10, 8, 12), 10, "sift");
  EXPECT_EQ(scaled.image.data, pixels.data());
  EXPECT_EQ(scaled.image.cols, 10);
  EXPECT_EQ(scaled.image.rows, 8);
  EXPECT_EQ(scaled.image.step[0], 12u);
  EXPECT_EQ(scaled.scale_x, 1);
  EXPECT_EQ(scaled.scale_y, 1);
}

TEST(ScaleToMaxSize, AveragesAreasAndReportsTheFactors) {
  // 4 x 2 to 2 x 1: each working pixel is the mean of a 2 x 2 block.
  std::vector<uint8_t> pixels = {10, 20, 30, 40, 50, 60, 70, 80};
  const ScaledImage scaled = ScaleToMaxSize(ViewOf(pixels, 4, 2, 4), 2, "sift");
  ASSERT_EQ(scaled.image.cols, 2);
  ASSERT_EQ(scaled.image.rows, 1);
  EXPECT_EQ(scaled.image.at<uint8_t>(0, 0), 35);
  EXPECT_EQ(scaled.image.at<uint8_t>(0, 1), 55);
  EXPECT_EQ(scaled.scale_x, 2);
  EXPECT_EQ(scaled.scale_y, 2);

  // 1000 x 333 to 300 x 100 (333 * 0.3 = 99.9 rounds to 100): the factors are the true
  // ratios of the sides, not 1 / 0.3.
  std::vector<uint8_t> large(1000 * 333, 9);
  const ScaledImage wide = ScaleToMaxSize(ViewOf(large, 1000, 333, 1000), 300, "orb");
  EXPECT_EQ(wide.image.cols, 300);
  EXPECT_EQ(wide.image.rows, 100);
  EXPECT_DOUBLE_EQ(wide.scale_x, 1000.0 / 300);
  EXPECT_DOUBLE_EQ(wide.scale_y, 3.33);
}

TEST(ScaleToMaxSize, RefusesAMalformedViewNamingTheDetector) {
  std::vector<uint8_t> pixels(16, 0);
  const auto message = [&](const ImageView& view) -> std::string {
    try {
      ScaleToMaxSize(view, 100, "orb");
    } catch (const InputError& error) {
      return error.what();
    }
    return "no error";
  };
  EXPECT_EQ(message(ViewOf(pixels, 4, 4, 3)),
            "orb: cannot detect features in an empty or malformed image view (4x4)");
  EXPECT_EQ(message(ViewOf(pixels, 0, 4, 4)),
            "orb: cannot detect features in an empty or malformed image view (0x4)");
  ImageView no_data = ViewOf(pixels, 4, 4, 4);
  no_data.data = nullptr;
  EXPECT_EQ(message(no_data),
            "orb: cannot detect features in an empty or malformed image view (4x4)");
}

}  // namespace
}  // namespace tessera
