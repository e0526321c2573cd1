#pragma once

// The workspace folder every stage writes: its creation, its lock, and the image
// folder it was made from.

#include <filesystem>
#include <memory>
#include <string>

#include "database/database.h"
#include "image/image_io.h"
#include "manifest/manifest.h"
#include "util/workspace_lock.h"

namespace tessera {

// Creates the output folder, reports the plugin crashes of earlier runs (and makes the
// crash log current). Returns OUTPUT/database.db. Throws InputError naming the folder.
std::filesystem::path PrepareWorkspace(const std::filesystem::path& output_dir);

// One writer per workspace: every stage that writes it holds this for its whole run.
// Logs when it takes over a lock left by a process that ended without releasing it.
std::unique_ptr<WorkspaceLock> LockWorkspace(const std::filesystem::path& output_dir);

// The scan options of a run writing `output_dir`: the scan leaves the run's own output
// folder out (output never feeds input) and refuses images larger than the manifest's
// max_image_pixels.
ImageScanOptions WorkspaceScanOptions(const std::filesystem::path& output_dir,
                                      const Manifest& manifest);

// The image folder: `option` when given, else the one extract recorded in the workspace
// (empty when neither).
std::filesystem::path ImageFolder(const std::filesystem::path& option, const Database& database);

// `map` on its own: the images the points are coloured from (and the exporters read)
// must be the very files the workspace's features came from. Throws InputError naming
// the first image missing or changed.
void CheckImagesUnchanged(const std::filesystem::path& image_dir_option,
                          const std::filesystem::path& output_dir, const Manifest& manifest,
                          const Database& database);

}  // namespace tessera
