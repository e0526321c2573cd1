#include "toolbox/model_alignment.h"

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "estimators/ransac.h"
#include "geometry/similarity_estimator.h"
#include "pipeline/workspace.h"
#include "tessera/errors.h"
#include "tessera/io/colmap_model_io.h"
#include "tessera/io/exif.h"
#include "tessera/io/file_io.h"
#include "tessera/io/georeference_io.h"
#include "tessera/sfm/gps_similarity.h"
#include "toolbox/toolbox_outputs.h"
#include "util/angles.h"
#include "util/random.h"
#include "util/statistics.h"
#include "util/timer.h"

namespace tessera {
namespace {

// The median distance of `positions` from their coordinate-wise median: a scale of the
// scene that outliers do not move.
double RobustSpread(const std::vector<Eigen::Vector3d>& positions) {
  Eigen::Vector3d median;
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<double> values;
    for (const Eigen::Vector3d& position : positions) values.push_back(position(axis));
    median(axis) = UpperMedian(values);
  }
  std::vector<double> distances;
  for (const Eigen::Vector3d& position : positions) distances.push_back((position - median).norm());
  return UpperMedian(distances);
}

void SetResiduals(const std::vector<double>& residuals, Alignment* alignment) {
  alignment->residual_mean = residuals.empty()
                                 ? 0
                                 : std::accumulate(residuals.begin(), residuals.end(), 0.0) /
                                       static_cast<double>(residuals.size());
  alignment->residual_max =
      residuals.empty() ? 0 : *std::max_element(residuals.begin(), residuals.end());
}

// The camera's up direction (-y of the camera) in the world.
Eigen::Vector3d UpInWorld(const Image& image) {
  return -(image.cam_from_world.rotation.toRotationMatrix().row(1).transpose());
}

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * 180 / kPi;
}

nlohmann::json VectorJson(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

// Planes n . x + d = 0 (|n| = 1, n_z > 0) whose normal lies within max_tilt of +Z, for
// estimators/ransac.h: three points, or the least-squares plane of more.
class HorizontalPlaneEstimator {
 public:
  using X_t = Eigen::Vector3d;
  using Y_t = Eigen::Vector3d;  // unused: the points themselves
  using M_t = Eigen::Vector4d;
  static constexpr int kMinNumSamples = 3;

  HorizontalPlaneEstimator() = default;
  explicit HorizontalPlaneEstimator(double max_tilt_deg)
      : min_cos_(std::cos(max_tilt_deg * kPi / 180)) {}

  std::vector<M_t> Estimate(const std::vector<X_t>& X, const std::vector<Y_t>&) const {
    if (X.size() < 3) return {};
    Eigen::Vector3d normal;
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (const X_t& x : X) centroid += x;
    centroid /= static_cast<double>(X.size());
    if (X.size() == 3) {
      normal = (X[1] - X[0]).cross(X[2] - X[0]);
      if (normal.norm() < 1e-12) return {};
      normal.normalize();
    } else {
      Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
      for (const X_t& x : X) scatter += (x - centroid) * (x - centroid).transpose();
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(scatter);
      normal = solver.eigenvectors().col(0);
    }
    if (normal.z() < 0) normal = -normal;
    if (!(normal.z() >= min_cos_)) return {};
    M_t plane;
    plane << normal, -normal.dot(centroid);
    return {plane};
  }

  void Residuals(const std::vector<X_t>& X, const std::vector<Y_t>&, const M_t& plane,
                 std::vector<double>* residuals) const {
    residuals->resize(X.size());
    for (size_t i = 0; i < X.size(); ++i) {
      const double distance = plane.head<3>().dot(X[i]) + plane(3);
      (*residuals)[i] = distance * distance;
    }
  }

 private:
  double min_cos_ = std::cos(30 * kPi / 180);
};

Eigen::Matrix3d RotationOnto(const Eigen::Vector3d& from, const Eigen::Vector3d& to) {
  return Eigen::Quaterniond::FromTwoVectors(from, to).toRotationMatrix();
}

}  // namespace

