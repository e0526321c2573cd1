#include "toolbox/triangulate_known_poses.h"

#include <spdlog/spdlog.h>

#include <cmath>
#include <optional>
#include <set>
#include <utility>

#include "eval/ground_truth.h"
#include "outputs/output_transaction.h"
#include "pipeline/load_mapper_input.h"
#include "pipeline/pipeline_context.h"
#include "pipeline/workspace.h"
#include "plugin/bundle_adjuster_guard.h"
#include "tessera/errors.h"
#include "tessera/io/colmap_model_io.h"
#include "tessera/io/file_io.h"
#include "tessera/io/model_statistics.h"
#include "tessera/io/point_colors.h"
#include "tessera/sfm/feature_tracks.h"
#include "tessera/sfm/incremental_triangulator.h"
#include "tessera/sfm/observation_manager.h"
#include "tessera/sfm/track_filtering.h"
#include "tessera/sfm/verified_pairs.h"
#include "util/timer.h"
#include "util/workspace_layout.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

// Names listed in a warning before "and N more".
constexpr size_t kMaxNamesListed = 5;

// The mapper's filter: observations reprojecting too far, then points whose rays meet at
// too small an angle.
void FilterPoints(const KnownPosesTriangulationOptions& options, Reconstruction* model) {
  FilterObservationsByReprojectionError(options.filter_max_reproj_error, model);
  FilterPointsByTriangulationAngle(options.filter_min_tri_angle, model);
}

// One image of the known poses, before it is matched to the workspace's.
struct KnownImage {
  std::string name;   // as the source gives it
  std::string where;  // the file and record, for messages
  camera_t camera_id = kInvalidCameraId;
  Rigid3d cam_from_world;
};

struct KnownPoses {
  std::map<camera_t, Camera> cameras;
  std::vector<KnownImage> images;
};

// A COLMAP model's cameras and poses, each checked.
KnownPoses ReadKnownModel(const fs::path& dir) {
  if (!ExistsColmapModel(dir)) {
    throw InputError(dir.string() +
                     ": no COLMAP model there (cameras, images and points3D as .txt or .bin)");
  }
  std::error_code error;
  const bool binary = fs::is_regular_file(dir / "cameras.bin", error) &&
                      fs::is_regular_file(dir / "images.bin", error) &&
                      fs::is_regular_file(dir / "points3D.bin", error);
  const std::string extension = binary ? ".bin" : ".txt";
  const std::string cameras_file = (dir / ("cameras" + extension)).string();
  const std::string images_file = (dir / ("images" + extension)).string();
  const Reconstruction model = ReadColmapModel(dir);
  if (model.cameras.empty()) throw InputError(cameras_file + ": the model has no cameras");
  if (model.images.empty()) throw InputError(images_file + ": the model has no images");
  KnownPoses known;
  for (const auto& [camera_id, camera] : model.cameras) {
    bool finite = true;
    for (const double value : camera.params) finite = finite && std::isfinite(value);
    if (!camera.IsValid() || !finite) {
      throw InputError(cameras_file + ": camera " + std::to_string(camera_id) +
                       " is not a valid camera (model, size or parameters not finite)");
    }
    known.cameras.emplace(camera_id, camera);
  }
  for (const auto& [image_id, image] : model.images) {
    KnownImage entry;
    entry.name = image.name;
    entry.where = images_file + ": image " + std::to_string(image_id) + " (" + image.name + ")";
    const Eigen::Quaterniond& q = image.cam_from_world.rotation;
    // The reader normalizes the quaternion (a zero one it refuses): a rotation, or NaN.
    if (!q.coeffs().allFinite() || !image.cam_from_world.translation.allFinite()) {
      throw InputError(entry.where + ": the pose holds numbers that are not finite");
    }
    entry.camera_id = image.camera_id;
    entry.cam_from_world = image.cam_from_world;
    known.images.push_back(std::move(entry));
  }
  return known;
}

