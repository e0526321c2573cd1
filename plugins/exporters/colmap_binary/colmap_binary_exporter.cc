// Writes a reconstruction as a COLMAP 3.8 binary model, which COLMAP and the tools that
// read COLMAP models open unchanged.

#include "common/colmap_model_exporter.h"

namespace tessera {

class ColmapBinaryExporter : public ColmapModelExporter {
 public:
  explicit ColmapBinaryExporter(const nlohmann::json& options)
      : ColmapModelExporter(options, ColmapModelFormat::kBinary) {}
};

}  // namespace tessera

TESSERA_PLUGIN_OPTIONS(tessera::ColmapModelExporterOptions,
                       tessera::VisitColmapModelExporterOptions)
TESSERA_PLUGIN(exporter, tessera::ColmapBinaryExporter, "colmap_binary", "1.0.0",
               "COLMAP 3.8 binary model: sparse/N/{cameras,images,points3D}.bin")
