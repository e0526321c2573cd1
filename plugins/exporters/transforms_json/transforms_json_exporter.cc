// Camera poses and intrinsics as the transforms.json that instant-ngp and nerfstudio
// read: per frame the camera-to-world matrix with OpenGL camera axes (x right, y up,
// z backwards) and the image path relative to the JSON file; intrinsics as an OPENCV
// camera (fl_x fl_y cx cy w h k1 k2 p1 p2), at the top when every frame shares one
// camera, else in each frame.

#include <algorithm>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "common/exported_camera.h"
#include "tessera/io/exporter_paths.h"
#include "tessera/io/file_io.h"
#include "tessera/sdk.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

bool IsFisheye(const Camera& camera) {
  return camera.model_id == CameraModelId::kOpenCVFisheye ||
         camera.model_id == CameraModelId::kSimpleRadialFisheye;
}

// The camera as OPENCV intrinsics, or OPENCV_FISHEYE ones (k1..k4) for the fisheye
// models; models with one focal length give fl_x = fl_y, and coefficients a model lacks
// are zero.
nlohmann::json Intrinsics(const Camera& camera) {
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0;
  const std::vector<double>& params = camera.params;
  if (IsFisheye(camera)) {
    const std::vector<int> extra = camera.ExtraParamsIdx();
    nlohmann::json json = {{"fl_x", camera.FocalLengthX()},
                           {"fl_y", camera.FocalLengthY()},
                           {"cx", camera.PrincipalPointX()},
                           {"cy", camera.PrincipalPointY()},
                           {"w", camera.width},
                           {"h", camera.height}};
    for (size_t k = 0; k < 4; ++k) {
      json["k" + std::to_string(k + 1)] = k < extra.size() ? params[extra[k]] : 0.0;
    }
    return json;
  }
  switch (camera.model_id) {
    case CameraModelId::kSimpleRadial:
      k1 = params[3];
      break;
    case CameraModelId::kRadial:
      k1 = params[3];
      k2 = params[4];
      break;
    case CameraModelId::kOpenCV:
      k1 = params[4];
      k2 = params[5];
      p1 = params[6];
      p2 = params[7];
      break;
    case CameraModelId::kSimplePinhole:
    case CameraModelId::kPinhole:
      break;
    default:
      throw InputError("camera " + std::to_string(camera.camera_id) + " has model '" +
                       camera.ModelName() + "', which transforms.json cannot express");
  }
  return {{"fl_x", camera.FocalLengthX()},
          {"fl_y", camera.FocalLengthY()},
          {"cx", camera.PrincipalPointX()},
          {"cy", camera.PrincipalPointY()},
          {"w", camera.width},
          {"h", camera.height},
          {"k1", k1},
          {"k2", k2},
          {"p1", p1},
          {"p2", p2}};
}

// 4x4 camera-to-world with OpenGL camera axes: the OpenCV camera's y and z flipped.
nlohmann::json TransformMatrix(const Rigid3d& cam_from_world) {
  const Rigid3d world_from_cam = cam_from_world.Inverse();
  Eigen::Matrix4d matrix = Eigen::Matrix4d::Identity();
  matrix.topLeftCorner<3, 3>() =
      world_from_cam.rotation.toRotationMatrix() * Eigen::Vector3d(1, -1, -1).asDiagonal();
  matrix.topRightCorner<3, 1>() = world_from_cam.translation;
  nlohmann::json rows = nlohmann::json::array();
  for (int row = 0; row < 4; ++row) {
    rows.push_back({matrix(row, 0), matrix(row, 1), matrix(row, 2), matrix(row, 3)});
  }
  return rows;
}

// `path` made absolute and with every link resolved: a reader opens
// dirname(transforms.json)/file_path through the file system, which follows a link
// before it applies "..", so the relative path is computed between real folders.
fs::path RealPath(const fs::path& path) { return fs::weakly_canonical(fs::absolute(path)); }

// Where image `name` lies, relative to `json_dir` (the JSON's folder once placed: where
// its readers resolve file_path), with '/' separators. Without an image folder:
// nerfstudio's layout, images/<name> beside the JSON. Either way the image must be there:
// a path that resolves to nothing is an InputError, never written.
std::string FilePath(const fs::path& json_dir, const fs::path& image_dir, const std::string& name) {
  const fs::path image = (image_dir.empty() ? json_dir / "images" : image_dir) / name;
  std::error_code error;
  if (!fs::is_regular_file(image, error)) {
    throw InputError(image_dir.empty()
                         ? "the image folder is unknown (tessera export --images "
                           "DIR) and " +
                               image.string() + " does not exist: file_path would name no image"
                         : "image '" + name + "': " + image.string() +
                               " does not exist: file_path would name no image");
  }
  if (image_dir.empty()) return (fs::path("images") / name).generic_string();
  // Its file name kept, even if it is a link.
  return (RealPath(image.parent_path()) / image.filename())
      .lexically_relative(RealPath(json_dir))
      .generic_string();
}

}  // namespace

