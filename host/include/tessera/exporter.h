#pragma once

#include <filesystem>

#include "tessera/plugin.h"
#include "tessera/reconstruction.h"

namespace tessera {

struct ExportContext {
  std::filesystem::path output_dir;  // the run's output folder
  std::filesystem::path image_dir;   // where the images named in the model live
  int model_index = 0;               // 0 is the largest model
};

// Writes a reconstruction to files.
class TESSERA_API Exporter : public Plugin {
 public:
  virtual void Export(const Reconstruction& reconstruction, const ExportContext& context) const = 0;
};

}  // namespace tessera