nlohmann::json Alignment::ToJson() const {
  const Eigen::Quaterniond quaternion(new_from_old.rotation);
  nlohmann::json rotation = nlohmann::json::array();
  for (int row = 0; row < 3; ++row) {
    rotation.push_back({new_from_old.rotation(row, 0), new_from_old.rotation(row, 1),
                        new_from_old.rotation(row, 2)});
  }
  nlohmann::json json = {
      {"method", method},
      {"maps", "x_new = scale * rotation * x_model + translation"},
      {"scale", new_from_old.scale},
      {"rotation", rotation},
      {"quaternion_wxyz", {quaternion.w(), quaternion.x(), quaternion.y(), quaternion.z()}},
      {"translation", VectorJson(new_from_old.translation)},
      {"num_inliers", num_inliers},
      {"residuals", {{"unit", residual_unit}, {"mean", residual_mean}, {"max", residual_max}}},
  };
  if (method == "upright") {
    json["inlier_point_ids"] = inlier_point_ids;
  } else {
    json["inliers"] = inlier_names;
  }
  for (const auto& [key, value] : details.items()) json[key] = value;
  return json;
}

Alignment AlignToReference(const Reconstruction& model, const Reconstruction& reference,
                           const std::string& model_name, const std::string& reference_name,
                           const ReferenceAlignmentOptions& options) {
  std::map<std::string, const Image*> reference_by_name;
  for (const auto& [image_id, image] : reference.images) {
    if (image.registered) reference_by_name[image.name] = &image;
  }
  std::vector<SimilaritySample> source, target;
  std::vector<std::string> names;
  for (const auto& [image_id, image] : model.images) {
    if (!image.registered) continue;
    const auto it = reference_by_name.find(image.name);
    if (it == reference_by_name.end()) continue;
    SimilaritySample from, to;
    from.position = image.ProjectionCenter();
    to.position = it->second->ProjectionCenter();
    from.id = to.id = names.size();
    source.push_back(from);
    target.push_back(to);
    names.push_back(image.name);
  }
  const std::string both = model_name + " and " + reference_name;
  if (names.size() < static_cast<size_t>(SimilarityEstimator::kMinNumSamples)) {
    throw InputError(both + " share " + std::to_string(names.size()) +
                     " registered images by name; aligning them needs at least 3");
  }
  std::vector<Eigen::Vector3d> target_positions, source_positions;
  for (size_t i = 0; i < names.size(); ++i) {
    target_positions.push_back(target[i].position);
    source_positions.push_back(source[i].position);
  }
  if (NearlyCollinear(target_positions) || NearlyCollinear(source_positions)) {
    throw InputError("the camera centres of the " + std::to_string(names.size()) + " images that " +
                     both + " share lie on a line: the rotation about it is open");
  }
  RANSACOptions ransac;
  ransac.max_error =
      options.max_error > 0 ? options.max_error : 0.05 * RobustSpread(target_positions);
  ransac.confidence = 0.9999;
  ransac.min_inlier_ratio = 0.25;
  ransac.max_num_trials = 10000;
  const auto report =
      LORANSAC<SimilarityEstimator, SimilarityEstimator>(ransac, DeriveSeed(options.seed, 0xa119))
          .Estimate(source, target);
  if (!report.success) {
    throw InputError("no similarity maps " + model_name + " onto " + reference_name + " within " +
                     std::to_string(ransac.max_error) + " (the reference's units)");
  }
  // The least-squares fit on the inliers (Umeyama), as the mappers' GPS anchoring ends.
  std::vector<Eigen::Vector3d> src, dst;
  Alignment alignment;
  alignment.method = "reference";
  for (size_t i = 0; i < names.size(); ++i) {
    if (!report.inlier_mask[i]) continue;
    src.push_back(source_positions[i]);
    dst.push_back(target_positions[i]);
    alignment.inlier_names.push_back(names[i]);
  }
  alignment.new_from_old = EstimateSimilarity(src, dst);
  alignment.num_inliers = src.size();
  std::vector<double> residuals;
  for (size_t i = 0; i < src.size(); ++i) {
    residuals.push_back((alignment.new_from_old * src[i] - dst[i]).norm());
  }
  alignment.residual_unit = "reference units (camera centre distance)";
  SetResiduals(residuals, &alignment);
  alignment.details = {{"reference", reference_name},
                       {"num_shared_images", names.size()},
                       {"max_error", ransac.max_error}};
  return alignment;
}