struct TransformsJsonOptions {
  // The JSON file written, inside the output folder.
  std::string file = "transforms.json";
};

// The options, listed once: read, checked and described (`tessera plugins transforms_json`).
template <typename Visit>
void VisitTransformsJsonOptions(TransformsJsonOptions& o, const Visit& visit) {
  visit("file", option_list::RelativePath{o.file},
        "the JSON file, a relative path inside the output folder");
}

class TransformsJsonExporter : public Exporter {
 public:
  explicit TransformsJsonExporter(const nlohmann::json& options) {
    OptionReader reader(options);
    TransformsJsonOptions parsed;
    VisitTransformsJsonOptions(parsed, option_list::Reader(&reader));
    file_ = parsed.file;
    reader.Finish();
    effective_options_ = reader.Effective();
  }

  // Writes OUTPUT/<file> for model 0 and OUTPUT/<file stem>_<k>.json for model k.
  void Export(const Reconstruction& reconstruction, const ExportContext& context) const override {
    const fs::path path = PerModelPath(context, file_);
    std::vector<const Image*> frames;
    for (const auto& [image_id, image] : reconstruction.images) {
      if (image.registered) frames.push_back(&image);
    }
    std::sort(frames.begin(), frames.end(),
              [](const Image* a, const Image* b) { return a->name < b->name; });
    const bool shared_camera =
        !frames.empty() && std::all_of(frames.begin(), frames.end(), [&](const Image* image) {
          return image->camera_id == frames.front()->camera_id;
        });

    nlohmann::json json = nlohmann::json::object();
    try {
      // Readers take "fl_x": 0.0 at its word: a camera no lens has is refused.
      for (const Image* image : frames) {
        CheckExportedCamera(reconstruction.cameras.at(image->camera_id));
      }
      if (shared_camera) json = Intrinsics(reconstruction.cameras.at(frames.front()->camera_id));
      // Both readers take the camera model from the top level only: one for all frames.
      size_t num_fisheye = 0;
      for (const Image* image : frames) {
        num_fisheye += IsFisheye(reconstruction.cameras.at(image->camera_id));
      }
      if (num_fisheye > 0 && num_fisheye < frames.size()) {
        throw InputError(
            "fisheye and other cameras in one model: transforms.json has one "
            "camera_model for all frames");
      }
      json["camera_model"] = num_fisheye > 0 ? "OPENCV_FISHEYE" : "OPENCV";
      // Which frame transform_matrix is in: GPS-anchored east-north-up metres, or none.
      if (context.georeference) {
        json["georeference"] = {{"latitude", context.georeference->latitude_deg},
                                {"longitude", context.georeference->longitude_deg},
                                {"altitude", context.georeference->altitude_m},
                                {"frame", context.georeference->frame}};
      }
      json["frames"] = nlohmann::json::array();
      for (const Image* image : frames) {
        nlohmann::json frame = shared_camera
                                   ? nlohmann::json::object()
                                   : Intrinsics(reconstruction.cameras.at(image->camera_id));
        frame["file_path"] =
            FilePath(PlacedPath(context, path).parent_path(), context.image_dir, image->name);
        frame["transform_matrix"] = TransformMatrix(image->cam_from_world);
        frame["colmap_im_id"] = image->image_id;
        json["frames"].push_back(frame);
      }
    } catch (const InputError& error) {
      throw InputError(path.string() + ": " + error.what());
    }
    CreateFolder(path.parent_path());
    WriteFileAtomically(path, json.dump(2) + "\n");
  }

 private:
  std::string file_;
};

}  // namespace tessera

TESSERA_PLUGIN_OPTIONS(tessera::TransformsJsonOptions, tessera::VisitTransformsJsonOptions)
TESSERA_PLUGIN(exporter, tessera::TransformsJsonExporter, "transforms_json", "1.0.0",
               "Poses and OPENCV intrinsics as the transforms.json of instant-ngp and "
               "nerfstudio (camera-to-world, OpenGL axes)")
