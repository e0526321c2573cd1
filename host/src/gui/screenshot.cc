#include "gui/screenshot.h"

#include <stb_image_write.h>

#include <cstring>
#include <string>

#include "gui/gl.h"
#include "tessera/errors.h"
#include "tessera/io/file_io.h"

namespace tessera::gui {
namespace {

void AppendBytes(void* context, void* data, int size) {
  auto* bytes = static_cast<std::string*>(context);
  bytes->append(static_cast<const char*>(data), static_cast<size_t>(size));
}

}  // namespace

RgbImage ReadFramebuffer(int width, int height) {
  RgbImage image;
  image.width = width;
  image.height = height;
  const size_t row = static_cast<size_t>(width) * 3;
  std::vector<uint8_t> bottom_up(row * static_cast<size_t>(height));
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadBuffer(GL_BACK);
  glReadPixels(0, 0, width, height, GL_RGB, GL_UNSIGNED_BYTE, bottom_up.data());
  image.pixels.resize(bottom_up.size());
  for (int y = 0; y < height; ++y) {
    std::memcpy(image.pixels.data() + static_cast<size_t>(y) * row,
                bottom_up.data() + static_cast<size_t>(height - 1 - y) * row, row);
  }
  return image;
}

void WritePng(const RgbImage& image, const std::filesystem::path& file) {
  std::string bytes;
  if (image.width <= 0 || image.height <= 0 ||
      stbi_write_png_to_func(AppendBytes, &bytes, image.width, image.height, 3, image.pixels.data(),
                             image.width * 3) == 0) {
    throw InputError(file.string() + ": the screenshot could not be encoded as PNG");
  }
  WriteFileAtomically(file, bytes);
}

}  // namespace tessera::gui