// A transforms.json's cameras (one per distinct intrinsics, ids from 1 in frame order)
// and poses.
KnownPoses ReadKnownTransforms(const fs::path& file) {
  KnownPoses known;
  const std::vector<TransformsJsonFrame> frames = ReadTransformsJsonFrames(file, true);
  for (size_t i = 0; i < frames.size(); ++i) {
    const TransformsJsonFrame& frame = frames[i];
    KnownImage entry;
    entry.name = frame.file_path;
    entry.where = file.string() + ": frames[" + std::to_string(i) + "] (" + frame.file_path + ")";
    for (const auto& [camera_id, camera] : known.cameras) {
      if (camera.model_id == frame.camera.model_id && camera.width == frame.camera.width &&
          camera.height == frame.camera.height && camera.params == frame.camera.params) {
        entry.camera_id = camera_id;
      }
    }
    if (entry.camera_id == kInvalidCameraId) {
      entry.camera_id = static_cast<camera_t>(known.cameras.size() + 1);
      Camera camera = frame.camera;
      camera.camera_id = entry.camera_id;
      known.cameras.emplace(entry.camera_id, std::move(camera));
    }
    // The quaternion of the (checked) rotation; the translation puts the centre where
    // the file says.
    const Eigen::Quaterniond rotation =
        Eigen::Quaterniond(frame.pose.R_cam_from_world).normalized();
    entry.cam_from_world = Rigid3d(rotation, -(rotation * frame.pose.center_in_world));
    known.images.push_back(std::move(entry));
  }
  return known;
}

// "a, b, c, d, e and 7 more"
std::string ListNames(const std::vector<std::string>& names) {
  std::string text;
  for (size_t i = 0; i < names.size() && i < kMaxNamesListed; ++i) {
    text += (i == 0 ? "" : ", ") + names[i];
  }
  if (names.size() > kMaxNamesListed) {
    text += " and " + std::to_string(names.size() - kMaxNamesListed) + " more";
  }
  return text;
}

// The workspace's images by their name, their file name, and their file name without
// extension, so that a source naming "images/r_0.png" or "r_0" finds "r_0.png".
class WorkspaceNames {
 public:
  explicit WorkspaceNames(const std::map<image_t, Image>& images) {
    for (const auto& [image_id, image] : images) {
      by_name_.emplace(image.name, image_id);
      by_file_name_[fs::path(image.name).filename().string()].push_back(image_id);
      by_stem_[fs::path(image.name).stem().string()].push_back(image_id);
    }
  }

  // The workspace image `name` names, kInvalidImageId when none (or several) do.
  image_t Find(std::string name) const {
    while (name.rfind("./", 0) == 0) name = name.substr(2);
    if (const auto it = by_name_.find(name); it != by_name_.end()) return it->second;
    const fs::path path(name);
    if (const auto it = by_file_name_.find(path.filename().string());
        it != by_file_name_.end() && it->second.size() == 1) {
      return it->second.front();
    }
    if (path.has_extension()) return kInvalidImageId;
    if (const auto it = by_stem_.find(path.filename().string());
        it != by_stem_.end() && it->second.size() == 1) {
      return it->second.front();
    }
    return kInvalidImageId;
  }

 private:
  std::map<std::string, image_t> by_name_;
  std::map<std::string, std::vector<image_t>> by_file_name_;
  std::map<std::string, std::vector<image_t>> by_stem_;
};

}  // namespace

