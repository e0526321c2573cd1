#pragma once

#include <string>

#include "tessera/mapper.h"

namespace tessera {

// Checks what a mapper plugin returned before anything is written from it: every
// model's images are input images with their names and cameras, its cameras are the
// images' own, every track element and points2D link points at something in the model,
// one self-check per model, no georeference or one per model (afterwards always one
// per model, nullopt where none), reasons only for input images that are in no model, and
// `cancelled` only when the host asked. Sorts the models largest first. Throws a
// PluginError (internal, exit code 1) naming the plugin and the first fault.
void CheckMapperResult(const std::string& mapper, const MapperInput& input, MapperResult* result);

}  // namespace tessera