Alignment AlignToGps(const Reconstruction& model, const std::map<image_t, ImageMetadata>& metadata,
                     const std::string& model_name, const GpsAnchoringOptions& options,
                     uint64_t seed) {
  const GpsSimilarity found = EstimateGpsSimilarity(metadata, options, seed, model);
  if (!found.report.anchored) {
    throw InputError(model_name + ": cannot be aligned to its GPS: " + found.report.reason);
  }
  Alignment alignment;
  alignment.method = "gps";
  alignment.new_from_old.scale = found.scale;
  alignment.new_from_old.rotation = found.rotation;
  alignment.new_from_old.translation = found.translation;
  std::vector<double> residuals;
  for (size_t i = 0; i < found.images.size(); ++i) {
    if (!found.agreeing[i]) continue;
    const Image& image = model.images.at(found.images[i]);
    alignment.inlier_names.push_back(image.name);
    residuals.push_back((alignment.new_from_old * image.ProjectionCenter() - found.enu[i]).norm());
  }
  alignment.num_inliers = alignment.inlier_names.size();
  alignment.residual_unit = "m (camera centre to its GPS position)";
  SetResiduals(residuals, &alignment);
  alignment.georeference = found.report.origin;
  nlohmann::json set_aside = nlohmann::json::array();
  for (const GpsTagSetAside& tag : found.report.set_aside) {
    set_aside.push_back({{"image", model.images.at(tag.image_id).name}, {"reason", tag.reason}});
  }
  alignment.details = {{"origin",
                        {{"latitude", found.report.origin.latitude_deg},
                         {"longitude", found.report.origin.longitude_deg},
                         {"altitude", found.report.origin.altitude_m},
                         {"frame", "ENU"}}},
                       {"num_geotagged", found.report.num_geotagged},
                       {"set_aside", set_aside},
                       {"max_error_m", found.threshold_m}};
  return alignment;
}

Alignment AlignUpright(const Reconstruction& model, const std::string& model_name,
                       const UprightOptions& options) {
  Eigen::Vector3d up_sum = Eigen::Vector3d::Zero();
  size_t num_images = 0;
  for (const auto& [image_id, image] : model.images) {
    if (!image.registered) continue;
    up_sum += UpInWorld(image);
    ++num_images;
  }
  if (num_images == 0) throw InputError(model_name + ": has no registered images");
  if (up_sum.norm() < 1e-3 * static_cast<double>(num_images)) {
    throw InputError(model_name + ": the cameras' up directions cancel out: no mean up direction");
  }
  const Eigen::Vector3d mean_up = up_sum.normalized();
  Alignment alignment;
  alignment.method = "upright";
  alignment.new_from_old.rotation = RotationOnto(mean_up, Eigen::Vector3d::UnitZ());

  // The ground: the plane near-horizontal (now) that holds most points.
  std::vector<Eigen::Vector3d> points;
  std::vector<point3D_t> point_ids;
  for (const auto& [point3D_id, point3D] : model.points3D) {
    points.push_back(alignment.new_from_old.rotation * point3D.xyz);
    point_ids.push_back(point3D_id);
  }
  nlohmann::json plane_json = {{"found", false}};
  const double plane_max_error = points.size() < 3             ? 0
                                 : options.plane_max_error > 0 ? options.plane_max_error
                                                               : 0.01 * RobustSpread(points);
  if (plane_max_error > 0) {
    RANSACOptions ransac;
    ransac.max_error = plane_max_error;
    ransac.confidence = 0.999;
    ransac.min_inlier_ratio = std::clamp(options.min_plane_inlier_ratio, 1e-3, 1.0);
    ransac.max_num_trials = 10000;
    const HorizontalPlaneEstimator estimator(options.max_plane_tilt_deg);
    const auto report = LORANSAC<HorizontalPlaneEstimator, HorizontalPlaneEstimator>(
                            ransac, DeriveSeed(options.seed, 0x9a0d), estimator, estimator)
                            .Estimate(points, points);
    const size_t num_inliers = report.success
                                   ? static_cast<size_t>(std::count(report.inlier_mask.begin(),
                                                                    report.inlier_mask.end(), 1))
                                   : 0;
    plane_json["max_error"] = ransac.max_error;
    plane_json["num_inliers"] = num_inliers;
    if (report.success && static_cast<double>(num_inliers) >=
                              options.min_plane_inlier_ratio * static_cast<double>(points.size())) {
      const Eigen::Vector3d normal = report.model.head<3>().normalized();
      const Eigen::Matrix3d level = RotationOnto(normal, Eigen::Vector3d::UnitZ());
      std::vector<double> heights;
      for (size_t i = 0; i < points.size(); ++i) {
        if (!report.inlier_mask[i]) continue;
        heights.push_back((level * points[i]).z());
        alignment.inlier_point_ids.push_back(point_ids[i]);
      }
      alignment.num_inliers = alignment.inlier_point_ids.size();
      alignment.new_from_old.rotation = level * alignment.new_from_old.rotation;
      alignment.new_from_old.translation = Eigen::Vector3d(0, 0, -UpperMedian(heights));
      plane_json["found"] = true;
      plane_json["normal_tilt_deg"] = AngleDeg(normal, Eigen::Vector3d::UnitZ());
    }
  }
  // The residuals: how far each camera's up direction is from +Z after the move.
  std::vector<double> angles;
  for (const auto& [image_id, image] : model.images) {
    if (!image.registered) continue;
    angles.push_back(
        AngleDeg(alignment.new_from_old.rotation * UpInWorld(image), Eigen::Vector3d::UnitZ()));
  }
  alignment.residual_unit = "degrees (camera up direction from +Z)";
  SetResiduals(angles, &alignment);
  alignment.details = {
      {"mean_up_before", VectorJson(mean_up)},
      {"mean_up_angle_after_deg",
       AngleDeg(alignment.new_from_old.rotation * mean_up, Eigen::Vector3d::UnitZ())},
      {"ground_plane", plane_json}};
  return alignment;
}