Reconstruction TriangulateKnownPoses(const MapperInput& input,
                                     const KnownPosesTriangulationOptions& options,
                                     const BundleAdjuster* bundle_adjuster) {
  std::map<image_t, Image> images;
  std::map<image_t, size_t> num_points2D;
  for (const auto& [image_id, image] : input.images) {
    if (!image.registered) continue;
    images.emplace(image_id, image);
    num_points2D[image_id] = image.points2D.size();
  }
  // Tracks of the verified pairs between posed images only: a track through an image
  // without a pose could join features that no pose confirms.
  std::vector<ImagePairMatches> matches;
  for (const MapperInput::Pair* pair : VerifiedPairs(input, options.min_num_matches)) {
    if (images.count(pair->image_id1) == 0 || images.count(pair->image_id2) == 0) continue;
    matches.push_back({pair->image_id1, pair->image_id2, pair->geometry.inlier_matches});
  }
  ObservationManager observations(input.cameras, images, BuildFeatureTracks(matches, num_points2D));
  for (const auto& [image_id, image] : images) {
    // Normalized for the geometry; the input's pose goes back into the model at the end.
    observations.RegisterImage(image_id, Rigid3d(image.cam_from_world.rotation.normalized(),
                                                 image.cam_from_world.translation));
  }
  IncrementalTriangulatorOptions triangulator_options;
  triangulator_options.max_error = options.tri_max_error;
  triangulator_options.min_angle = options.tri_min_angle;
  triangulator_options.max_num_pairs = options.tri_max_num_pairs;
  IncrementalTriangulator triangulator(triangulator_options, &observations);
  for (const auto& [image_id, image] : images) triangulator.TriangulateImage(image_id);
  // As the mapper's global refinement: tracks that no image's pass could start, then the
  // tracks a refused match links, then every point completed.
  triangulator.Retriangulate();
  triangulator.MergeTracks();
  std::set<point3D_t> all_points;
  for (const auto& [point3D_id, point3D] : observations.model().points3D) {
    all_points.insert(point3D_id);
  }
  triangulator.CompleteTracks(all_points);
  Reconstruction model = observations.TakeModel();
  FilterPoints(options, &model);

  if (bundle_adjuster != nullptr && !model.points3D.empty()) {
    BundleAdjustmentConfig config;
    for (const auto& [image_id, image] : model.images) config.constant_poses.insert(image_id);
    config.refine_focal_length = true;
    config.refine_principal_point = false;
    config.refine_extra_params = true;
    config.fix_gauge = false;  // every pose is constant: the gauge is the input's
    const BundleAdjustmentSummary summary = bundle_adjuster->Adjust(config, &model);
    spdlog::info("triangulate: bundle adjustment of the intrinsics and points, poses held: {}",
                 summary.BriefReport());
    if (!summary.usable) {
      spdlog::warn(
          "triangulate: the bundle adjustment was not usable ({}); the intrinsics are "
          "the input's",
          summary.BriefReport());
    }
    FilterPoints(options, &model);
  }
  for (auto& [image_id, image] : model.images) {
    image.cam_from_world = input.images.at(image_id).cam_from_world;
  }
  for (auto& [point3D_id, point3D] : model.points3D) {
    point3D.error = PointReprojectionError(model, point3D);
  }
  return model;
}

nlohmann::json TriangulateSummary::ToJson() const {
  return {{"source", source},
          {"images_in_common", num_images_in_common},
          {"only_in_source", only_in_source},
          {"only_in_workspace", only_in_workspace},
          {"num_points3D", num_points3D},
          {"num_observations", num_observations},
          {"mean_track_length", mean_track_length},
          {"mean_reprojection_error", mean_reprojection_error},
          {"refined_intrinsics", refined_intrinsics},
          {"model", model_folder.string()},
          {"seconds", seconds}};
}

namespace {

// One warning naming the images on one side only (the first few of each, and a count).
void WarnOfOneSidedImages(const TriangulateSummary& summary) {
  if (summary.only_in_source.empty() && summary.only_in_workspace.empty()) return;
  std::string line = "triangulate: images on one side only are left out:";
  if (!summary.only_in_source.empty()) {
    line += " " + std::to_string(summary.only_in_source.size()) + " of " + summary.source +
            " are not in the workspace (" + ListNames(summary.only_in_source) + ")";
  }
  if (!summary.only_in_workspace.empty()) {
    line += std::string(summary.only_in_source.empty() ? "" : ";") + " " +
            std::to_string(summary.only_in_workspace.size()) + " of the workspace's are not in " +
            summary.source + " (" + ListNames(summary.only_in_workspace) + ")";
  }
  spdlog::warn("{}", line);
}

}  // namespace

