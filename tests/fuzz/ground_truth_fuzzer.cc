// The ground-truth readers: the first byte picks the format, the rest is the file.
//   0: a Strecha `<image>.camera` file, read through ReadGroundTruth on its folder;
//   1: an instant-ngp/nerfstudio transforms.json, read through ReadGroundTruth;
//   2: a K.txt calibration matrix (ReadCalibrationMatrixFile).
// Malformed files must be refused with InputError.

#include <filesystem>

#include "eval/ground_truth.h"
#include "fuzz_support.h"
#include "manifest/manifest.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  namespace fs = std::filesystem;
  static const fs::path strecha_dir = [] {
    const fs::path path = tessera::fuzz::ScratchDir() / "strecha";
    fs::create_directories(path);
    return path;
  }();
  if (size == 0) return 0;
  const std::string_view file(reinterpret_cast<const char*>(data + 1), size - 1);
  switch (data[0] % 3) {
    case 0:
      tessera::fuzz::WriteFile(strecha_dir / "0000.jpg.camera", file);
      tessera::fuzz::ExpectReadOrInputError("ReadGroundTruth (Strecha)",
                                            [&] { tessera::ReadGroundTruth(strecha_dir); });
      break;
    case 1: {
      const fs::path path = tessera::fuzz::ScratchDir() / "transforms.json";
      tessera::fuzz::WriteFile(path, file);
      tessera::fuzz::ExpectReadOrInputError("ReadGroundTruth (transforms.json)",
                                            [&] { tessera::ReadGroundTruth(path); });
      break;
    }
    default: {
      const fs::path path = tessera::fuzz::ScratchDir() / "K.txt";
      tessera::fuzz::WriteFile(path, file);
      tessera::fuzz::ExpectReadOrInputError("ReadCalibrationMatrixFile",
                                            [&] { tessera::ReadCalibrationMatrixFile(path); });
      break;
    }
  }
  return 0;
}
