#include "gui/image_list.h"

#include <algorithm>
#include <cctype>
#include <map>
#include <set>

#include "database/database.h"
#include "gui/model_loader.h"
#include "pipeline/mapping_summary.h"
#include "tessera/errors.h"
#include "tessera/io/colmap_model_io.h"
#include "util/workspace_layout.h"

namespace tessera::gui {
namespace fs = std::filesystem;
namespace {

// Each image's model: mapping_summary.json's when the workspace has one (with its
// reasons), else each model folder's own image names (read whole).
void ReadModelsOfImages(const fs::path& workspace, std::map<std::string, int>* model_of,
                        std::map<std::string, std::string>* reason_of, bool* has_summary) {
  const fs::path summary_file = workspace / workspace_layout::kMappingSummary;
  std::error_code error;
  *has_summary = fs::is_regular_file(summary_file, error);
  if (*has_summary) {
    const MappingSummary summary = MappingSummary::Read(summary_file);
    for (const MappingSummary::Model& model : summary.models) {
      for (const std::string& name : model.images) {
        model_of->emplace(name, static_cast<int>(model.index));
      }
    }
    for (const MappingSummary::Unregistered& left_out : summary.unregistered) {
      (*reason_of)[left_out.image] = left_out.reason;
    }
    return;
  }
  std::vector<fs::path> folders;
  try {
    folders = FindModelFolders(workspace);
  } catch (const InputError&) {
    return;  // no model yet: every image is in none
  }
  for (const fs::path& folder : folders) {
    const Reconstruction model = ReadColmapModel(folder);
    for (const auto& [image_id, image] : model.images) {
      if (image.registered) model_of->emplace(image.name, ModelFolderNumber(folder));
    }
  }
}

}  // namespace

size_t ImageList::NumInModels() const {
  return static_cast<size_t>(std::count_if(
      entries.begin(), entries.end(), [](const auto& entry) { return entry.model != kInNoModel; }));
}

bool IsImageFileName(const fs::path& file) {
  std::string extension = file.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension == ".jpg" || extension == ".jpeg" || extension == ".png" ||
         extension == ".tif" || extension == ".tiff";
}

size_t CountImageFiles(const fs::path& dir, size_t max_entries) {
  size_t count = 0, seen = 0;
  std::error_code error;
  for (fs::directory_iterator it(dir, fs::directory_options::skip_permission_denied, error), end;
       !error && it != end && seen < max_entries; it.increment(error), ++seen) {
    const std::string name = it->path().filename().string();
    std::error_code type_error;
    if (!name.empty() && name[0] != '.' && IsImageFileName(it->path()) &&
        it->is_regular_file(type_error)) {
      ++count;
    }
  }
  return count;
}

std::vector<std::string> ListImageFiles(const fs::path& dir) {
  std::vector<std::string> names;
  std::error_code error;
  if (dir.empty() || !fs::is_directory(dir, error)) return names;
  fs::recursive_directory_iterator it(dir, fs::directory_options::skip_permission_denied, error);
  for (; !error && it != fs::recursive_directory_iterator(); it.increment(error)) {
    const std::string name = it->path().filename().string();
    if (!name.empty() && name[0] == '.') {
      if (it->is_directory(error)) it.disable_recursion_pending();
      continue;
    }
    if (it->is_regular_file(error) && IsImageFileName(it->path())) {
      names.push_back(it->path().lexically_relative(dir).generic_string());
    }
  }
  std::sort(names.begin(), names.end());
  return names;
}

ImageList ReadImageList(const fs::path& workspace, const fs::path& image_dir) {
  ImageList list;
  list.workspace = workspace;
  std::map<std::string, int> model_of;
  std::map<std::string, std::string> reason_of;
  bool has_summary = false;
  ReadModelsOfImages(workspace, &model_of, &reason_of, &has_summary);

  std::set<std::string> listed;
  const auto add = [&](const std::string& name, const std::string& not_in_database) {
    if (!listed.insert(name).second) return;
    ImageListEntry entry;
    entry.name = name;
    const auto model = model_of.find(name);
    if (model != model_of.end()) {
      entry.model = model->second;
    } else if (!not_in_database.empty()) {
      entry.reason = not_in_database;
    } else if (const auto reason = reason_of.find(name); reason != reason_of.end()) {
      entry.reason = reason->second;
    } else {
      entry.reason = has_summary ? "in no model; mapping_summary.json gives no reason"
                                 : "in no model (no mapping_summary.json records why)";
    }
    list.entries.push_back(std::move(entry));
  };

  const fs::path database_file = workspace / workspace_layout::kDatabase;
  std::error_code error;
  const bool has_database = fs::is_regular_file(database_file, error);
  if (has_database) {
    std::vector<Image> images;
    try {
      images = Database(database_file, Database::Mode::kReadOnly).ReadAllImages();
    } catch (const std::exception& e) {
      throw InputError(database_file.string() + ": cannot read its images: " + e.what());
    }
    std::sort(images.begin(), images.end(),
              [](const Image& a, const Image& b) { return a.image_id < b.image_id; });
    for (const Image& image : images) add(image.name, "");
  }
  // The models' images (a model folder without a database), then the folder's others.
  for (const auto& [name, model] : model_of) add(name, "");
  for (const std::string& name : ListImageFiles(image_dir)) {
    add(name, has_database ? "not in the workspace database: not extracted (added later, or "
                             "skipped by the run's scan: see its log)"
                           : "in no model");
  }
  return list;
}

}  // namespace tessera::gui