Similarity3d ReadAlignmentFile(const std::filesystem::path& file) {
  const std::string text = ReadFileContents(file);
  nlohmann::json json;
  try {
    json = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& error) {
    throw InputError(file.string() + ": not valid JSON: " + error.what());
  }
  auto number = [&](const nlohmann::json& value, const std::string& field) {
    if (!value.is_number() || !std::isfinite(value.get<double>())) {
      throw InputError(file.string() + ": " + field + ": expected a finite number");
    }
    return value.get<double>();
  };
  if (!json.is_object()) throw InputError(file.string() + ": expected a JSON object");
  Similarity3d sim;
  if (!json.contains("scale")) throw InputError(file.string() + ": scale: missing");
  sim.scale = number(json["scale"], "scale");
  if (!(sim.scale > 0)) throw InputError(file.string() + ": scale: must be positive");
  const nlohmann::json rotation = json.value("rotation", nlohmann::json());
  if (!rotation.is_array() || rotation.size() != 3) {
    throw InputError(file.string() + ": rotation: expected 3 rows of 3 numbers");
  }
  for (int row = 0; row < 3; ++row) {
    if (!rotation[row].is_array() || rotation[row].size() != 3) {
      throw InputError(file.string() + ": rotation: expected 3 rows of 3 numbers");
    }
    for (int col = 0; col < 3; ++col) {
      sim.rotation(row, col) = number(rotation[row][col], "rotation");
    }
  }
  if ((sim.rotation * sim.rotation.transpose() - Eigen::Matrix3d::Identity()).norm() > 1e-6 ||
      sim.rotation.determinant() < 0) {
    throw InputError(file.string() + ": rotation: not a rotation matrix");
  }
  const nlohmann::json translation = json.value("translation", nlohmann::json());
  if (!translation.is_array() || translation.size() != 3) {
    throw InputError(file.string() + ": translation: expected 3 numbers");
  }
  for (int axis = 0; axis < 3; ++axis) {
    sim.translation(axis) = number(translation[axis], "translation");
  }
  return sim;
}

namespace {

// The images' EXIF GPS, read from `folder`/NAME for every registered image.
std::map<image_t, ImageMetadata> ReadImageGps(const Reconstruction& model,
                                              const std::filesystem::path& folder) {
  std::map<image_t, ImageMetadata> metadata;
  for (const auto& [image_id, image] : model.images) {
    if (!image.registered) continue;
    const std::filesystem::path file = folder / image.name;
    std::error_code error;
    if (!std::filesystem::is_regular_file(file, error)) {
      throw InputError(file.string() + ": no such image (image " + image.name +
                       " of the model); give the images' folder with --images");
    }
    const std::string bytes = ReadFileContents(file);
    metadata[image_id] = MetadataFromExif(
        ReadExifInfo(reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size()));
  }
  return metadata;
}

}  // namespace

