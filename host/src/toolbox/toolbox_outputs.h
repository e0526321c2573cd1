#pragma once

// What the toolbox verbs (adjust, align) share around a model they read and write.

#include <filesystem>
#include <functional>
#include <string>

#include "tessera/io/colmap_model_io.h"
#include "tessera/reconstruction.h"

namespace tessera {

// The format ReadColmapModel reads in `dir`: binary when the three .bin files are there.
ColmapModelFormat ColmapModelFormatOf(const std::filesystem::path& dir);

// Throws InputError "<name>: has no cameras" (or no registered images).
void CheckModelHasCamerasAndImages(const Reconstruction& model, const std::string& name);

// Writes `model` (in `format`, records in `order`) and what `write_more` writes into the
// same folder (alignment.json, georeference.json) into `output` as one set of outputs
// (outputs/output_transaction.h): placed whole or not at all, replacing only what Tessera
// wrote there. `writer` names the set in errors.
void WriteToolboxOutputs(const std::filesystem::path& output, const std::string& writer,
                         const Reconstruction& model, ColmapModelFormat format,
                         const ColmapModelFileOrder* order,
                         const std::function<void(const std::filesystem::path&)>& write_more);

}  // namespace tessera
