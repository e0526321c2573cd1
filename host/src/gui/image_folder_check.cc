#include "gui/image_folder_check.h"

#include <spdlog/spdlog.h>

#include "tessera/io/image_io.h"

namespace tessera::gui {
namespace fs = std::filesystem;

std::string PhotoProblem(bool found, int file_width, int file_height, const Camera& camera) {
  if (!found) return "image not found";
  if (static_cast<size_t>(file_width) == camera.width &&
      static_cast<size_t>(file_height) == camera.height) {
    return "";
  }
  return "image does not match the model's camera: " + std::to_string(file_width) + "x" +
         std::to_string(file_height) + " vs " + std::to_string(camera.width) + "x" +
         std::to_string(camera.height);
}

namespace {

// The image's size as displayed (EXIF orientation applied), from its headers; false when
// the file is not there or not a usable image.
bool ReadDisplayedSize(const fs::path& file, int* width, int* height) {
  std::error_code error;
  if (!fs::is_regular_file(file, error)) return false;
  const auto bytes = ReadFileBytes(file);
  if (!bytes) return false;
  ImageFileHeader header;
  if (!InspectImageData(*bytes, &header, nullptr).empty()) return false;
  const bool swap = OrientationSwapsAxes(header.exif.orientation);
  *width = swap ? header.stored_height : header.stored_width;
  *height = swap ? header.stored_width : header.stored_height;
  return true;
}

}  // namespace

ImageFolderCheck CheckImageFolder(std::shared_ptr<const Reconstruction> model,
                                  const fs::path& image_dir) {
  ImageFolderCheck check;
  check.model = std::move(model);
  check.image_dir = image_dir;
  if (check.model == nullptr || image_dir.empty()) return check;
  for (const auto& [image_id, image] : check.model->images) {
    ++check.num_images;
    int width = 0, height = 0;
    const bool found = ReadDisplayedSize(image_dir / image.name, &width, &height);
    const auto camera = check.model->cameras.find(image.camera_id);
    if (!found) {
      ++check.missing;
    } else if (camera != check.model->cameras.end() &&
               !PhotoProblem(true, width, height, camera->second).empty()) {
      ++check.mismatched;
    }
  }
  if (check.missing == 0 && check.mismatched == 0) return check;
  const std::string total = std::to_string(check.num_images);
  std::string counts;
  if (check.missing > 0) {
    counts = std::to_string(check.missing) + " of " + total + " images of the model are not in " +
             image_dir.string();
  }
  if (check.mismatched > 0) {
    counts += counts.empty()
                  ? std::to_string(check.mismatched) + " of " + total + " images in " +
                        image_dir.string() + " do not match"
                  : " and " + std::to_string(check.mismatched) + " of " + total + " do not match";
    counts += " the model's cameras' sizes";
  }
  check.warning = counts + ": is it the model's image folder?";
  spdlog::warn("gui: {}", check.warning);
  return check;
}

}  // namespace tessera::gui