TriangulateSummary TriangulateWorkspace(const TriangulateArguments& arguments) {
  const Timer timer;
  if (arguments.model_index < 0) {
    throw InputError("model_index: Value " + std::to_string(arguments.model_index) +
                     " is not a whole number of at least 0");
  }
  if (arguments.model.empty() == arguments.poses.empty()) {
    throw InputError(
        "--model or --poses: give one of them (a COLMAP model folder, or a transforms.json)");
  }
  // The manifest's bundle adjuster, checked before any file is read.
  std::optional<PipelineContext> context;
  if (arguments.refine_intrinsics) {
    context.emplace(LoadPipelineContext(arguments.stage));
    context->Require("bundle_adjuster", "triangulate --refine-intrinsics");
  }
  TriangulateSummary summary;
  summary.source = (arguments.model.empty() ? arguments.poses : arguments.model).string();
  const KnownPoses known = arguments.model.empty() ? ReadKnownTransforms(arguments.poses)
                                                   : ReadKnownModel(arguments.model);

  Workspace::Options workspace_options;
  workspace_options.require_database_for = "triangulate";
  const std::unique_ptr<Workspace> workspace = Workspace::Open(arguments.output, workspace_options);
  Database& database = workspace->database();
  const MapperInput workspace_input = LoadMapperInput(database);
  if (workspace_input.pairs.empty()) {
    throw InputError(database.path().string() +
                     ": no verified image pairs in the workspace; run match first");
  }

  // The known images matched by name to the workspace's.
  MapperInput input;
  input.pairs = workspace_input.pairs;
  const WorkspaceNames names(workspace_input.images);
  std::map<image_t, const KnownImage*> known_of_image;
  for (const KnownImage& known_image : known.images) {
    const image_t image_id = names.Find(known_image.name);
    if (image_id == kInvalidImageId) {
      summary.only_in_source.push_back(known_image.name);
      continue;
    }
    const Image& image = workspace_input.images.at(image_id);
    const auto [it, inserted] = known_of_image.emplace(image_id, &known_image);
    if (!inserted) {
      throw InputError(known_image.where + " and " + it->second->where +
                       " both name the workspace's image " + image.name);
    }
    const Camera& camera = known.cameras.at(known_image.camera_id);
    const Camera& workspace_camera = workspace_input.cameras.at(image.camera_id);
    if (camera.width != workspace_camera.width || camera.height != workspace_camera.height) {
      throw InputError(known_image.where + ": its camera " + std::to_string(camera.camera_id) +
                       " is " + std::to_string(camera.width) + "x" + std::to_string(camera.height) +
                       ", but the workspace's image " + image.name + " is " +
                       std::to_string(workspace_camera.width) + "x" +
                       std::to_string(workspace_camera.height) +
                       " (scale the intrinsics to the images the workspace holds)");
    }
    Image posed = image;
    posed.camera_id = camera.camera_id;
    posed.cam_from_world = known_image.cam_from_world;
    posed.registered = true;
    input.cameras.emplace(camera.camera_id, camera);
    input.images.emplace(image_id, std::move(posed));
  }
  for (const auto& [image_id, image] : workspace_input.images) {
    if (known_of_image.count(image_id) == 0) summary.only_in_workspace.push_back(image.name);
  }
  if (input.images.empty()) {
    throw InputError(summary.source + ": none of its " + std::to_string(known.images.size()) +
                     " images (" + ListNames(summary.only_in_source) + ") is in the workspace " +
                     arguments.output.string() + " (images are matched by name)");
  }
  summary.num_images_in_common = input.images.size();
  WarnOfOneSidedImages(summary);

  std::optional<BundleAdjusterGuard> bundle_adjuster;
  if (context) bundle_adjuster.emplace(context->bundle_adjuster, &workspace->crash_log());
  Reconstruction model = TriangulateKnownPoses(input, KnownPosesTriangulationOptions(),
                                               bundle_adjuster ? &*bundle_adjuster : nullptr);
  summary.refined_intrinsics = bundle_adjuster.has_value();

  const fs::path image_dir = ImageFolder({}, database);
  if (image_dir.empty()) {
    spdlog::warn("triangulate: the image folder is unknown; points are not coloured");
  } else {
    const int num_threads =
        context ? context->manifest.EffectiveNumThreads() : arguments.stage.threads;
    for (const std::string& warning : ColorPointsFromImages(image_dir, &model, num_threads)) {
      spdlog::warn("triangulate: {}", warning);
    }
  }

  // Placed whole or not at all, replacing only what Tessera wrote (sparse/N of an
  // earlier map or triangulate); the other models stay.
  OutputTransaction outputs(workspace->folder(), OutputTransaction::Mode::kAddToSet);
  outputs.Protect(image_dir);
  const fs::path relative =
      fs::path(workspace_layout::kModelsFolder) / std::to_string(arguments.model_index);
  WriteColmapModel(model, outputs.StageFor("tessera") / relative, ColmapModelFormat::kBinary);
  outputs.Commit();

  const ModelStatistics statistics = ComputeModelStatistics(model);
  summary.num_points3D = statistics.num_points3D;
  summary.num_observations = statistics.num_observations;
  summary.mean_track_length = statistics.mean_track_length;
  summary.mean_reprojection_error = statistics.mean_reprojection_error;
  summary.model_folder = workspace->folder() / relative;
  summary.seconds = timer.ElapsedSeconds();
  return summary;
}

}  // namespace tessera
