// Bundler v0.3 (bundle.out + list.txt), as a third party would write a Tessera
// exporter: the SDK headers and Tessera::io (image decoding as detection saw the
// images, atomic writes, per-model output paths), and TESSERA_PLUGIN at the end.
//
//   OUTPUT/<folder>/bundle.out     cameras (f k1 k2, R, t) and points (xyz, rgb, views)
//   OUTPUT/<folder>/list.txt       one line per camera: images/<name>
//   OUTPUT/<folder>/images/<name>  the registered images as detection saw them
//
// Bundler's camera looks down -z with y up, COLMAP's down +z with y down: R and t are
// COLMAP's with rows 2 and 3 negated. A view's x, y are relative to the image centre,
// y up. Images are copied with the EXIF orientation applied, since the keypoints are
// positions in the image as displayed; Bundler readers ignore EXIF.

#include <cctype>
#include <cstdio>
#include <locale>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "tessera/io/exporter_paths.h"
#include "tessera/io/file_io.h"
#include "tessera/io/image_io.h"
#include "tessera/sdk.h"

namespace {

namespace fs = std::filesystem;

// Bundler's f, k1, k2 of a camera: models with a single focal length (or fx, fy
// averaged, as COLMAP's Bundler export does) and at most two radial terms.
struct BundlerIntrinsics {
  double f = 0, k1 = 0, k2 = 0;
};

BundlerIntrinsics ToBundler(const tessera::Camera& camera, const std::string& image_name) {
  const std::vector<double>& p = camera.params;
  switch (camera.model_id) {
    case tessera::CameraModelId::kSimplePinhole:
      return {p[0], 0, 0};
    case tessera::CameraModelId::kPinhole:
      return {(p[0] + p[1]) / 2, 0, 0};
    case tessera::CameraModelId::kSimpleRadial:
      return {p[0], p[3], 0};
    case tessera::CameraModelId::kRadial:
      return {p[0], p[3], p[4]};
    default:
      throw tessera::InputError("bundler: image '" + image_name + "': camera model " +
                                camera.ModelName() +
                                " has no Bundler equivalent (SIMPLE_PINHOLE, PINHOLE, "
                                "SIMPLE_RADIAL or RADIAL)");
  }
}

std::ostringstream MakeStream() {
  std::ostringstream stream;
  stream.imbue(std::locale::classic());
  stream.precision(17);
  return stream;
}

// The image as detection saw it: the file's bytes when it is stored upright, else the
// decoded pixels (EXIF orientation applied) encoded again in the same format.
std::string ImageAsDetected(const fs::path& path, const tessera::Camera& camera) {
  const auto bytes = tessera::ReadFileBytes(path);
  if (!bytes) throw tessera::InputError(path.string() + ": cannot read the image file");
  tessera::ImageFileHeader header;
  const std::string problem = tessera::InspectImageData(*bytes, &header, nullptr);
  if (!problem.empty()) throw tessera::InputError(path.string() + ": " + problem);
  const cv::Mat pixels = tessera::ReadColorImage(path);
  if (static_cast<size_t>(pixels.cols) != camera.width ||
      static_cast<size_t>(pixels.rows) != camera.height) {
    throw tessera::InputError(path.string() + ": the image is " + std::to_string(pixels.cols) +
                              "x" + std::to_string(pixels.rows) + ", its camera " +
                              std::to_string(camera.width) + "x" + std::to_string(camera.height));
  }
  if (header.exif.orientation == 1) return std::string(bytes->begin(), bytes->end());
  std::string extension = path.extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  std::vector<uchar> encoded;
  if (!cv::imencode(extension, pixels, encoded, {cv::IMWRITE_JPEG_QUALITY, 95})) {
    throw tessera::InputError(path.string() + ": cannot encode the upright image");
  }
  return std::string(encoded.begin(), encoded.end());
}

struct BundlerOptions {
  // The folder written, inside the output folder.
  std::string folder = "bundler";
};

// The options, listed once: read by the constructor and described by
// TESSERA_PLUGIN_OPTIONS below (`tessera plugins bundler`).
template <typename Visit>
void VisitBundlerOptions(BundlerOptions& o, const Visit& visit) {
  visit("folder", tessera::option_list::RelativePath{o.folder},
        "the folder written for model 0 (model k: FOLDER_k), inside the output folder");
}

class BundlerExporter : public tessera::Exporter {
 public:
  explicit BundlerExporter(const nlohmann::json& options) {
    tessera::OptionReader reader(options);
    BundlerOptions parsed;
    VisitBundlerOptions(parsed, tessera::option_list::Reader(&reader));
    folder_ = parsed.folder;
    reader.Finish();
    effective_options_ = reader.Effective();
  }

