#include "image/camera_assignment.h"

#include <spdlog/fmt/fmt.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <tuple>

#include "image/sensor_database.h"
#include "tessera/errors.h"

namespace tessera {
namespace {

constexpr double kPi = 3.14159265358979323846;
// Diagonal of the 36 x 24 mm frame that "35 mm equivalent" focal lengths refer to.
const double kFullFrameDiagonalMm = std::hypot(36.0, 24.0);

std::string FormatNumber(double value) {
  std::ostringstream stream;
  stream.precision(4);
  stream << value;
  return stream.str();
}

class PriorBuilder {
 public:
  PriorBuilder(const ImageEntry& image, std::vector<std::string>* warnings)
      : image_(image), warnings_(warnings) {}

  // Whether a positive EXIF value; warns about the others.
  bool IsPositive(const std::optional<double>& value, const char* tag, const char* unit) {
    if (!value) return false;
    if (*value > 0 && std::isfinite(*value)) return true;
    Warn("EXIF " + std::string(tag) + " of " + FormatNumber(*value) + unit +
         " is not positive; ignored.");
    return false;
  }

  // Whether the focal length gives a plausible field of view; warns about the others.
  bool IsPlausible(double focal_px, const std::string& what) {
    const double longer = std::max(image_.width, image_.height);
    if (IsPlausibleFocalLength(focal_px, longer)) return true;
    const double fov = FieldOfViewDeg(focal_px, longer);
    Warn("the focal length from " + what + " (" + FormatNumber(focal_px) +
         " px) gives a field of view of " + FormatNumber(fov) + " degrees, outside [" +
         FormatNumber(kMinPlausibleFieldOfViewDeg) + ", " +
         FormatNumber(kMaxPlausibleFieldOfViewDeg) + "]; ignored.");
    return false;
  }

 private:
  void Warn(const std::string& text) {
    if (warnings_ != nullptr) warnings_->push_back("Image '" + image_.name + "': " + text);
  }

