#pragma once

// Opens anything COLMAP-shaped for the 3D view: a model folder (binary or text, written
// by Tessera or COLMAP), a workspace folder (its sparse/0..N), or a workspace database
// (database.db: the models of its workspace).

#include <cstddef>
#include <filesystem>
#include <optional>
#include <vector>

namespace tessera::gui {

// The model folders `path` names, in model order: `path` itself when it holds a model,
// else PATH/sparse/N (N = 0, 1, ...) for a workspace folder or the folder of a
// database.db. Throws InputError naming `path` and what is missing when there is none.
std::vector<std::filesystem::path> FindModelFolders(const std::filesystem::path& path);

// The number of images a model folder holds, from the head of its images.bin (or the
// count line of images.txt), without reading the model; nothing when it cannot tell.
std::optional<size_t> CountModelImages(const std::filesystem::path& folder);
// Likewise its points (points3D.bin's head, or points3D.txt's count line).
std::optional<size_t> CountModelPoints(const std::filesystem::path& folder);

// The image folder a run recorded in the workspace `folder` (its database.db: the
// folder extract read, absolute); empty when it has no database or none is recorded, or
// the database cannot be read.
std::filesystem::path RecordedImageFolder(const std::filesystem::path& folder);

// N of a workspace's sparse/N model folder; 0 for a model folder outside a workspace.
int ModelFolderNumber(const std::filesystem::path& folder);

}  // namespace tessera::gui