  void Export(const tessera::Reconstruction& reconstruction,
              const tessera::ExportContext& context) const override {
    const fs::path dir = tessera::PerModelPath(context, folder_);
    tessera::CreateFolder(dir);
    // Cameras: the registered images by ascending id; their index in this order is the
    // camera index of the views.
    std::map<tessera::image_t, int> camera_index;
    std::ostringstream cameras = MakeStream();
    std::string list;
    for (const auto& [image_id, image] : reconstruction.images) {
      if (!image.registered) continue;
      camera_index[image_id] = static_cast<int>(camera_index.size());
      const tessera::Camera& camera = reconstruction.cameras.at(image.camera_id);
      const BundlerIntrinsics intrinsics = ToBundler(camera, image.name);
      cameras << intrinsics.f << " " << intrinsics.k1 << " " << intrinsics.k2 << "\n";
      Eigen::Matrix3d R = image.cam_from_world.rotation.toRotationMatrix();
      Eigen::Vector3d t = image.cam_from_world.translation;
      R.row(1) *= -1;
      R.row(2) *= -1;
      t(1) *= -1;
      t(2) *= -1;
      for (int row = 0; row < 3; ++row) {
        cameras << R(row, 0) << " " << R(row, 1) << " " << R(row, 2) << "\n";
      }
      cameras << t(0) << " " << t(1) << " " << t(2) << "\n";
      const fs::path copy = dir / "images" / image.name;
      tessera::CreateFolder(copy.parent_path());
      tessera::WriteFileAtomically(copy, ImageAsDetected(context.image_dir / image.name, camera));
      list += "images/" + image.name + "\n";
    }

    std::ostringstream points = MakeStream();
    for (const auto& [point3D_id, point3D] : reconstruction.points3D) {
      points << point3D.xyz(0) << " " << point3D.xyz(1) << " " << point3D.xyz(2) << "\n"
             << static_cast<int>(point3D.color(0)) << " " << static_cast<int>(point3D.color(1))
             << " " << static_cast<int>(point3D.color(2)) << "\n"
             << point3D.track.size();
      for (const tessera::TrackElement& element : point3D.track) {
        const tessera::Image& image = reconstruction.images.at(element.image_id);
        const tessera::Camera& camera = reconstruction.cameras.at(image.camera_id);
        const Eigen::Vector2d& xy = image.points2D.at(element.point2D_idx).xy;
        points << " " << camera_index.at(element.image_id) << " " << element.point2D_idx << " "
               << xy.x() - camera.width / 2.0 << " " << camera.height / 2.0 - xy.y();
      }
      points << "\n";
    }

    const std::string bundle = "# Bundle file v0.3\n" + std::to_string(camera_index.size()) + " " +
                               std::to_string(reconstruction.points3D.size()) + "\n" +
                               cameras.str() + points.str();
    tessera::WriteFileAtomically(dir / "bundle.out", bundle);
    tessera::WriteFileAtomically(dir / "list.txt", list);
  }

 private:
  std::string folder_;
};

}  // namespace

TESSERA_PLUGIN_OPTIONS(BundlerOptions, VisitBundlerOptions)
TESSERA_PLUGIN(exporter, BundlerExporter, "bundler", "1.0.0",
               "Bundler v0.3 bundle.out + list.txt, with the images as detected")
