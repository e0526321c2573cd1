#pragma once

// The colmap_text and colmap_binary exporters: one class, the format chosen by the
// plugin, writing through Tessera::io's COLMAP model writer (tessera/io/colmap_model_io.h).

#include <filesystem>
#include <string>

#include "common/exported_camera.h"
#include "tessera/io/colmap_model_io.h"
#include "tessera/io/exporter_paths.h"
#include "tessera/io/georeference_io.h"
#include "tessera/sdk.h"

namespace tessera {

struct ColmapModelExporterOptions {
  // A COLMAP model folder whose record order the written files follow; empty: ascending
  // ids.
  std::string record_order_from;
};

// The options of colmap_text and colmap_binary, listed once: read, checked and described
// (`tessera plugins colmap_text`) from here.
template <typename Visit>
void VisitColmapModelExporterOptions(ColmapModelExporterOptions& o, const Visit& visit) {
  visit("record_order_from", o.record_order_from,
        "a COLMAP model folder (binary or text) whose record order to follow: records it lists "
        "come in its order, the others by ascending id; empty: ascending ids");
}

class ColmapModelExporter : public Exporter {
 public:
  ColmapModelExporter(const nlohmann::json& options, ColmapModelFormat format) : format_(format) {
    OptionReader reader(options);
    ColmapModelExporterOptions parsed;
    VisitColmapModelExporterOptions(parsed, option_list::Reader(&reader));
    record_order_from_ = parsed.record_order_from;
    reader.Finish();
    if (!record_order_from_.empty() && !ExistsColmapModel(record_order_from_)) {
      throw OptionError("record_order_from", "'" + record_order_from_ +
                                                 "' is not a COLMAP model folder (cameras, "
                                                 "images and points3D as .bin or .txt)");
    }
    effective_options_ = reader.Effective();
  }

  // Writes OUTPUT/sparse/<model_index>/{cameras,images,points3D}.{txt|bin}, and
  // georeference.json beside them for a model in a GPS-anchored ENU frame.
  void Export(const Reconstruction& reconstruction, const ExportContext& context) const override {
    // COLMAP and every reader of its models take a focal length of 0 at its word.
    try {
      CheckExportedCameras(reconstruction);
    } catch (const InputError& error) {
      throw InputError(SparseModelDir(context).string() + ": " + error.what());
    }
    if (context.georeference) WriteGeoreference(*context.georeference, SparseModelDir(context));
    if (record_order_from_.empty()) {
      WriteColmapModel(reconstruction, SparseModelDir(context), format_);
      return;
    }
    // COLMAP writes records in hash-map order; following the order of the files a model
    // was read from writes an unchanged model byte for byte as COLMAP did.
    ColmapModelFileOrder order;
    ReadColmapModel(record_order_from_, &order);
    WriteColmapModel(reconstruction, SparseModelDir(context), format_, &order);
  }

 private:
  ColmapModelFormat format_;
  std::string record_order_from_;
};

}  // namespace tessera
