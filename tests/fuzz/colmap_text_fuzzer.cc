// The COLMAP text model reader: the bytes are cameras.txt, images.txt and points3D.txt
// joined by tessera::fuzz::kFileSeparator. Damaged models must be refused with
// InputError; a model that reads must be consistent (every track element points at an
// existing image's existing keypoint).

#include "colmap_model_fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  tessera::fuzz::ReadColmapModelFromInput(data, size, ".txt");
  return 0;
}
