#include "gui/model_loader.h"

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <string>

#include "database/database.h"
#include "pipeline/workspace.h"
#include "tessera/errors.h"
#include "tessera/io/colmap_model_io.h"
#include "util/workspace_layout.h"

namespace tessera::gui {
namespace fs = std::filesystem;

std::vector<fs::path> FindModelFolders(const fs::path& path) {
  std::error_code error;
  if (!fs::exists(path, error)) throw InputError(path.string() + ": no such file or folder");
  if (fs::is_directory(path, error) && ExistsColmapModel(path)) return {path};
  const fs::path workspace = fs::is_directory(path, error) ? path : path.parent_path();
  if (!fs::is_directory(path, error) && path.filename() != workspace_layout::kDatabase) {
    throw InputError(path.string() + ": not a model folder or a workspace database.db");
  }
  std::vector<std::pair<int, fs::path>> models;
  const fs::path sparse = workspace / workspace_layout::kModelsFolder;
  if (fs::is_directory(sparse, error)) {
    for (const auto& entry : fs::directory_iterator(sparse, error)) {
      const std::string name = entry.path().filename().string();
      if (name.empty() || !std::all_of(name.begin(), name.end(), ::isdigit) || name.size() > 6) {
        continue;
      }
      if (ExistsColmapModel(entry.path())) models.emplace_back(std::stoi(name), entry.path());
    }
  }
  if (models.empty()) {
    throw InputError(path.string() +
                     ": not a model: no cameras, images and points3D (.bin or .txt) in it, and "
                     "no sparse/N model folders beside a workspace database");
  }
  std::sort(models.begin(), models.end());
  std::vector<fs::path> folders;
  for (const auto& [index, folder] : models) folders.push_back(folder);
  return folders;
}

fs::path RecordedImageFolder(const fs::path& folder) {
  std::error_code error;
  const fs::path database_file = folder / workspace_layout::kDatabase;
  if (folder.empty() || !fs::is_regular_file(database_file, error)) return {};
  try {
    return ImageFolder({}, Database(database_file, Database::Mode::kReadOnly));
  } catch (const std::exception&) {
    return {};  // not a database this build reads: nothing recorded to use
  }
}

int ModelFolderNumber(const fs::path& folder) {
  const std::string name = folder.filename().string();
  if (folder.parent_path().filename() != workspace_layout::kModelsFolder || name.empty() ||
      name.size() > 6 || !std::all_of(name.begin(), name.end(), ::isdigit)) {
    return 0;
  }
  return std::stoi(name);
}

namespace {

// The record count of a model file: FILE.bin's head (a little-endian uint64, COLMAP's
// binary layout), else FILE.txt's comment line starting with `count_line`.
std::optional<size_t> CountRecords(const fs::path& folder, const std::string& file_stem,
                                   const std::string& count_line) {
  std::error_code error;
  const fs::path binary = folder / (file_stem + ".bin");
  if (fs::is_regular_file(binary, error)) {
    std::ifstream file(binary, std::ios::binary);
    unsigned char bytes[8] = {};
    if (!file.read(reinterpret_cast<char*>(bytes), sizeof(bytes))) return std::nullopt;
    uint64_t count = 0;
    for (int i = 7; i >= 0; --i) count = (count << 8) | bytes[i];
    return static_cast<size_t>(count);
  }
  const fs::path text = folder / (file_stem + ".txt");
  if (!fs::is_regular_file(text, error)) return std::nullopt;
  std::ifstream file(text);
  std::string line;
  while (std::getline(file, line) && !line.empty() && line[0] == '#') {
    if (line.rfind(count_line, 0) == 0) {
      try {
        return static_cast<size_t>(std::stoul(line.substr(count_line.size())));
      } catch (const std::exception&) {
        return std::nullopt;
      }
    }
  }
  return std::nullopt;
}

}  // namespace

std::optional<size_t> CountModelImages(const fs::path& folder) {
  // "# Number of images: 3, mean observations per image: ..."
  return CountRecords(folder, "images", "# Number of images: ");
}

std::optional<size_t> CountModelPoints(const fs::path& folder) {
  // "# Number of points: 4, mean track length: ..."
  return CountRecords(folder, "points3D", "# Number of points: ");
}

}  // namespace tessera::gui
