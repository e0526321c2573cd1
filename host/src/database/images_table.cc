#include "database/images_table.h"

#include "database/colmap_row_codecs.h"

namespace tessera {

image_t ImagesTable::Insert(const Image& image, bool use_image_id) const {
  SqliteStatement::Use use(insert_, "write image '" + image.name + "'");
  if (use_image_id) {
    use.BindInt64(1, image.image_id);
  } else {
    use.BindNull(1);
  }
  use.BindText(2, image.name);
  use.BindInt64(3, image.camera_id);
  use.Step();
  return static_cast<image_t>(connection_.LastInsertRowId());
}

std::optional<Image> ImagesTable::ReadWithName(const std::string& name) const {
  SqliteStatement::Use use(read_with_name_, "read image '" + name + "'");
  use.BindText(1, name);
  if (!use.Step()) return std::nullopt;
  return ImageFromRow(use);
}

std::vector<Image> ImagesTable::ReadAll() const {
  SqliteStatement::Use use(read_all_, "read the images");
  std::vector<Image> images;
  while (use.Step()) images.push_back(ImageFromRow(use));
  return images;
}

void ImagesTable::UpdateCamera(image_t image_id, camera_t camera_id) const {
  SqliteStatement::Use use(update_camera_, "set the camera of image " + std::to_string(image_id));
  use.BindInt64(1, camera_id);
  use.BindInt64(2, image_id);
  use.Step();
}

size_t ImagesTable::Count() const {
  return static_cast<size_t>(count_.QueryInt64("count the images"));
}

}  // namespace tessera
