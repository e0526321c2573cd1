#include "eval/evaluation.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>

#include "tessera/io/model_statistics.h"

namespace tessera {
namespace {

constexpr size_t kMinNumAlignedImages = 3;

// Distinct centres among `centers`, counted up to `enough`. Centres closer than 1e-12 of
// the largest coordinate are one, as rounding could have made them: an alignment to
// points that coincide is no alignment (every centre maps to their mean: a "perfect" 0).
size_t NumDistinctCenters(const std::vector<Eigen::Vector3d>& centers, size_t enough) {
  double magnitude = 0;
  for (const Eigen::Vector3d& center : centers) {
    magnitude = std::max(magnitude, center.cwiseAbs().maxCoeff());
  }
  const double tolerance = 1e-12 * magnitude;
  std::vector<Eigen::Vector3d> distinct;
  for (const Eigen::Vector3d& center : centers) {
    if (distinct.size() == enough) break;
    const bool seen = std::any_of(distinct.begin(), distinct.end(), [&](const auto& other) {
      return (other - center).norm() <= tolerance;
    });
    if (!seen) distinct.push_back(center);
  }
  return distinct.size();
}

// Why `centers` (of the images both hold) cannot anchor an alignment; "" when they can.
std::string DegenerateCentersError(const std::vector<Eigen::Vector3d>& centers,
                                   const std::string& whose) {
  const size_t num_distinct = NumDistinctCenters(centers, kMinNumAlignedImages);
  if (num_distinct >= kMinNumAlignedImages) return "";
  return whose + " places the " + std::to_string(centers.size()) + " images in both at only " +
         std::to_string(num_distinct) + " distinct camera centre" + (num_distinct == 1 ? "" : "s") +
         "; aligning needs at least " + std::to_string(kMinNumAlignedImages);
}

double Mean(const std::vector<double>& values) {
  return std::accumulate(values.begin(), values.end(), 0.0) / static_cast<double>(values.size());
}

// As numpy.median: the mean of the two middle values for an even count.
double Median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : (values[n / 2 - 1] + values[n / 2]) / 2;
}

double Max(const std::vector<double>& values) {
  return *std::max_element(values.begin(), values.end());
}

// Angle of the rotation between two orientations, in degrees.
double RotationAngleDeg(const Eigen::Matrix3d& R_a, const Eigen::Matrix3d& R_b) {
  const double cos_angle = std::clamp(((R_a * R_b.transpose()).trace() - 1) / 2, -1.0, 1.0);
  return std::acos(cos_angle) * 180 / M_PI;
}

void AddModelStatistics(const Reconstruction& model, EvaluationResult* result) {
  const ModelStatistics statistics = ComputeModelStatistics(model);
  result->num_points3D = statistics.num_points3D;
  result->num_observations = statistics.num_observations;
  result->num_observations_behind_camera = statistics.num_observations_behind_camera;
  result->mean_track_length = statistics.mean_track_length;
  result->mean_reprojection_error = statistics.mean_reprojection_error;
}

std::string FormatNumber(double value, const char* format) {
  if (std::isnan(value)) return "-";
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), format, value);
  return buffer;
}

}  // namespace

EvaluationResult EvaluateReconstruction(const Reconstruction& model,
                                        const std::map<std::string, GroundTruthPose>& ground_truth,
                                        const std::filesystem::path& model_dir,
                                        const std::optional<Similarity3d>& fixed_gt_from_model) {
  EvaluationResult result;
  AddModelStatistics(model, &result);
  const std::map<std::string, GroundTruthPose> estimated = PosesByBasename(model, model_dir);

  std::vector<std::string> names;
  std::vector<Eigen::Vector3d> centers_model, centers_gt;
  for (const auto& [name, gt_pose] : ground_truth) {
    ImageEvaluation row;
    row.name = name;
    const auto it = estimated.find(name);
    row.registered = it != estimated.end();
    if (row.registered) {
      names.push_back(name);
      centers_model.push_back(it->second.center_in_world);
      centers_gt.push_back(gt_pose.center_in_world);
    }
    result.images.push_back(row);
  }
  result.num_total = ground_truth.size();
  result.num_registered = names.size();
  if (names.size() < kMinNumAlignedImages) {
    result.error = "only " + std::to_string(names.size()) +
                   " images of the model are in the ground truth; aligning needs at least " +
                   std::to_string(kMinNumAlignedImages);
    return result;
  }
  for (const auto& [centers, whose] :
       {std::pair(&centers_gt, "the ground truth"), std::pair(&centers_model, "the model")}) {
    result.error = DegenerateCentersError(*centers, whose);
    if (!result.error.empty()) return result;
  }

  result.gt_from_model =
      fixed_gt_from_model ? *fixed_gt_from_model : EstimateSimilarity(centers_model, centers_gt);
  result.aligned = true;
  std::vector<double> position_errors, rotation_errors;
  for (ImageEvaluation& row : result.images) {
    if (!row.registered) continue;
    const GroundTruthPose& estimate = estimated.at(row.name);
    const GroundTruthPose& truth = ground_truth.at(row.name);
    row.position_error =
        (result.gt_from_model * estimate.center_in_world - truth.center_in_world).norm();
    // cam_from_gt_world = cam_from_model_world * model_from_gt_world.
    row.rotation_error_deg =
        RotationAngleDeg(truth.R_cam_from_world,
                         estimate.R_cam_from_world * result.gt_from_model.rotation.transpose());
    position_errors.push_back(row.position_error);
    rotation_errors.push_back(row.rotation_error_deg);
    if (row.rotation_error_deg > kWrongRegistrationDeg) ++result.num_wrongly_registered;
  }
  result.position_error_mean = Mean(position_errors);
  result.position_error_median = Median(position_errors);
  result.position_error_max = Max(position_errors);
  result.rotation_error_mean_deg = Mean(rotation_errors);
  result.rotation_error_max_deg = Max(rotation_errors);

  Eigen::Vector3d mean_gt = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& center : centers_gt) mean_gt += center;
  mean_gt /= centers_gt.size();
  result.scene_extent = 0;
  for (const Eigen::Vector3d& center : centers_gt) {
    result.scene_extent = std::max(result.scene_extent, (center - mean_gt).norm());
  }
  result.position_error_mean_relative = result.position_error_mean / result.scene_extent;
  return result;
}

