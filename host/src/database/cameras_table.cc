#include "database/cameras_table.h"

#include <stdexcept>

#include "database/colmap_row_codecs.h"

namespace tessera {

void CamerasTable::CheckWritable(const Camera& camera) const {
  if (camera.IsValid()) return;
  throw std::invalid_argument(
      "Database '" + connection_.path().string() + "': cannot write camera " +
      std::to_string(camera.camera_id) + " of model '" + camera.ModelName() + "' with " +
      std::to_string(camera.params.size()) + " parameters and size " +
      std::to_string(camera.width) + "x" + std::to_string(camera.height) + ".");
}

void CamerasTable::CheckUpdatable(const Camera& camera) const {
  if (camera.IsValid()) return;
  throw std::invalid_argument("Database '" + connection_.path().string() +
                              "': cannot update camera " + std::to_string(camera.camera_id) +
                              " of model '" + camera.ModelName() + "' with " +
                              std::to_string(camera.params.size()) + " parameters.");
}

camera_t CamerasTable::Insert(const Camera& camera, bool use_camera_id,
                              const std::string& operation) const {
  SqliteStatement::Use use(insert_, operation);
  if (use_camera_id) {
    use.BindInt64(1, camera.camera_id);
  } else {
    use.BindNull(1);
  }
  use.BindInt64(2, static_cast<int>(camera.model_id));
  use.BindInt64(3, static_cast<int64_t>(camera.width));
  use.BindInt64(4, static_cast<int64_t>(camera.height));
  use.BindBlob(5, camera.params.data(), sizeof(double) * camera.params.size());
  use.BindInt64(6, camera.has_prior_focal_length ? 1 : 0);
  use.Step();
  return static_cast<camera_t>(connection_.LastInsertRowId());
}

void CamerasTable::Update(const Camera& camera, const std::string& operation) const {
  {
    SqliteStatement::Use use(update_, operation);
    use.BindInt64(1, static_cast<int>(camera.model_id));
    use.BindInt64(2, static_cast<int64_t>(camera.width));
    use.BindInt64(3, static_cast<int64_t>(camera.height));
    use.BindBlob(4, camera.params.data(), sizeof(double) * camera.params.size());
    use.BindInt64(5, camera.has_prior_focal_length ? 1 : 0);
    use.BindInt64(6, camera.camera_id);
    use.Step();
  }
  if (connection_.NumChangedRows() == 0) {
    throw std::runtime_error("Database '" + connection_.path().string() +
                             "': cannot update camera " + std::to_string(camera.camera_id) +
                             ": there is no such camera.");
  }
}

std::vector<Camera> CamerasTable::ReadAll() const {
  SqliteStatement::Use use(read_all_, "read the cameras");
  std::vector<Camera> cameras;
  while (use.Step()) cameras.push_back(CameraFromRow(use));
  return cameras;
}

std::optional<Camera> CamerasTable::Read(camera_t camera_id) const {
  SqliteStatement::Use use(read_, "read camera " + std::to_string(camera_id));
  use.BindInt64(1, camera_id);
  if (!use.Step()) return std::nullopt;
  return CameraFromRow(use);
}

size_t CamerasTable::Count() const {
  return static_cast<size_t>(count_.QueryInt64("count the cameras"));
}

}  // namespace tessera
