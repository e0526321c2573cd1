#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "tessera/georeference.h"
#include "tessera/io/export.h"

namespace tessera {

// The file beside a model that says where its frame sits on the Earth.
constexpr const char* kGeoreferenceFileName = "georeference.json";

// Writes MODEL_DIR/georeference.json atomically (MODEL_DIR made when missing): {"latitude": deg,
// "longitude": deg, "altitude": m, "frame": "ENU"}.
TESSERA_IO_EXPORT void WriteGeoreference(const Georeference& georeference,
                                         const std::filesystem::path& model_dir);

// What makes `georeference` one that ReadGeoreference refuses ("altitude: ... is out of
// range [-100000, 100000]"); "" when it reads back. The host checks a mapper's
// georeferences with it before writing them, so that Tessera writes none it refuses.
TESSERA_IO_EXPORT std::string GeoreferenceProblem(const Georeference& georeference);

// Reads MODEL_DIR/georeference.json; nullopt when the model has none. Throws InputError
// naming the file and field when it is there but malformed (a latitude outside
// [-90, 90], a longitude outside [-180, 180], an altitude outside [-1e5, 1e5] m, a frame
// other than ENU).
TESSERA_IO_EXPORT std::optional<Georeference> ReadGeoreference(
    const std::filesystem::path& model_dir);

}  // namespace tessera