nlohmann::json EvaluationResult::ToJson() const {
  nlohmann::json json = {{"registered", num_registered}, {"total", num_total}};
  if (!aligned) json["error"] = error;
  if (aligned) {
    json["rot_mean_deg"] = rotation_error_mean_deg;
    json["rot_max_deg"] = rotation_error_max_deg;
    json["wrongly_registered"] = num_wrongly_registered;
    json["pos_mean"] = position_error_mean;
    json["pos_median"] = position_error_median;
    json["pos_max"] = position_error_max;
    json["pos_mean_rel"] = position_error_mean_relative;
    json["scene_extent"] = scene_extent;
    json["alignment_scale"] = gt_from_model.scale;
  }
  json["num_points3D"] = num_points3D;
  json["num_observations"] = num_observations;
  json["mean_track_length"] = mean_track_length;
  json["mean_reprojection_error_px"] = mean_reprojection_error;  // null when there is none
  json["num_observations_behind_camera"] = num_observations_behind_camera;
  json["images"] = nlohmann::json::array();
  for (const ImageEvaluation& row : images) {
    nlohmann::json image = {{"name", row.name}, {"registered", row.registered}};
    if (row.registered && aligned) {
      image["pos_error"] = row.position_error;
      image["rot_error_deg"] = row.rotation_error_deg;
    }
    json["images"].push_back(image);
  }
  return json;
}

std::string EvaluationResult::ToTable() const {
  size_t name_width = 5;
  for (const ImageEvaluation& row : images) name_width = std::max(name_width, row.name.size());
  std::string table;
  char line[512];
  std::snprintf(line, sizeof(line), "%-*s  %16s  %18s\n", static_cast<int>(name_width), "image",
                "position error", "rotation error deg");
  table += line;
  for (const ImageEvaluation& row : images) {
    if (!row.registered) {
      std::snprintf(line, sizeof(line), "%-*s  %16s\n", static_cast<int>(name_width),
                    row.name.c_str(), "not registered");
    } else {
      std::snprintf(line, sizeof(line), "%-*s  %16s  %18s\n", static_cast<int>(name_width),
                    row.name.c_str(), FormatNumber(row.position_error, "%.6g").c_str(),
                    FormatNumber(row.rotation_error_deg, "%.4f").c_str());
    }
    table += line;
  }
  table += "registered: " + std::to_string(num_registered) + "/" + std::to_string(num_total) + "\n";
  if (!aligned) {
    table += "not aligned: " + error + "\n";
  } else {
    table += "position error (ground-truth units): mean " +
             FormatNumber(position_error_mean, "%.6g") + ", median " +
             FormatNumber(position_error_median, "%.6g") + ", max " +
             FormatNumber(position_error_max, "%.6g") + "\n";
    table += "mean position error / scene extent (" + FormatNumber(scene_extent, "%.6g") +
             "): " + FormatNumber(100 * position_error_mean_relative, "%.4f") + "%\n";
    table += "rotation error (deg): mean " + FormatNumber(rotation_error_mean_deg, "%.4f") +
             ", max " + FormatNumber(rotation_error_max_deg, "%.4f") + "\n";
    table += "wrongly registered (rotation error over " +
             FormatNumber(kWrongRegistrationDeg, "%g") +
             " deg): " + std::to_string(num_wrongly_registered) + "\n";
  }
  table += "3D points: " + std::to_string(num_points3D) + ", mean track length " +
           FormatNumber(mean_track_length, "%.4f") + ", mean reprojection error " +
           FormatNumber(mean_reprojection_error, "%.4f") + " px";
  if (num_observations_behind_camera > 0) {
    table += " (" + std::to_string(num_observations_behind_camera) +
             " observations behind their camera left out)";
  }
  table += "\n";
  return table;
}

}  // namespace tessera
