// The 3D points as a binary little-endian PLY (x y z red green blue), which MeshLab,
// CloudCompare, Open3D and Blender open unchanged; optionally the camera centres as
// extra vertices in their own colour.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "tessera/io/exporter_paths.h"
#include "tessera/io/file_io.h"
#include "tessera/io/point_colors.h"
#include "tessera/sdk.h"

namespace tessera {
namespace {

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__,
              "the PLY writer copies numbers as they lie in memory");

using Color = Eigen::Matrix<uint8_t, 3, 1>;

// Per point, the mean over its observations of the image colour there (the host's
// sampler); any image that cannot be used is an error naming the file.
std::map<point3D_t, Color> SampleTrackColors(const Reconstruction& reconstruction,
                                             const std::filesystem::path& image_dir) {
  Reconstruction colored = reconstruction;
  const std::vector<std::string> warnings = ColorPointsFromImages(image_dir, &colored);
  if (!warnings.empty()) throw InputError(warnings.front());
  std::map<point3D_t, Color> colors;
  for (const auto& [point3D_id, point3D] : colored.points3D) colors[point3D_id] = point3D.color;
  return colors;
}

template <typename T>
void Append(std::string* buffer, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  buffer->append(bytes, sizeof(T));
}

}  // namespace

// Which frame the coordinates are in: a PLY comment line.
std::string FrameComment(const tessera::ExportContext& context) {
  if (!context.georeference) return "comment frame: arbitrary (not georeferenced)\n";
  char line[200];
  std::snprintf(line, sizeof(line),
                "comment frame: ENU metres, origin latitude %.9f longitude %.9f altitude %.3f\n",
                context.georeference->latitude_deg, context.georeference->longitude_deg,
                context.georeference->altitude_m);
  return line;
}

struct PlyOptions {
  // Coordinates as "float" or "double".
  std::string precision = "float";
  // Point colours: "auto", "model" or "images".
  std::string colors = "auto";
  // Add the camera centres as extra vertices, in camera_center_color ([r, g, b]).
  bool camera_centers = false;
  nlohmann::json camera_center_color = nlohmann::json::array({255, 0, 0});
};

// The options, listed once: read, checked and described (`tessera plugins ply`) from here.
template <typename Visit>
void VisitPlyOptions(PlyOptions& o, const Visit& visit) {
  visit("precision", o.precision, option_list::Choices{"float", "double"},
        "float or double coordinates");
  visit("colors", o.colors, option_list::Choices{"auto", "model", "images"},
        "point colours: auto (the model's, sampled from the images when all are unset), model or "
        "images");
  visit("camera_centers", o.camera_centers, "add the camera centres as extra vertices");
  visit("camera_center_color", o.camera_center_color,
        "their colour, [red, green, blue], each an integer in [0, 255]");
}

class PlyExporter : public Exporter {
 public:
  explicit PlyExporter(const nlohmann::json& options) {
    OptionReader reader(options);
    PlyOptions parsed;
    VisitPlyOptions(parsed, option_list::Reader(&reader));
    double_precision_ = parsed.precision == "double";
    colors_ = parsed.colors;
    camera_centers_ = parsed.camera_centers;
    const nlohmann::json& color = parsed.camera_center_color;
    bool valid = color.is_array() && color.size() == 3;
    for (size_t i = 0; valid && i < 3; ++i) {
      valid =
          color[i].is_number_integer() && color[i].get<int>() >= 0 && color[i].get<int>() <= 255;
      if (valid) camera_center_color_(i) = static_cast<uint8_t>(color[i].get<int>());
    }
    if (!valid) {
      throw OptionError(
          reader.KeyPath("camera_center_color"),
          "expected [red, green, blue], each an integer in [0, 255], got " + color.dump());
    }
    reader.Finish();
    effective_options_ = reader.Effective();
  }

  // Writes OUTPUT/sparse/<model_index>/points3D.ply.
  void Export(const Reconstruction& reconstruction, const ExportContext& context) const override {
    const std::filesystem::path path = SparseModelDir(context) / "points3D.ply";
    const std::map<point3D_t, Color> colors = PointColors(reconstruction, context, path);
    std::vector<Eigen::Vector3d> centers;
    if (camera_centers_) {
      for (const auto& [image_id, image] : reconstruction.images) {
        if (image.registered) centers.push_back(image.ProjectionCenter());
      }
    }
    const char* type = double_precision_ ? "double" : "float";
    std::string ply = "ply\nformat binary_little_endian 1.0\ncomment Tessera: " +
                      std::to_string(reconstruction.points3D.size()) + " 3D points, then " +
                      std::to_string(centers.size()) + " camera centres\n" + FrameComment(context) +
                      "element vertex " +
                      std::to_string(reconstruction.points3D.size() + centers.size()) + "\n";
    for (const char* axis : {"x", "y", "z"})
      ply += std::string("property ") + type + " " + axis + "\n";
    ply += "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n";
    const auto append_vertex = [&](const Eigen::Vector3d& xyz, const Color& color) {
      for (int k = 0; k < 3; ++k) {
        if (double_precision_) {
          Append<double>(&ply, xyz(k));
        } else {
          Append<float>(&ply, static_cast<float>(xyz(k)));
        }
      }
      for (int k = 0; k < 3; ++k) Append<uint8_t>(&ply, color(k));
    };
    for (const auto& [point3D_id, point3D] : reconstruction.points3D) {
      append_vertex(point3D.xyz, colors.at(point3D_id));
    }
    for (const Eigen::Vector3d& center : centers) append_vertex(center, camera_center_color_);
    CreateFolder(path.parent_path());
    WriteFileAtomically(path, ply);
  }

 private:
  std::map<point3D_t, Color> PointColors(const Reconstruction& reconstruction,
                                         const ExportContext& context,
                                         const std::filesystem::path& path) const {
    const bool unset = std::all_of(reconstruction.points3D.begin(), reconstruction.points3D.end(),
                                   [](const auto& item) { return item.second.color.isZero(); });
    if (colors_ == "model" || (colors_ == "auto" && !unset) || reconstruction.points3D.empty()) {
      std::map<point3D_t, Color> colors;
      for (const auto& [point3D_id, point3D] : reconstruction.points3D) {
        colors[point3D_id] = point3D.color;
      }
      return colors;
    }
    if (context.image_dir.empty()) {
      throw InputError(path.string() + ": " +
                       (colors_ == "auto" ? "every point's colour is unset and " : "") +
                       "no image folder was given to sample colours from (tessera export "
                       "--images DIR), or set the ply option colors to \"model\"");
    }
    return SampleTrackColors(reconstruction, context.image_dir);
  }

  bool double_precision_ = false;
  std::string colors_;
  bool camera_centers_ = false;
  Color camera_center_color_ = Color(255, 0, 0);
};

}  // namespace tessera

TESSERA_PLUGIN_OPTIONS(tessera::PlyOptions, tessera::VisitPlyOptions)
TESSERA_PLUGIN(exporter, tessera::PlyExporter, "ply", "1.0.0",
               "3D points (and optionally camera centres) as a coloured binary PLY: "
               "sparse/N/points3D.ply")
