// The COLMAP binary model reader: the bytes are cameras.bin, images.bin and points3D.bin
// joined by tessera::fuzz::kFileSeparator. Damaged models must be refused with
// InputError; a model that reads must be consistent (every track element points at an
// existing image's existing keypoint).

#include "colmap_model_fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  tessera::fuzz::ReadColmapModelFromInput(data, size, ".bin");
  return 0;
}
