#include "pipeline/evaluate_model.h"

#include "eval/ground_truth.h"
#include "pipeline/workspace.h"
#include "tessera/io/colmap_model_io.h"
#include "tessera/io/georeference_io.h"
#include "tessera/sfm/gps_anchoring.h"

namespace tessera {

namespace {

// Ground-truth poses in east-north-up metres about `from`, moved into the east-north-up
// frame about `to` (through WGS84, so the axes' turn between the two origins is kept).
std::map<std::string, GroundTruthPose> IntoFrame(std::map<std::string, GroundTruthPose> poses,
                                                 const Georeference& from, const Georeference& to) {
  const auto move = [&](const Eigen::Vector3d& x) {
    return EnuFromWgs84(Wgs84FromEnu(x, from), to);
  };
  const Eigen::Vector3d origin = move(Eigen::Vector3d::Zero());
  Eigen::Matrix3d to_from_from;
  for (int axis = 0; axis < 3; ++axis) {
    to_from_from.col(axis) = (move(1000 * Eigen::Vector3d::Unit(axis)) - origin) / 1000;
  }
  for (auto& [name, pose] : poses) {
    pose.center_in_world = move(pose.center_in_world);
    pose.R_cam_from_world = pose.R_cam_from_world * to_from_from.transpose();
  }
  return poses;
}

}  // namespace

EvaluationResult EvaluateModelFolder(const std::filesystem::path& model_dir,
                                     const std::filesystem::path& ground_truth, bool no_align,
                                     const std::optional<Georeference>& gt_origin,
                                     const std::optional<Similarity3d>& model_moved_by) {
  // A model of a workspace is read while no run can rewrite it.
  const auto workspaces = HoldEnclosingWorkspaces({model_dir});
  Reconstruction model = ReadColmapModel(model_dir);
  if (model_moved_by) TransformModel(*model_moved_by, &model);
  auto poses = ReadGroundTruth(ground_truth);
  if (!no_align) return EvaluateReconstruction(model, poses, model_dir);
  if (model_moved_by) {
    if (gt_origin) throw InputError("--gt-origin: not with --alignment, which gives the frame");
    return EvaluateReconstruction(model, poses, model_dir, Similarity3d());
  }

  const std::optional<Georeference> frame = ReadGeoreference(model_dir);
  if (!frame) {
    throw InputError(model_dir.string() +
                     ": --no-align needs a model anchored to GPS, with a georeference.json "
                     "(map with the mapper option use_gps_prior); this model has none");
  }
  std::optional<Georeference> truth_frame = gt_origin;
  std::error_code error;
  if (!truth_frame && std::filesystem::is_directory(ground_truth, error)) {
    truth_frame = ReadGeoreference(ground_truth);
  }
  if (!truth_frame) {
    throw InputError(ground_truth.string() +
                     ": --no-align needs the ground truth's frame: give --gt-origin LAT,LON,ALT "
                     "(the ground truth in east-north-up metres about that point), or a "
                     "georeferenced model folder");
  }
  return EvaluateReconstruction(model, IntoFrame(std::move(poses), *truth_frame, *frame), model_dir,
                                Similarity3d());
}

InputError UnscoredError(const EvaluationResult& result, const std::filesystem::path& model_dir,
                         const std::filesystem::path& ground_truth) {
  return InputError("Cannot score " + model_dir.string() + " against " + ground_truth.string() +
                    ": " + result.error + ".");
}

}  // namespace tessera
