#pragma once

// Test helper (header only): a workspace as a run leaves it, with an image left out.
// database.db holds frame_1..4.jpg; sparse/0 is SmallColmapModel (frame_1..3) and
// sparse/1 frame_4 alone, registered there (what a model folder says when no summary
// does); mapping_summary.json (when asked for) puts frame_1..3 in model 0 and says why
// frame_4 was left out; images/ holds the four and late.png, added after the run.

#include <filesystem>
#include <fstream>
#include <string>

#include "database/database.h"
#include "pipeline/mapping_summary.h"
#include "small_colmap_model.h"
#include "tessera/io/colmap_model_io.h"

namespace tessera::gui {

inline constexpr const char* kLeftOutReason = "no verified pair with a registered image";

inline void WriteImageListWorkspace(const std::filesystem::path& workspace, bool with_summary) {
  namespace fs = std::filesystem;
  const Reconstruction model = tessera::testing::SmallColmapModel();
  WriteColmapModel(model, workspace / "sparse" / "0", ColmapModelFormat::kBinary);
  Reconstruction other;
  other.cameras[1] = model.cameras.at(1);
  Image& fourth = other.images[4];
  fourth.image_id = 4;
  fourth.camera_id = 1;
  fourth.name = "frame_4.jpg";
  fourth.registered = true;
  WriteColmapModel(other, workspace / "sparse" / "1", ColmapModelFormat::kBinary);
  {
    Database database(workspace / "database.db");
    database.WriteCamera(model.cameras.at(1), /*use_camera_id=*/true);
    for (image_t image_id = 1; image_id <= 4; ++image_id) {
      Image image;
      image.image_id = image_id;
      image.camera_id = 1;
      image.name = "frame_" + std::to_string(image_id) + ".jpg";
      database.WriteImage(image, /*use_image_id=*/true);
    }
  }
  fs::create_directories(workspace / "images");
  for (const char* name :
       {"frame_1.jpg", "frame_2.jpg", "frame_3.jpg", "frame_4.jpg", "late.png", "notes.txt"}) {
    std::ofstream(workspace / "images" / name) << "x";
  }
  if (!with_summary) return;
  MappingSummary summary;
  MappingSummary::Model first;
  first.index = 0;
  first.folder = (workspace / "sparse" / "0").string();
  first.num_images = 3;
  first.images = {"frame_1.jpg", "frame_2.jpg", "frame_3.jpg"};
  summary.models.push_back(first);
  summary.unregistered.push_back({"frame_4.jpg", kLeftOutReason});
  summary.Write(workspace / "mapping_summary.json");
}

}  // namespace tessera::gui
