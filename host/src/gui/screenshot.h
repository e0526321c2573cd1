#pragma once

// Reads back the current OpenGL framebuffer and writes it as a PNG (stb_image_write).

#include <cstdint>
#include <filesystem>
#include <vector>

namespace tessera::gui {

struct RgbImage {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> pixels;  // rgb, rows top to bottom
};

// The framebuffer now bound for reading (the back buffer before a swap), top row first.
RgbImage ReadFramebuffer(int width, int height);

// Writes `image` as an 8-bit RGB PNG, atomically. Throws InputError naming the file when
// it cannot be written.
void WritePng(const RgbImage& image, const std::filesystem::path& file);

}  // namespace tessera::gui
