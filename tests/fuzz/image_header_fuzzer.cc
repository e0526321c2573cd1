// The image-header sniffing of the folder scan: the bytes are one image file. The
// scan tells the format by signature, checks JPEG/PNG completeness, reads the size and
// EXIF from the headers (TIFF: decodes), then the focal length prior is taken from
// the EXIF. A bad file is skipped with a warning; nothing here may throw.

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "fuzz_support.h"
#include "image/camera_assignment.h"
#include "image/image_folder_scan.h"

namespace {

void Check(bool condition, const char* what) {
  if (condition) return;
  std::fprintf(stderr, "tessera fuzz: image scan: %s\n", what);
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::filesystem::path dir = [] {
    const std::filesystem::path path = tessera::fuzz::ScratchDir() / "images";
    std::filesystem::create_directories(path);
    return path;
  }();
  tessera::fuzz::WriteFile(dir / "image.jpg",
                           std::string_view(reinterpret_cast<const char*>(data), size));
  tessera::fuzz::ExpectReadOrInputError("ScanImageFolder", [&] {
    const tessera::ImageScan scan = tessera::ScanImageFolder(dir);
    Check(scan.images.size() + scan.warnings.size() == 1, "not one image or one warning");
    for (const tessera::ImageEntry& image : scan.images) {
      Check(image.width > 0 && image.height > 0, "an image size <= 0");
      std::vector<std::string> warnings;
      if (const auto prior = tessera::EstimateFocalLengthPrior(image, &warnings)) {
        Check(std::isfinite(prior->focal_px) && prior->focal_px > 0,
              "a focal length prior that is not a positive number");
      }
    }
  });
  return 0;
}
