// Undistorted images and a PINHOLE model, the input that 3D Gaussian Splatting trainers
// read as it is (the reference trainer accepts only PINHOLE and SIMPLE_PINHOLE cameras):
//   OUTPUT/<folder>/images/<name>                         undistorted images
//   OUTPUT/<folder>/sparse/0/{cameras,images,points3D}.bin the model of those images
//   OUTPUT/<folder>/masks/<name>.png                      with mask_path: their masks

#include <cctype>
#include <map>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "tessera/io/colmap_model_io.h"
#include "tessera/io/exporter_paths.h"
#include "tessera/io/file_io.h"
#include "tessera/io/image_io.h"
#include "tessera/sdk.h"

namespace tessera {
namespace {

// The camera of the undistorted images. Size, focal lengths and principal point stay
// those of the original camera, as COLMAP's image_undistorter keeps them by default:
// nothing is cropped or scaled, and only the corners that barrel distortion pulls in
// are left black (for pincushion distortion the border of the original is cut off).
Camera PinholeCamera(const Camera& camera) {
  Camera pinhole = camera;
  pinhole.model_id = CameraModelId::kPinhole;
  pinhole.params = {camera.FocalLengthX(), camera.FocalLengthY(), camera.PrincipalPointX(),
                    camera.PrincipalPointY()};
  return pinhole;
}

// cv::remap maps: for every pixel of the undistorted image, the position to read in the
// original. Pixel (col, row) has its centre at (col + 0.5, row + 0.5) in COLMAP's
// coordinates and at (col, row) in OpenCV's.
struct UndistortionMaps {
  cv::Mat map_x;
  cv::Mat map_y;
};

UndistortionMaps MakeUndistortionMaps(const Camera& camera, const Camera& pinhole) {
  const int width = static_cast<int>(camera.width), height = static_cast<int>(camera.height);
  UndistortionMaps maps{cv::Mat(height, width, CV_32FC1), cv::Mat(height, width, CV_32FC1)};
  const Eigen::Matrix3d K_inverse = pinhole.CalibrationMatrix().inverse();
  cv::parallel_for_(cv::Range(0, height), [&](const cv::Range& rows) {
    for (int row = rows.start; row < rows.end; ++row) {
      float* map_x = maps.map_x.ptr<float>(row);
      float* map_y = maps.map_y.ptr<float>(row);
      for (int col = 0; col < width; ++col) {
        const Eigen::Vector3d ray = K_inverse * Eigen::Vector3d(col + 0.5, row + 0.5, 1);
        const Eigen::Vector2d source = camera.ImgFromCam(ray);
        map_x[col] = static_cast<float>(source.x() - 0.5);
        map_y[col] = static_cast<float>(source.y() - 0.5);
      }
    }
  });
  return maps;
}

std::string EncodeImage(const cv::Mat& image, const std::filesystem::path& path, int jpeg_quality) {
  std::string extension = path.extension().string();  // OpenCV chooses the codec by it
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  std::vector<uchar> bytes;
  bool encoded = false;
  try {
    encoded = cv::imencode(extension, image, bytes, {cv::IMWRITE_JPEG_QUALITY, jpeg_quality});
  } catch (const cv::Exception&) {
    encoded = false;
  }
  if (!encoded) {
    throw InputError(path.string() + ": cannot encode the undistorted image as '" +
                     path.extension().string() + "'");
  }
  return std::string(bytes.begin(), bytes.end());
}

// The mask of image `name` as the extract stage finds it: DIR/NAME.png, else NAME with
// its extension replaced by .png. Empty when neither exists.
std::filesystem::path FindMask(const std::filesystem::path& dir, const std::string& name) {
  std::error_code error;
  const std::filesystem::path colmap = dir / (name + ".png");
  if (std::filesystem::is_regular_file(colmap, error)) return colmap;
  std::filesystem::path replaced = dir / name;
  replaced.replace_extension(".png");
  if (std::filesystem::is_regular_file(replaced, error)) return replaced;
  return {};
}

}  // namespace

class GaussianSplattingExporter : public Exporter {
 public:
  explicit GaussianSplattingExporter(const nlohmann::json& options) {
    OptionReader reader(options);
    folder_ = reader.GetRelativePath("folder", "gaussian_splatting");
    jpeg_quality_ = reader.Get<int>("jpeg_quality", 95, 1, 100);
    mask_path_ = reader.GetString("mask_path", "");
    reader.Finish();
    effective_options_ = reader.Effective();
  }

