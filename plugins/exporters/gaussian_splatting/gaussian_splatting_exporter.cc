// Undistorted images and a PINHOLE model, the input that 3D Gaussian Splatting trainers
// read as it is (the reference trainer accepts only PINHOLE and SIMPLE_PINHOLE cameras):
//   OUTPUT/<folder>/images/<name>                         undistorted images
//   OUTPUT/<folder>/sparse/0/{cameras,images,points3D}.bin the model of those images
//   OUTPUT/<folder>/masks/<name>.png                      with masks: theirs
// With field_of_view "full" the images are larger and hold the whole field of a wide
// lens; every image then gets a mask, black on the blank border.

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <map>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "common/exported_camera.h"
#include "tessera/io/colmap_model_io.h"
#include "tessera/io/exporter_paths.h"
#include "tessera/io/file_io.h"
#include "tessera/io/image_io.h"
#include "tessera/sdk.h"

namespace tessera {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The reference 3DGS trainer's COLMAP loader keeps only the focal lengths (its field of
// view is 2 atan(size / 2f)) and puts the principal point at the image centre, so every
// exported camera has it there: within this many pixels counts as there.
constexpr double kCentredPx = 1e-6;

bool PrincipalPointCentred(const Camera& camera) {
  return std::abs(camera.PrincipalPointX() - static_cast<double>(camera.width) / 2) <= kCentredPx &&
         std::abs(camera.PrincipalPointY() - static_cast<double>(camera.height) / 2) <= kCentredPx;
}

// "(dx, dy) px": how far the principal point is from the image centre.
std::string FormatOffset(const Camera& camera) {
  char text[64];
  std::snprintf(text, sizeof(text), "(%+.2f, %+.2f) px",
                camera.PrincipalPointX() - static_cast<double>(camera.width) / 2,
                camera.PrincipalPointY() - static_cast<double>(camera.height) / 2);
  return text;
}

// The pixels of the undistorted image differ from the original's: resampled.
bool NeedsResampling(const Camera& camera) {
  return camera.HasDistortion() || !PrincipalPointCentred(camera);
}

// The camera of the undistorted images with field_of_view "crop": the original's focal
// lengths, as COLMAP's image_undistorter keeps them (nothing is scaled; the corners that
// barrel distortion pulls in are black, and pincushion distortion or a fisheye lens
// loses the original's border). The principal point is the image centre: an off-centre
// one (refined by bundle adjustment) keeps the largest window of the original centred on
// it, width 2 min(cx, W - cx) and height 2 min(cy, H - cy) rounded down to even pixels,
// so that no pixel is blank. Throws InputError when no pixel is left.
Camera PinholeCamera(const Camera& camera) {
  Camera pinhole = camera;
  pinhole.model_id = CameraModelId::kPinhole;
  if (!PrincipalPointCentred(camera)) {
    const double cx = camera.PrincipalPointX(), cy = camera.PrincipalPointY();
    const double half_width =
        std::floor(std::min(cx, static_cast<double>(camera.width) - cx) + kCentredPx);
    const double half_height =
        std::floor(std::min(cy, static_cast<double>(camera.height) - cy) + kCentredPx);
    if (half_width < 1 || half_height < 1) {
      throw InputError("camera " + std::to_string(camera.camera_id) + ": its principal point (" +
                       std::to_string(cx) + ", " + std::to_string(cy) + ") lies outside its " +
                       std::to_string(camera.width) + "x" + std::to_string(camera.height) +
                       " image: no centred window of it is left");
    }
    pinhole.width = static_cast<size_t>(2 * half_width);
    pinhole.height = static_cast<size_t>(2 * half_height);
  }
  pinhole.params = {camera.FocalLengthX(), camera.FocalLengthY(),
                    static_cast<double>(pinhole.width) / 2,
                    static_cast<double>(pinhole.height) / 2};
  return pinhole;
}

// The largest |x| and |y| on the normalized image plane of the rays that the original
// camera sees through a pixel centre, up to `max_ray_angle` radians off the optical axis.
struct FieldExtent {
  double x = 0;
  double y = 0;
};

// The kept rays form a region whose extremes lie on its boundary: the image border (every
// border pixel centre, within the angle) and the circle of rays at the angle limit (where
// it projects inside the image; where it meets the border is found by bisection).
FieldExtent MeasureFieldExtent(const Camera& camera, double max_ray_angle) {
  const double width = static_cast<double>(camera.width);
  const double height = static_cast<double>(camera.height);
  const double max_radius = std::tan(max_ray_angle);
  FieldExtent extent;
  const auto keep = [&](const Eigen::Vector2d& normalized) {
    extent.x = std::max(extent.x, std::abs(normalized.x()));
    extent.y = std::max(extent.y, std::abs(normalized.y()));
  };
  const auto keep_border_pixel = [&](double x, double y) {
    const Eigen::Vector2d pixel(x, y);
    const Eigen::Vector2d normalized = camera.CamFromImg(pixel);
    if (!normalized.allFinite() || normalized.norm() > max_radius) return;
    // A fisheye pixel beyond what the model can reach (rays past 90 degrees) does not
    // come back to itself: it is outside every pinhole image.
    if ((camera.ImgFromCam(normalized.homogeneous()) - pixel).norm() > 1e-3) return;
    keep(normalized);
  };
  for (double x = 0.5; x < width; x += 1) {
    keep_border_pixel(x, 0.5);
    keep_border_pixel(x, height - 0.5);
  }
  for (double y = 0.5; y < height; y += 1) {
    keep_border_pixel(0.5, y);
    keep_border_pixel(width - 0.5, y);
  }
  const auto on_limit = [&](double angle) {
    return Eigen::Vector2d(max_radius * std::cos(angle), max_radius * std::sin(angle));
  };
  const auto inside = [&](double angle) {
    const Eigen::Vector2d pixel = camera.ImgFromCam(on_limit(angle).homogeneous());
    return pixel.allFinite() && pixel.x() >= 0.5 && pixel.x() <= width - 0.5 && pixel.y() >= 0.5 &&
           pixel.y() <= height - 0.5;
  };
  constexpr int kDirections = 4096;  // a multiple of 4: the axes' directions are sampled
  const double step = 2 * kPi / kDirections;
  for (int i = 0; i < kDirections; ++i) {
    const double angle = i * step;
    const bool here = inside(angle);
    if (here) keep(on_limit(angle));
    if (here == inside(angle + step)) continue;
    double in = here ? angle : angle + step, out = here ? angle + step : angle;
    for (int k = 0; k < 40; ++k) {
      const double middle = (in + out) / 2;
      (inside(middle) ? in : out) = middle;
    }
    keep(on_limit(in));
  }
  return extent;
}

// The camera of the undistorted images with field_of_view "full": every pixel of the
// original whose ray is at most `max_ray_angle` off the axis lands inside the image, with
// a pixel to spare. The principal point is the image centre (the reference 3DGS trainer
// assumes it there). The focal lengths stay the original's unless the image would then
// be more than `max_scale` times the original's width or height: then both shrink by
// the same factor until it fits.
Camera FullFieldPinholeCamera(const Camera& camera, double max_scale, double max_ray_angle) {
  const FieldExtent extent = MeasureFieldExtent(camera, max_ray_angle);
  const double fx = camera.FocalLengthX(), fy = camera.FocalLengthY();
  constexpr double kMargin = 1;  // pixels beyond the outermost pixel centre
  const double max_half_width = std::floor(max_scale * static_cast<double>(camera.width) / 2);
  const double max_half_height = std::floor(max_scale * static_cast<double>(camera.height) / 2);
  // A hair under the limit, so that rounding the size up stays within max_scale.
  constexpr double kUnder = 1 - 1e-12;
  double scale = 1;
  if (fx * extent.x > 0) {
    scale = std::min(scale, kUnder * (max_half_width - kMargin) / (fx * extent.x));
  }
  if (fy * extent.y > 0) {
    scale = std::min(scale, kUnder * (max_half_height - kMargin) / (fy * extent.y));
  }
  const double half_width = std::max(1.0, std::ceil(scale * fx * extent.x + kMargin));
  const double half_height = std::max(1.0, std::ceil(scale * fy * extent.y + kMargin));
  Camera pinhole = camera;
  pinhole.model_id = CameraModelId::kPinhole;
  pinhole.width = static_cast<size_t>(2 * half_width);
  pinhole.height = static_cast<size_t>(2 * half_height);
  pinhole.params = {scale * fx, scale * fy, half_width, half_height};
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
  const int width = static_cast<int>(pinhole.width), height = static_cast<int>(pinhole.height);
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

// `name` with its control characters escaped (\n, \r, \t, \0, else \xHH), for a
// message on one line.
std::string Printable(const std::string& name) {
  std::string printable;
  for (const char c : name) {
    const auto byte = static_cast<unsigned char>(c);
    if (byte >= 0x20 && byte != 0x7f) {
      printable += c;
    } else if (c == '\n' || c == '\r' || c == '\t' || c == '\0') {
      printable += c == '\n' ? "\\n" : c == '\r' ? "\\r" : c == '\t' ? "\\t" : "\\0";
    } else {
      char escaped[5];
      std::snprintf(escaped, sizeof(escaped), "\\x%02x", byte);
      printable += escaped;
    }
  }
  return printable;
}

// Why the image name `name` cannot be a path below a folder; empty when it can. It may
// not resolve outside the folder (absolute, more '..' than folders), hold a NUL (which
// cuts the path short) or name the folder itself.
std::string WhyNotBelowFolder(const std::string& name) {
  const std::filesystem::path path(name);
  const std::filesystem::path normal = path.lexically_normal();
  if (name.find('\0') != std::string::npos) return "holds a NUL, which cuts the path short";
  if (path.has_root_path() || (!normal.empty() && *normal.begin() == "..")) {
    return "would be written outside this folder";
  }
  if (normal.empty() || normal.filename().empty() || normal.filename() == ".") {
    return "names no file";
  }
  return "";
}

// Image names become paths below OUTPUT/<folder>/images and masks: each is checked before
// anything is written. The model readers refuse unsafe names already; this guards
// models that reach the exporter by another way.
void CheckImageNames(const Reconstruction& reconstruction, const std::filesystem::path& root) {
  for (const auto& [image_id, image] : reconstruction.images) {
    if (!image.registered) continue;
    const std::string why = WhyNotBelowFolder(image.name);
    if (!why.empty()) {
      throw InputError((root / "images").string() + ": image " + std::to_string(image_id) +
                       " has the name '" + Printable(image.name) + "', which " + why);
    }
  }
}

}  // namespace

struct GaussianSplattingOptions {
  // The scene folder written for model 0, inside the output folder.
  std::string folder = "gaussian_splatting";
  int jpeg_quality = 95;
  // A folder of image masks; empty: the run's masks.
  std::string mask_path;
  // "crop" (the original's size and focal lengths) or "full" (the whole field).
  std::string field_of_view = "crop";
  // With "full" only: the largest output size, in times the original's, and the largest
  // ray angle off the optical axis, in degrees.
  double max_scale = 2.0;
  double max_ray_angle = 80.0;
};

// The options, listed once: read, checked and described (`tessera plugins
// gaussian_splatting`) from here.
template <typename Visit>
void VisitGaussianSplattingOptions(GaussianSplattingOptions& o, const Visit& visit) {
  visit("folder", option_list::RelativePath{o.folder},
        "output folder, a relative path inside the output folder");
  visit("jpeg_quality", o.jpeg_quality, 1, 100, "JPEG quality of the written images");
  visit("mask_path", o.mask_path,
        "a folder of image masks for this exporter; empty: the run's masks");
  visit("field_of_view", o.field_of_view, option_list::Choices{"crop", "full"},
        "crop: the original's size and focal lengths, the periphery of a wide lens cut off; "
        "full: a larger image holding the whole field, its blank border masked");
  visit("max_scale", o.max_scale, 1.0, 10.0,
        "with full only: the largest output width and height, in times the original's");
  visit("max_ray_angle", o.max_ray_angle, 1.0, 89.0,
        "with full only: rays further off the optical axis, in degrees, are not kept");
}

class GaussianSplattingExporter : public Exporter {
 public:
  explicit GaussianSplattingExporter(const nlohmann::json& options) {
    OptionReader reader(options);
    GaussianSplattingOptions parsed;
    VisitGaussianSplattingOptions(parsed, option_list::Reader(&reader));
    folder_ = parsed.folder;
    jpeg_quality_ = parsed.jpeg_quality;
    mask_path_ = parsed.mask_path;
    full_field_ = parsed.field_of_view == "full";
    max_scale_ = parsed.max_scale;
    max_ray_angle_degrees_ = parsed.max_ray_angle;
    reader.Finish();
    nlohmann::json effective = reader.Effective();
    for (const char* key : {"max_scale", "max_ray_angle"}) {
      if (full_field_) continue;
      // Meaningless when cropping: a value given there is a mistake worth naming.
      if (reader.Has(key)) {
        throw OptionError(key,
                          "is used only with field_of_view \"full\" (field_of_view is "
                          "\"crop\")");
      }
      effective.erase(key);
    }
    effective_options_ = effective;
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
    // Before anything is written: a focal length of 0 would undistort every image to black.
    try {
      CheckExportedCameras(reconstruction);
    } catch (const InputError& error) {
      throw InputError((root / "sparse" / "0").string() + ": " + error.what());
    }
    CheckImageNames(reconstruction, root);
    Reconstruction undistorted = reconstruction;
    for (auto& [camera_id, camera] : undistorted.cameras) {
      // A camera without distortion, its principal point centred, is kept as it is.
      camera = full_field_ && NeedsResampling(camera)
                   ? FullFieldPinholeCamera(camera, max_scale_, max_ray_angle_degrees_ * kPi / 180)
                   : PinholeCamera(camera);
      if (!PrincipalPointCentred(reconstruction.cameras.at(camera_id))) {
        const Camera& original = reconstruction.cameras.at(camera_id);
        log().Info("camera " + std::to_string(camera_id) + ": principal point " +
                   FormatOffset(original) + " off the image centre; written centred, " +
                   std::to_string(camera.width) + "x" + std::to_string(camera.height) +
                   ", as 3DGS trainers assume it");
      }
    }
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
      if (NeedsResampling(camera)) {
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
      cv::Mat mask;  // of the written image; empty: none written
      // The option names a folder for this exporter only; else the run's masks.
      const std::filesystem::path mask_dir =
          !mask_path_.empty() ? std::filesystem::path(mask_path_) : context.mask_dir;
      if (!mask_dir.empty()) {
        const std::filesystem::path mask_file = FindMask(mask_dir, image.name);
        if (!mask_file.empty()) mask = cv::imread(mask_file.string(), cv::IMREAD_GRAYSCALE);
        // No mask, or one of another size: none from mask_path (the extract stage warned).
        if (mask.cols != static_cast<int>(camera.width) ||
            mask.rows != static_cast<int>(camera.height)) {
          mask = cv::Mat();
        }
      }
      const bool blank_borders = full_field_ && NeedsResampling(camera);
      if (mask.empty() && blank_borders) {
        // The blank borders of the larger image are masked out: the original, all white.
        mask = cv::Mat(static_cast<int>(camera.height), static_cast<int>(camera.width), CV_8UC1,
                       cv::Scalar(255));
      }
      if (!mask.empty()) {
        if (NeedsResampling(camera)) {
          const UndistortionMaps& map = maps.at(camera.camera_id);
          cv::Mat remapped;  // black outside the original
          cv::remap(mask, remapped, map.map_x, map.map_y, cv::INTER_NEAREST, cv::BORDER_CONSTANT,
                    cv::Scalar::all(0));
          mask = remapped;
        }
        const std::filesystem::path mask_target = root / "masks" / (image.name + ".png");
        CreateFolder(mask_target.parent_path());
        WriteFileAtomically(mask_target, EncodeImage(mask, mask_target, jpeg_quality_));
      }
    }
    // Last, so that a model in place means its images are complete.
    WriteColmapModel(undistorted, root / "sparse" / "0", ColmapModelFormat::kBinary);
  }

 private:
  std::string folder_;
  int jpeg_quality_ = 95;
  std::string mask_path_;    // empty: no masks written
  bool full_field_ = false;  // field_of_view "full": nothing of the original cut off
  double max_scale_ = 2.0;
  double max_ray_angle_degrees_ = 80.0;
};

}  // namespace tessera

TESSERA_PLUGIN_OPTIONS(tessera::GaussianSplattingOptions, tessera::VisitGaussianSplattingOptions)
TESSERA_PLUGIN(exporter, tessera::GaussianSplattingExporter, "gaussian_splatting", "1.0.0",
               "Undistorted images and a PINHOLE COLMAP model for 3D Gaussian Splatting "
               "trainers: gaussian_splatting/{images,sparse/0}")
