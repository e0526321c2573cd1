#pragma once

// Every image of a workspace, the model it is in, and why one in no model was left out:
// COLMAP's image list, for the "Images" window. The images are the workspace database's
// (then those of the Images folder it does not hold); the models and the reasons are
// mapping_summary.json's, else the sparse/N models' own image lists.

#include <filesystem>
#include <string>
#include <vector>

namespace tessera::gui {

inline constexpr int kInNoModel = -1;

struct ImageListEntry {
  std::string name;        // relative to the image folder, as the database and models name it
  int model = kInNoModel;  // N of sparse/N holding it; kInNoModel when none does
  std::string reason;      // why it is in no model; empty when it is in one
};

struct ImageList {
  std::filesystem::path workspace;
  std::vector<ImageListEntry> entries;  // database order (image id), then the folder's names
  size_t NumInModels() const;
};

// The images of `workspace` (a folder with database.db and sparse/N, or a model folder
// alone: its images) and of `image_dir` (may be empty: not listed). Throws InputError
// naming the file when database.db or mapping_summary.json cannot be read.
ImageList ReadImageList(const std::filesystem::path& workspace,
                        const std::filesystem::path& image_dir);

// Whether `file` is named like an image (.jpg, .jpeg, .png, .tif, .tiff in any case).
bool IsImageFileName(const std::filesystem::path& file);

// The image files directly in `dir` (not its sub-folders), by name, looking at no more
// than `max_entries` entries; 0 when it cannot be listed.
size_t CountImageFiles(const std::filesystem::path& dir, size_t max_entries = 20000);

// The image files under `dir` (sub-folders too, hidden ones left out) by extension
// (.jpg, .jpeg, .png, .tif, .tiff in any case), relative to `dir` and sorted; without
// reading them. Nothing when `dir` is not a folder.
std::vector<std::string> ListImageFiles(const std::filesystem::path& dir);

}  // namespace tessera::gui
