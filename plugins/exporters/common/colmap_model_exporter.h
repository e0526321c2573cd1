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

class ColmapModelExporter : public Exporter {
 public:
  ColmapModelExporter(const nlohmann::json& options, ColmapModelFormat format) : format_(format) {
    OptionReader reader(options);
    record_order_from_ = reader.GetString("record_order_from", "");
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
