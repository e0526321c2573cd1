// Writes a reconstruction as a COLMAP 3.8 text model, which COLMAP and the tools that
// read COLMAP models open unchanged.

#include "common/colmap_model_exporter.h"

namespace tessera {

class ColmapTextExporter : public ColmapModelExporter {
 public:
  explicit ColmapTextExporter(const nlohmann::json& options)
      : ColmapModelExporter(options, ColmapModelFormat::kText) {}
};

}  // namespace tessera

TESSERA_PLUGIN_OPTIONS(tessera::ColmapModelExporterOptions,
                       tessera::VisitColmapModelExporterOptions)
TESSERA_PLUGIN(exporter, tessera::ColmapTextExporter, "colmap_text", "1.0.0",
               "COLMAP 3.8 text model: sparse/N/{cameras,images,points3D}.txt")