nlohmann::json AlignSummary::ToJson() const {
  nlohmann::json json = alignment.ToJson();
  // The summary names the inliers by count; alignment.json lists them.
  json.erase("inliers");
  json.erase("inlier_point_ids");
  json["format"] = format;
  json["num_images"] = num_images;
  json["num_points3D"] = num_points3D;
  json["seconds"] = seconds;
  return json;
}

AlignSummary AlignModel(const AlignArguments& arguments) {
  const Timer timer;
  const int num_methods =
      (arguments.reference.empty() ? 0 : 1) + (arguments.gps ? 1 : 0) + (arguments.upright ? 1 : 0);
  if (num_methods != 1) {
    throw InputError("align: give exactly one of --reference REF, --gps and --upright");
  }
  if (!arguments.images.empty() && !arguments.gps) {
    throw InputError("--images: only with --gps");
  }
  for (const double sigma : {arguments.gps_horizontal_sigma, arguments.gps_vertical_sigma}) {
    if (!(sigma >= 1e-3 && sigma <= 1e6)) {
      throw InputError("--gps-sigma: " + std::to_string(sigma) +
                       " is not a standard deviation in [0.001, 1e6] metres");
    }
  }
  std::vector<std::filesystem::path> held = {arguments.model, arguments.output};
  if (!arguments.reference.empty()) held.push_back(arguments.reference);
  const auto workspaces = HoldEnclosingWorkspaces(held);
  const std::string model_name = arguments.model.string();
  ColmapModelFileOrder order;
  const ColmapModelFormat format = ColmapModelFormatOf(arguments.model);
  Reconstruction model = ReadColmapModel(arguments.model, &order);
  CheckModelHasCamerasAndImages(model, model_name);

  AlignSummary summary;
  if (!arguments.reference.empty()) {
    const Reconstruction reference = ReadColmapModel(arguments.reference);
    summary.alignment =
        AlignToReference(model, reference, model_name, arguments.reference.string());
  } else if (arguments.gps) {
    std::filesystem::path images = arguments.images;
    if (images.empty()) {
      // The folder extract recorded in the model's workspace.
      const std::filesystem::path enclosing = EnclosingWorkspace(arguments.model);
      for (const auto& workspace : workspaces) {
        std::error_code error;
        if (enclosing.empty() ||
            !std::filesystem::equivalent(workspace->folder(), enclosing, error)) {
          continue;
        }
        if (std::filesystem::exists(workspace->DatabaseFile())) {
          workspace->OpenDatabase();
          images = ImageFolder({}, workspace->database());
        }
      }
      if (images.empty()) {
        throw InputError("--images: needed: " + model_name +
                         " lies in no workspace that recorded its images' folder");
      }
    }
    GpsAnchoringOptions options;
    options.horizontal_sigma_m = arguments.gps_horizontal_sigma;
    options.vertical_sigma_m = arguments.gps_vertical_sigma;
    summary.alignment = AlignToGps(model, ReadImageGps(model, images), model_name, options);
  } else {
    summary.alignment = AlignUpright(model, model_name);
  }
  TransformModel(summary.alignment.new_from_old, &model);

  // The model's frame changed: a georeference.json it had no longer holds, and is not
  // carried over; --gps writes the new frame's.
  WriteToolboxOutputs(
      arguments.output, "align", model, format, &order, [&](const std::filesystem::path& folder) {
        WriteFileAtomically(folder / kAlignmentFileName, summary.alignment.ToJson().dump(2) + "\n");
        if (summary.alignment.georeference) {
          WriteGeoreference(*summary.alignment.georeference, folder);
        }
      });
  summary.format = format == ColmapModelFormat::kBinary ? "binary" : "text";
  summary.num_images = model.NumRegisteredImages();
  summary.num_points3D = model.points3D.size();
  summary.seconds = timer.ElapsedSeconds();
  return summary;
}

}  // namespace tessera
