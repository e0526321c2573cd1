#pragma once

// Whether the Images field's folder holds the photographs of the model shown: each of
// the model's images must be there, at its camera's width and height. A model opened with
// another data set's folder (Herz-Jesus's model, fountain's folder) would otherwise show
// another photograph under the model's observations, with no warning.

#include <filesystem>
#include <map>
#include <memory>
#include <string>

#include "tessera/reconstruction.h"

namespace tessera::gui {

// What the camera window shows instead of a photograph that is missing or of another
// size: "image not found", or "image does not match the model's camera: WxH vs WxH"
// (the file's size, then the camera's). Empty when the photograph can be shown.
std::string PhotoProblem(bool found, int file_width, int file_height, const Camera& camera);

struct ImageFolderCheck {
  std::shared_ptr<const Reconstruction> model;  // the model checked (null: none)
  std::filesystem::path image_dir;              // the folder checked
  size_t num_images = 0;
  size_t missing = 0;     // not in the folder (or not a readable image)
  size_t mismatched = 0;  // of another size than the model's camera
  // Empty when every image is there at its camera's size; else a sentence with the
  // counts, e.g. "3 of 8 images of the model are not in /f and 5 of 8 do not match the
  // model's cameras' sizes: is it the model's image folder?" (also logged as a warning).
  std::string warning;
};

// Checks the model's images in `image_dir` from the files' headers (the files are read,
// not decoded). An empty `image_dir` or a null model gives no warning.
ImageFolderCheck CheckImageFolder(std::shared_ptr<const Reconstruction> model,
                                  const std::filesystem::path& image_dir);

}  // namespace tessera::gui
