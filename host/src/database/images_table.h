#pragma once

// COLMAP's `images` table: name and camera_id. COLMAP's pose priors are left NULL, as
// COLMAP 3.8 writes them when it has none.

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "database/sqlite_statement.h"
#include "tessera/ids.h"
#include "tessera/reconstruction.h"

namespace tessera {

class ImagesTable {
 public:
  // Prepares the statements; `connection` must outlive the table.
  explicit ImagesTable(const SqliteConnection& connection) : connection_(connection) {}

  // Returns the new id: image.image_id if use_image_id, else the next free one.
  image_t Insert(const Image& image, bool use_image_id) const;
  std::optional<Image> ReadWithName(const std::string& name) const;
  std::vector<Image> ReadAll() const;  // sorted by image_id
  void UpdateCamera(image_t image_id, camera_t camera_id) const;
  size_t Count() const;

 private:
  const SqliteConnection& connection_;
  SqliteStatement insert_{connection_,
                          "INSERT INTO images(image_id, name, camera_id) VALUES(?, ?, ?);"};
  // The columns of ImageFromRow.
  SqliteStatement read_with_name_{connection_,
                                  "SELECT image_id, name, camera_id FROM images WHERE name = ?;"};
  SqliteStatement read_all_{connection_,
                            "SELECT image_id, name, camera_id FROM images ORDER BY image_id;"};
  SqliteStatement update_camera_{connection_,
                                 "UPDATE images SET camera_id = ? WHERE image_id = ?;"};
  SqliteStatement count_{connection_, "SELECT COUNT(*) FROM images;"};
};

}  // namespace tessera