  // Writes OUTPUT/<folder> for model 0 and OUTPUT/<folder>_<k> for model k, each a
  // complete scene folder with sparse/0 as the trainers expect.
  void Export(const Reconstruction& reconstruction, const ExportContext& context) const override {
    const std::filesystem::path root = PerModelPath(context, folder_);
    if (context.image_dir.empty()) {
      throw InputError(root.string() +
                       ": the gaussian_splatting exporter needs the image folder to undistort "
                       "(tessera export --images DIR)");
    }
    Reconstruction undistorted = reconstruction;
    for (auto& [camera_id, camera] : undistorted.cameras) camera = PinholeCamera(camera);
    std::map<camera_t, UndistortionMaps> maps;
    for (auto& [image_id, image] : undistorted.images) {
      if (!image.registered) continue;
      const Camera& camera = reconstruction.cameras.at(image.camera_id);
      const Camera& pinhole = undistorted.cameras.at(image.camera_id);
      for (Point2D& point2D : image.points2D) {
        point2D.xy = pinhole.ImgFromCam(camera.CamFromImg(point2D.xy).homogeneous());
      }
      const std::filesystem::path source = context.image_dir / image.name;
      cv::Mat pixels = ReadColorImage(source);
      if (static_cast<size_t>(pixels.cols) != camera.width ||
          static_cast<size_t>(pixels.rows) != camera.height) {
        throw InputError(source.string() + ": the image is " + std::to_string(pixels.cols) + "x" +
                         std::to_string(pixels.rows) + " but its camera " +
                         std::to_string(camera.camera_id) + " is " + std::to_string(camera.width) +
                         "x" + std::to_string(camera.height));
      }
      if (camera.HasDistortion()) {
        auto it = maps.find(camera.camera_id);
        if (it == maps.end()) {
          it = maps.emplace(camera.camera_id, MakeUndistortionMaps(camera, pinhole)).first;
        }
        cv::Mat remapped;
        cv::remap(pixels, remapped, it->second.map_x, it->second.map_y, cv::INTER_LINEAR,
                  cv::BORDER_CONSTANT, cv::Scalar::all(0));
        pixels = remapped;
      }
      const std::filesystem::path target = root / "images" / image.name;
      CreateFolder(target.parent_path());
      WriteFileAtomically(target, EncodeImage(pixels, target, jpeg_quality_));
      if (!mask_path_.empty()) {
        const std::filesystem::path mask_file = FindMask(mask_path_, image.name);
        cv::Mat mask;
        if (!mask_file.empty()) mask = cv::imread(mask_file.string(), cv::IMREAD_GRAYSCALE);
        // No mask, or one of another size: none written (the extract stage warned).
        if (mask.cols == pixels.cols && mask.rows == pixels.rows) {
          if (camera.HasDistortion()) {
            const UndistortionMaps& map = maps.at(camera.camera_id);
            cv::Mat remapped;
            cv::remap(mask, remapped, map.map_x, map.map_y, cv::INTER_NEAREST, cv::BORDER_CONSTANT,
                      cv::Scalar::all(0));
            mask = remapped;
          }
          const std::filesystem::path mask_target = root / "masks" / (image.name + ".png");
          CreateFolder(mask_target.parent_path());
          WriteFileAtomically(mask_target, EncodeImage(mask, mask_target, jpeg_quality_));
        }
      }
    }
    // Last, so that a model in place means its images are complete.
    WriteColmapModel(undistorted, root / "sparse" / "0", ColmapModelFormat::kBinary);
  }

 private:
  std::string folder_;
  int jpeg_quality_ = 95;
  std::string mask_path_;  // empty: no masks written
};

}  // namespace tessera

TESSERA_PLUGIN(exporter, tessera::GaussianSplattingExporter, "gaussian_splatting", "1.0.0",
               "Undistorted images and a PINHOLE COLMAP model for 3D Gaussian Splatting "
               "trainers: gaussian_splatting/{images,sparse/0}")
