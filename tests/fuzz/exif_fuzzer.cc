// The EXIF reader: the bytes are a JPEG file or a raw EXIF block ("Exif\0\0" + TIFF).
// EXIF is optional, so ReadExifInfo never refuses: it must return, with plausible values.

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "fuzz_support.h"
#include "tessera/io/exif.h"

namespace {

void Check(bool condition, const char* what) {
  if (condition) return;
  std::fprintf(stderr, "tessera fuzz: ReadExifInfo returned %s\n", what);
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  tessera::fuzz::ExpectReadOrInputError("ReadExifInfo", [&] {
    const tessera::ExifInfo info = tessera::ReadExifInfo(data, size);
    Check(info.orientation >= 1 && info.orientation <= 8, "an orientation outside 1..8");
    if (info.focal_plane_x_resolution) {
      Check(std::isfinite(*info.focal_plane_x_resolution) && *info.focal_plane_x_resolution > 0,
            "a focal-plane resolution that is not a positive number");
    }
    if (info.pixel_x_dimension) Check(*info.pixel_x_dimension > 0, "a pixel width <= 0");
    if (info.pixel_y_dimension) Check(*info.pixel_y_dimension > 0, "a pixel height <= 0");
  });
  return 0;
}