  const ImageEntry& image_;
  std::vector<std::string>* warnings_;
};

// The focal length per image and where it came from.
struct ImagePrior {
  double focal_px;
  CalibrationSource source;
  bool has_prior;
};

double MedianOf(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const size_t mid = values.size() / 2;
  return values.size() % 2 == 1 ? values[mid] : (values[mid - 1] + values[mid]) / 2;
}

// "the 640x480 image 'a.jpg'", "the 3 images of 640x480 (the first 'a.jpg')".
std::string DescribeImagesOfSize(const std::vector<ImageEntry>& images,
                                 const std::vector<size_t>& indices) {
  const ImageEntry& first = images[indices.front()];
  const std::string dimensions = std::to_string(first.width) + "x" + std::to_string(first.height);
  return indices.size() == 1 ? "the " + dimensions + " image '" + first.name + "'"
                             : "the " + std::to_string(indices.size()) + " images of " +
                                   dimensions + " (the first '" + first.name + "')";
}

// Refuses a focal length of K that no lens gives on images of this size (K in other units,
// or a typo): a field of view outside [kMinPlausibleFieldOfViewDeg,
// kMaxPlausibleFieldOfViewDeg] across the longer side.
void CheckKnownFocalLengths(const CameraSettings& settings, const ImageEntry& image,
                            const std::string& these) {
  const Eigen::Vector4d& K = *settings.known_intrinsics;
  const double longer = std::max(image.width, image.height);
  for (const auto& [focal, name] : {std::pair{K(0), "fx"}, std::pair{K(1), "fy"}}) {
    if (IsPlausibleFocalLength(focal, longer)) continue;
    throw InputError(
        settings.known_intrinsics_source + ": " + name + " = " + FormatNumber(focal) +
        " px is implausible for the camera of " + these + ": a field of view of " +
        FormatNumber(FieldOfViewDeg(focal, longer)) + " degrees across the longer side, outside [" +
        FormatNumber(kMinPlausibleFieldOfViewDeg) + ", " +
        FormatNumber(kMaxPlausibleFieldOfViewDeg) + "]; give K in pixels of these images");
  }
}

// Which images a known K applies to. The K is checked as input first: what is wrong with
// it regardless of the images (settings.known_intrinsics_problems), and a focal length no
// lens gives on the images (always refused). It applies to the images of a size whose
// interior holds its principal point; when some size also has its centre within 10% of
// the image size of the principal point, only such sizes: on a folder of mixed sizes a K
// made for one size is not given to another whose interior merely holds the point. A K
// that fits none of the images is refused (it was given for another resolution). Each
// size it does not fit is named in a warning, and those images get the camera their EXIF
// or the default focal length gives; each size it applies to whose centre lies more than
// 10% of the image's size from the principal point is named in a warning too. A recipe
// that holds the intrinsics (settings.calibration_required_by) refuses all of these: no
// K, a problem of K, an image K does not fit or fits off centre, whose guessed or
// doubtful focal length it would hold.
std::vector<bool> ImagesKnownIntrinsicsFit(const std::vector<ImageEntry>& images,
                                           const CameraSettings& settings,
                                           std::vector<std::string>* warnings) {
  const bool required = !settings.calibration_required_by.empty();
  if (!settings.known_intrinsics) {
    if (required) {
      throw InputError(settings.calibration_required_by +
                       ": this recipe holds the intrinsics, and none were given: pass "
                       "--camera-K FILE, or set camera.K, camera.K_file or camera.params");
    }
    return std::vector<bool>(images.size(), false);
  }
  const Eigen::Vector4d& K = *settings.known_intrinsics;
  const std::string point =
      "the principal point (" + FormatNumber(K(2)) + ", " + FormatNumber(K(3)) + ")";
  std::map<std::pair<int, int>, std::vector<size_t>> images_by_size;
  for (size_t i = 0; i < images.size(); ++i) {
    images_by_size[{images[i].width, images[i].height}].push_back(i);
  }
  const auto inside = [&](int width, int height) {
    return K(2) > 0 && K(2) < width && K(3) > 0 && K(3) < height;
  };
  const auto centred = [&](int width, int height) {
    return inside(width, height) && std::abs(K(2) - width / 2.0) <= 0.1 * width &&
           std::abs(K(3) - height / 2.0) <= 0.1 * height;
  };
  bool any_inside = false, any_centred = false;
  for (const auto& [size, indices] : images_by_size) {
    any_inside = any_inside || inside(size.first, size.second);
    any_centred = any_centred || centred(size.first, size.second);
  }
  if (!images.empty() && !any_inside) {
    const ImageEntry& first = images.front();
    throw InputError(settings.known_intrinsics_source + ": " + point + " lies outside image '" +
                     first.name + "' (" + std::to_string(first.width) + "x" +
                     std::to_string(first.height) +
                     "); the intrinsics must be given for the images' resolution");
  }
  std::vector<bool> fits(images.size(), false);
  bool problems_said = false;
  for (const auto& [size, indices] : images_by_size) {
    const auto [width, height] = size;
    const std::string these = DescribeImagesOfSize(images, indices);
    const bool applies = inside(width, height) && (centred(width, height) || !any_centred);
    if (applies) {
      CheckKnownFocalLengths(settings, images[indices.front()], these);
      if (!settings.known_intrinsics_problems.empty() && required) {
        throw InputError(settings.calibration_required_by +
                         ": this recipe holds the intrinsics, and those given for the camera "
                         "of " +
                         these + " are wrong: " + settings.known_intrinsics_problems.front());
      }
      if (!problems_said) {
        for (const std::string& problem : settings.known_intrinsics_problems) {
          warnings->push_back(problem);
        }
        problems_said = true;
      }
      for (const size_t i : indices) fits[i] = true;
    }
    const double dx = K(2) - width / 2.0, dy = K(3) - height / 2.0;
    const std::string distance = FormatNumber(std::round(std::hypot(dx, dy))) + " px";
    const std::string off_centre = point + " lies " + distance + " from the centre of " + these;
    if (required && !(applies && centred(width, height))) {
      throw InputError(settings.calibration_required_by +
                       ": this recipe holds the intrinsics, and those of " +
                       settings.known_intrinsics_source + " do not fit " + these + " (" + point +
                       (inside(width, height) ? " lies " + distance +
                                                    " from their centre, more than 10% of the "
                                                    "image size"
                                              : " lies outside") +
                       "): give them for the images' resolution");
    }
    if (!inside(width, height)) {
      warnings->push_back(settings.known_intrinsics_source + ": " + point + " lies outside " +
                          these +
                          "; K is not used there: the EXIF or the default "
                          "focal length gives the camera");
    } else if (!applies) {
      warnings->push_back(settings.known_intrinsics_source + ": " + off_centre +
                          ", more than 10% of the image size, while K fits images of another "
                          "size; K is not used there: the EXIF or the default focal length "
                          "gives the camera");
    } else if (!centred(width, height)) {
      warnings->push_back(settings.known_intrinsics_source + ": " + off_centre +
                          ", more than 10% of the image size: were the intrinsics given for "
                          "another resolution?");
    }
  }
  return fits;
}

}  // namespace

std::string DescribeCamera(const Camera& camera) {
  return fmt::format("camera {} ({} {}x{}, focal {:.1f} px, {})", camera.camera_id,
                     camera.ModelName(), camera.width, camera.height, camera.MeanFocalLength(),
                     CalibrationSourceName(camera.calibration_source));
}

double FieldOfViewDeg(double focal_px, double longer_side_px) {
  return 2 * std::atan(longer_side_px / 2 / focal_px) * 180 / kPi;
}

bool IsPlausibleFocalLength(double focal_px, double longer_side_px) {
  const double fov = FieldOfViewDeg(focal_px, longer_side_px);
  return std::isfinite(fov) && fov >= kMinPlausibleFieldOfViewDeg &&
         fov <= kMaxPlausibleFieldOfViewDeg;
}

std::optional<FocalLengthPrior> EstimateFocalLengthPrior(const ImageEntry& image,
                                                         std::vector<std::string>* warnings) {
  const double longer = std::max(image.width, image.height);
  if (longer <= 0) return std::nullopt;
  const ExifInfo& exif = image.exif;
  PriorBuilder builder(image, warnings);

  if (builder.IsPositive(exif.focal_length_mm, "FocalLength", " mm")) {
    const double focal_mm = *exif.focal_length_mm;
    if (const auto sensor_width_mm = LookupSensorWidthMm(exif.make, exif.model)) {
      const double focal_px = focal_mm / *sensor_width_mm * longer;
      if (builder.IsPlausible(focal_px, "FocalLength " + FormatNumber(focal_mm) +
                                            " mm and a sensor width of " +
                                            FormatNumber(*sensor_width_mm) + " mm")) {
        return FocalLengthPrior{focal_px, CalibrationSource::kExifFocalLength};
      }
    } else if (exif.focal_plane_x_resolution && *exif.focal_plane_x_resolution > 0) {
      // The resolution refers to the image size the camera wrote; a resized copy
      // has proportionally fewer pixels per millimetre.
      double scale = 1;
      if (exif.pixel_x_dimension && exif.pixel_y_dimension) {
        scale = longer / std::max(*exif.pixel_x_dimension, *exif.pixel_y_dimension);
      }
      const double focal_px = focal_mm * *exif.focal_plane_x_resolution * scale;
      if (builder.IsPlausible(focal_px, "FocalLength " + FormatNumber(focal_mm) +
                                            " mm and FocalPlaneXResolution")) {
        return FocalLengthPrior{focal_px, CalibrationSource::kExifFocalLength};
      }
    }
  }
  if (builder.IsPositive(exif.focal_length_35mm, "FocalLengthIn35mmFilm", " mm")) {
    const double diagonal_px = std::hypot(image.width, image.height);
    const double focal_px = *exif.focal_length_35mm / kFullFrameDiagonalMm * diagonal_px;
    if (builder.IsPlausible(
            focal_px, "FocalLengthIn35mmFilm " + FormatNumber(*exif.focal_length_35mm) + " mm")) {
      return FocalLengthPrior{focal_px, CalibrationSource::kExif35mmEquivalent};
    }
  }
  return std::nullopt;
}

std::string ImageFolder(const std::string& image_name) {
  const size_t slash = image_name.rfind('/');
  return slash == std::string::npos ? "" : image_name.substr(0, slash);
}

std::string FisheyeLensHint(const std::vector<ImageEntry>& images, const CameraSettings& settings) {
  if (settings.model.find("FISHEYE") != std::string::npos) return "";
  size_t count = 0;
  const ImageEntry* first = nullptr;
  for (const ImageEntry& image : images) {
    if (image.exif.focal_length_35mm && *image.exif.focal_length_35mm > 0 &&
        *image.exif.focal_length_35mm < kFisheyeHint35mm) {
      if (!first) first = &image;
      ++count;
    }
  }
  if (!first) return "";
  return "'" + first->name + "'" +
         (count > 1 ? " and " + std::to_string(count - 1) + " other image(s)" : "") +
         ": EXIF FocalLengthIn35mmFilm " + FormatNumber(*first->exif.focal_length_35mm) +
         " mm suggests a fisheye or action-camera lens; camera.model OPENCV_FISHEYE models "
         "one (keeping " +
         settings.model + ")";
}

CameraAssignment AssignCameras(const std::vector<ImageEntry>& images,
                               const CameraSettings& settings) {
  const CameraModelId model_id = CameraModelNameToId(settings.model);
  if (model_id == CameraModelId::kInvalid) {
    std::string known;
    for (const CameraModelId id : AllCameraModelIds()) {
      known += (known.empty() ? "" : ", ") + CameraModelIdToName(id);
    }
    throw OptionError("camera.model", "unknown camera model '" + settings.model +
                                          "' (known models: " + known + ")");
  }
  if (!(settings.default_focal_length_factor > 0)) {
    throw OptionError("camera.default_focal_length_factor", "must be positive");
  }
  CameraAssignment assignment;
  const std::string hint = FisheyeLensHint(images, settings);
  if (!hint.empty()) assignment.notes.push_back(hint);

  for (const ImageEntry& image : images) {
    if (image.width <= 0 || image.height <= 0) {
      throw InputError(image.name + ": the image has no size");
    }
  }
  const std::vector<bool> uses_known =
      ImagesKnownIntrinsicsFit(images, settings, &assignment.warnings);

  // The intrinsics each image would get on its own.
  std::vector<ImagePrior> priors;
  priors.reserve(images.size());
  for (size_t i = 0; i < images.size(); ++i) {
    const ImageEntry& image = images[i];
    if (uses_known[i]) {
      priors.push_back({0, CalibrationSource::kUser, true});
      continue;
    }
    if (auto prior = EstimateFocalLengthPrior(image, &assignment.warnings)) {
      priors.push_back({prior->focal_px, prior->source, true});
    } else {
      priors.push_back({settings.default_focal_length_factor * std::max(image.width, image.height),
                        CalibrationSource::kDefault, false});
    }
  }

  // Groups of images sharing a camera, in order of their first image.
  using GroupKey = std::tuple<std::string, int, int, std::string, std::string>;
  std::map<GroupKey, size_t> group_of_key;
  std::vector<std::vector<size_t>> groups;
  for (size_t i = 0; i < images.size(); ++i) {
    const ImageEntry& image = images[i];
    if (!settings.single_camera) {
      groups.push_back({i});
      continue;
    }
    // Known intrinsics describe one physical camera whatever the EXIF says.
    const bool by_make = !uses_known[i];
    const GroupKey key(settings.per_folder ? ImageFolder(image.name) : "", image.width,
                       image.height, by_make ? image.exif.make : "",
                       by_make ? image.exif.model : "");
    const auto [it, inserted] = group_of_key.emplace(key, groups.size());
    if (inserted) groups.emplace_back();
    groups[it->second].push_back(i);
  }

  assignment.image_camera_ids.resize(images.size());
  for (const std::vector<size_t>& group : groups) {
    const ImageEntry& first = images[group.front()];
    const camera_t camera_id = static_cast<camera_t>(assignment.cameras.size() + 1);
    Camera camera;
    if (uses_known[group.front()]) {
      const Eigen::Vector4d& K = *settings.known_intrinsics;
      camera = Camera::Create(camera_id, model_id, (K(0) + K(1)) / 2, first.width, first.height);
      const std::vector<int> focal_idx = camera.FocalIdx();
      if (focal_idx.size() == 2) {
        camera.params[focal_idx[0]] = K(0);
        camera.params[focal_idx[1]] = K(1);
      }
      const std::vector<int> pp_idx = camera.PrincipalPointIdx();
      camera.params[pp_idx[0]] = K(2);
      camera.params[pp_idx[1]] = K(3);
      if (!settings.known_params.empty() && settings.known_intrinsics_source == "camera.params") {
        camera.params = settings.known_params;  // K from the command line overrides them
      }
      camera.has_prior_focal_length = true;
      camera.calibration_source = CalibrationSource::kUser;
    } else {
      std::vector<std::pair<double, CalibrationSource>> with_prior;
      for (const size_t i : group) {
        if (priors[i].has_prior) with_prior.emplace_back(priors[i].focal_px, priors[i].source);
      }
      if (with_prior.empty()) {
        camera = Camera::Create(camera_id, model_id, priors[group.front()].focal_px, first.width,
                                first.height);
        camera.has_prior_focal_length = false;
        camera.calibration_source = CalibrationSource::kDefault;
      } else {
        std::vector<double> focals;
        for (const auto& prior : with_prior) focals.push_back(prior.first);
        // The source of the lower-median image names where the median came from.
        std::sort(with_prior.begin(), with_prior.end(),
                  [](const auto& a, const auto& b) { return a.first < b.first; });
        camera = Camera::Create(camera_id, model_id, MedianOf(focals), first.width, first.height);
        camera.has_prior_focal_length = true;
        camera.calibration_source = with_prior[(with_prior.size() - 1) / 2].second;
      }
    }
    for (const size_t i : group) assignment.image_camera_ids[i] = camera_id;
    assignment.cameras.push_back(std::move(camera));
  }
  return assignment;
}

std::map<camera_t, std::string> CameraFolders(const std::vector<ImageEntry>& images,
                                              const CameraAssignment& assignment) {
  std::map<camera_t, std::string> folders;
  for (size_t i = 0; i < images.size() && i < assignment.image_camera_ids.size(); ++i) {
    folders.emplace(assignment.image_camera_ids[i], ImageFolder(images[i].name));
  }
  return folders;
}

std::map<camera_t, std::string> CameraFolders(const std::vector<Image>& images) {
  std::map<camera_t, std::string> folders;
  std::vector<camera_t> mixed;
  for (const Image& image : images) {
    const auto [it, inserted] = folders.emplace(image.camera_id, ImageFolder(image.name));
    if (!inserted && it->second != ImageFolder(image.name)) mixed.push_back(image.camera_id);
  }
  for (const camera_t id : mixed) folders.erase(id);
  return folders;
}

std::string DescribeCameraFolders(const std::map<camera_t, std::string>& folders) {
  constexpr size_t kMaxShown = 20;
  std::string text = std::to_string(folders.size()) +
                     (folders.size() == 1 ? " camera" : " cameras") +
                     " by folder (camera.per_folder): ";
  size_t shown = 0;
  for (const auto& [id, folder] : folders) {
    if (shown == kMaxShown) {
      text += " and " + std::to_string(folders.size() - kMaxShown) + " more";
      break;
    }
    text += (shown++ > 0 ? ", camera " : "camera ") + std::to_string(id) +
            (folder.empty() ? " from the top level" : " from '" + folder + "'");
  }
  return text;
}

}  // namespace tessera
