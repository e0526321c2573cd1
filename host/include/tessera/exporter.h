#pragma once

#include <filesystem>

#include "tessera/plugin.h"
#include "tessera/reconstruction.h"

namespace tessera {

struct ExportContext {
  std::filesystem::path output_dir;  // the run's output folder
  std::filesystem::path image_dir;   // where the images named in the model live
  int model_index = 0;               // 0 is the largest model
  // The run's mask folder (camera.mask_path or --masks): the mask of image NAME is
  // MASK_DIR/NAME.png, else MASK_DIR/NAME with the image's extension replaced by .png;
  // white keeps, black masks out. Empty: the run has no masks.
  std::filesystem::path mask_dir;
};

// Writes a reconstruction to files. `reconstruction` may hold images that are not
// registered (Image::registered false: after `map`, every image of the run is there);
// an exporter writes the registered ones only. It writes below context.output_dir only
// (the host runs each exporter in a staging folder and places its files when the whole
// set succeeded).
class TESSERA_API Exporter : public Plugin {
 public:
  virtual void Export(const Reconstruction& reconstruction, const ExportContext& context) const = 0;
};

}  // namespace tessera
