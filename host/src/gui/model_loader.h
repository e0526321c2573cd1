#pragma once

// Opens anything COLMAP-shaped for the 3D view: a model folder (binary or text, written
// by Tessera or COLMAP), a workspace folder (its sparse/0..N), or a workspace database
// (database.db: the models of its workspace).

#include <filesystem>
#include <vector>

namespace tessera::gui {

// The model folders `path` names, in model order: `path` itself when it holds a model,
// else PATH/sparse/N (N = 0, 1, ...) for a workspace folder or the folder of a
// database.db. Throws InputError naming `path` and what is missing when there is none.
std::vector<std::filesystem::path> FindModelFolders(const std::filesystem::path& path);

}  // namespace tessera::gui
