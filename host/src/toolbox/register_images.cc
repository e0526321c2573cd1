#include "toolbox/register_images.h"

#include <spdlog/fmt/fmt.h>
#include <spdlog/spdlog.h>

#include <map>
#include <optional>
#include <set>

#include "outputs/output_transaction.h"
#include "pipeline/extract_stage.h"
#include "pipeline/load_mapper_input.h"
#include "pipeline/map_stage.h"
#include "pipeline/match_stage.h"
#include "pipeline/pipeline_context.h"
#include "pipeline/workspace.h"
#include "plugin/bundle_adjuster_guard.h"
#include "tessera/errors.h"
#include "tessera/io/colmap_model_io.h"
#include "tessera/io/file_io.h"
#include "tessera/io/georeference_io.h"
#include "tessera/io/point_colors.h"
#include "tessera/sfm/incremental_mapper.h"
#include "tessera/sfm/verified_pairs.h"
#include "util/timer.h"
#include "util/workspace_layout.h"

namespace tessera {
namespace {

constexpr const char* kRegisterSummaryFile = "register_summary.json";

// The names of the images of every model in OUTPUT/sparse/ but `index`'s.
std::set<std::string> ImagesOfOtherModels(const std::filesystem::path& sparse, int index) {
  std::set<std::string> names;
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(sparse, error)) {
    if (!entry.is_directory() || entry.path().filename() == std::to_string(index) ||
        !ExistsColmapModel(entry.path())) {
      continue;
    }
    for (const auto& [image_id, image] : ReadColmapModel(entry.path()).images) {
      names.insert(image.name);
    }
  }
  return names;
}

// The incremental mapper's options of the manifest when its mapper is `incremental`;
// the defaults otherwise (registration is the incremental mapper's step whatever mapped).
IncrementalMapperOptions MapperOptions(const PipelineContext& context, int num_threads) {
  IncrementalMapperOptions options;
  const PluginSlot& slot = context.manifest.mapper;
  if (slot.plugin == "incremental") {
    options = IncrementalMapperOptions::FromJson(
        slot.options, slot.options_path.empty() ? slot.json_path + ".options" : slot.options_path);
  } else {
    spdlog::info(
        "register: the manifest's mapper is not 'incremental'; registering with the "
        "incremental mapper's default options");
  }
  options.num_threads = num_threads;
  return options;
}

// Why a new image that did not register did not.
std::string ReasonNotRegistered(image_t image_id, const MapperRunState& run,
                                const std::set<image_t>& model_images, int model_index) {
  const auto failure = run.failure_reasons.find(image_id);
  if (failure != run.failure_reasons.end()) return failure->second;
  for (const MapperInput::Pair* pair : run.verified_pairs) {
    if ((pair->image_id1 == image_id && model_images.count(pair->image_id2) > 0) ||
        (pair->image_id2 == image_id && model_images.count(pair->image_id1) > 0)) {
      return "it sees none of the 3D points of model " + std::to_string(model_index);
    }
  }
  return "no verified pair with an image of model " + std::to_string(model_index);
}

// The model folder, when the workspace has a database and model `index`; else the
// InputError naming what is missing. Nothing is created.
std::filesystem::path CheckModelFolder(const RegisterArguments& arguments) {
  // As the command line refuses --model-index -1, for every caller (the Python module).
  if (arguments.model_index < 0) {
    throw InputError("model_index: Value " + std::to_string(arguments.model_index) +
                     " is not a whole number of at least 0");
  }
  if (arguments.output.empty()) throw InputError("--output: no workspace given");
  const std::filesystem::path database_file = arguments.output / workspace_layout::kDatabase;
  std::error_code error;
  if (!std::filesystem::is_regular_file(database_file, error)) {
    throw InputError(database_file.string() +
                     ": no workspace database; register places images into a workspace's "
                     "model: run `tessera run` (or extract, match and map) first");
  }
  const std::filesystem::path model_dir =
      arguments.output / workspace_layout::kModelsFolder / std::to_string(arguments.model_index);
  if (!ExistsColmapModel(model_dir)) {
    throw InputError(model_dir.string() + ": no model " + std::to_string(arguments.model_index) +
                     " in the workspace (--model-index)");
  }
  return model_dir;
}

// The workspace's images in no model: those extracted now, and any an interrupted
// register (or a map that left them out) extracted before. None is an InputError.
std::set<std::string> NewImageNames(const Database& database, const std::filesystem::path& sparse,
                                    int index, const Reconstruction& model,
                                    const std::filesystem::path& image_dir) {
  std::set<std::string> in_models = ImagesOfOtherModels(sparse, index);
  for (const auto& [image_id, image] : model.images) in_models.insert(image.name);
  std::set<std::string> names;
  const std::vector<Image> images = database.ReadAllImages();
  for (const Image& image : images) {
    if (in_models.count(image.name) == 0) names.insert(image.name);
  }
  if (names.empty()) {
    throw InputError(image_dir.string() + ": no new images: each of the workspace's " +
                     std::to_string(images.size()) + " images is in a model already (" +
                     (sparse / std::to_string(index)).string() + " holds " +
                     std::to_string(model.images.size()) + ")");
  }
  return names;
}

// Matching of the manifest's pairs that hold a new image (the others are done, or not
// the new images' business).
MatchingSummary MatchNewPairs(const Workspace& workspace, const PipelineContext& context,
                              const std::set<std::string>& new_names, const StageControl& control) {
  StageScope scope;
  scope.name = "register";
  scope.pairs = [&new_names](const std::vector<ImageIndexPair>& pairs,
                             const std::vector<Image>& images) {
    std::vector<bool> keep(pairs.size());
    for (size_t p = 0; p < pairs.size(); ++p) {
      keep[p] = new_names.count(images[pairs[p].first].name) > 0 ||
                new_names.count(images[pairs[p].second].name) > 0;
    }
    return keep;
  };
  const MatchingSummary matching =
      MatchFeatures(workspace, context.MakeMatchSettings(), scope, control);
  LogMatching(matching);
  return matching;
}

// Step 3: the new images registered into `model` (held unless refine_existing), each
// reported in `summary`; nullopt when cancelled.
std::optional<Reconstruction> RegisterNewImages(
    const Workspace& workspace, const PipelineContext& context, const MapSettings& map_settings,
    const RegisterArguments& arguments, const Reconstruction& model,
    const std::filesystem::path& model_dir, const std::set<std::string>& new_names,
    const StageControl& control, RegisterSummary* summary) {
  const IncrementalMapperOptions options = MapperOptions(context, map_settings.num_threads);
  const MapperInput input = LoadMapperInput(workspace.database());
  std::set<image_t> new_ids, model_ids;
  std::set<std::string> with_features;
  for (const auto& [image_id, image] : input.images) {
    with_features.insert(image.name);
    if (new_names.count(image.name) > 0) new_ids.insert(image_id);
  }
  for (const auto& [image_id, image] : model.images) model_ids.insert(image_id);
  const BundleAdjusterGuard bundle_adjuster(*map_settings.bundle_adjuster, &workspace.crash_log());
  MapperRunState run(input, bundle_adjuster, map_settings.seed);
  run.Prepare(options, VerifiedPairs(input, static_cast<size_t>(options.min_num_matches)));
  IncrementalMapper mapper(options, &run);
  try {
    mapper.StartFrom(model, !arguments.refine_existing);
  } catch (const InputError& bad) {
    throw InputError(model_dir.string() + ": " + bad.what() +
                     " (a model of another workspace, or one made before the images changed?)");
  }
  control.Report("register", 0, new_ids.size());
  const std::set<image_t> registered =
      RegisterImages(&mapper, new_ids, [&control] { return control.Cancelled(); });
  if (control.Cancelled()) return std::nullopt;
  if (arguments.refine_existing && !registered.empty()) mapper.GlobalRefinement();
  control.Report("register", new_ids.size(), new_ids.size());
  for (const image_t image_id : new_ids) {
    RegisterSummary::NewImage entry;
    entry.name = input.images.at(image_id).name;
    entry.registered = registered.count(image_id) > 0;
    if (!entry.registered) {
      entry.reason = ReasonNotRegistered(image_id, run, model_ids, arguments.model_index);
    }
    summary->images.push_back(entry);
  }
  for (const std::string& name : new_names) {
    if (with_features.count(name) == 0) {
      summary->images.push_back({name, false, "it has no features in the workspace"});
    }
  }
  return mapper.TakeModel();
}

}  // namespace

size_t RegisterSummary::NumRegistered() const {
  size_t count = 0;
  for (const NewImage& image : images) count += image.registered ? 1 : 0;
  return count;
}

nlohmann::json RegisterSummary::ToJson() const {
  nlohmann::json list = nlohmann::json::array();
  for (const NewImage& image : images) {
    nlohmann::json entry = {{"name", image.name}, {"registered", image.registered}};
    if (!image.registered) entry["reason"] = image.reason;
    list.push_back(entry);
  }
  return {{"status", StageStatusName(status)},
          {"model_index", model_index},
          {"model", model_folder},
          {"refine_existing", refine_existing},
          {"num_images_before", num_images_before},
          {"num_images_after", num_images_after},
          {"num_points3D_before", num_points_before},
          {"num_points3D_after", num_points_after},
          {"num_new_images", images.size()},
          {"num_registered", NumRegistered()},
          {"num_extracted", num_extracted},
          {"num_pairs_matched", num_pairs_matched},
          {"images", list},
          {"seconds",
           {{"extract", extract_seconds},
            {"match", match_seconds},
            {"register", register_seconds},
            {"total", seconds}}}};
}

std::vector<std::string> DescribeRegistration(const RegisterSummary& summary) {
  std::vector<std::string> lines;
  for (const RegisterSummary::NewImage& image : summary.images) {
    lines.push_back(image.registered ? fmt::format("register: {}: registered", image.name)
                                     : fmt::format("register: {}: not registered: {}", image.name,
                                                   image.reason));
  }
  lines.push_back(fmt::format(
      "register: {} of {} new images registered into {}: {} -> {} images, {} -> {} points ({}); "
      "extract {:.2f} s, match {:.2f} s, register {:.2f} s, total {:.2f} s",
      summary.NumRegistered(), summary.images.size(), summary.model_folder,
      summary.num_images_before, summary.num_images_after, summary.num_points_before,
      summary.num_points_after,
      summary.refine_existing ? "then refined globally"
                              : "the model's cameras, poses and points held",
      summary.extract_seconds, summary.match_seconds, summary.register_seconds, summary.seconds));
  return lines;
}

RegisterSummary RegisterIntoModel(const RegisterArguments& arguments, const StageControl& control) {
  const Timer timer;
  RegisterSummary summary;
  summary.model_index = arguments.model_index;
  summary.refine_existing = arguments.refine_existing;
  // Before the workspace is opened (which would make the folder): there must be one.
  const std::filesystem::path model_dir = CheckModelFolder(arguments);
  summary.model_folder = model_dir.string();

  // Every plugin and option is checked before an image is read.
  const PipelineContext context = LoadPipelineContext(arguments.stage);
  for (const char* slot : {"detector", "pair_selector", "matcher", "bundle_adjuster"}) {
    context.Require(slot, "register");
  }
  Workspace::Options open;
  open.require_database_for = "register";
  const auto workspace = Workspace::Open(arguments.output, open);
  context.UseWorkspaceCaches(*workspace);
  Database& database = workspace->database();
  const std::filesystem::path image_dir = ImageFolder(arguments.images, database);
  if (image_dir.empty()) {
    throw InputError(workspace->DatabaseFile().string() +
                     ": the workspace records no image folder; pass --images");
  }
  CheckImageFolderApart(image_dir, arguments.output);
  // The workspace's images must be the very files it ingested: else extraction would
  // drop or replace them, and the model would name images the workspace has not.
  CheckImagesUnchanged(
      *workspace, image_dir,
      workspace->ScanOptions(context.manifest.camera.mask_path, context.manifest.max_image_pixels));
  const Reconstruction model = ReadColmapModel(model_dir);
  const std::optional<Georeference> georeference = ReadGeoreference(model_dir);
  summary.num_images_before = model.images.size();
  summary.num_points_before = model.points3D.size();

  // 1. Extraction of the images the workspace does not hold yet (it resumes).
  const ExtractionSummary extraction =
      ExtractFeatures(*workspace, context.MakeExtractSettings(image_dir), {}, control);
  LogExtraction(extraction);
  summary.num_extracted = extraction.num_detected;
  summary.extract_seconds = extraction.seconds;
  if (extraction.status == StageStatus::kCancelled) {
    summary.status = StageStatus::kCancelled;
    return summary;
  }
  const std::set<std::string> new_names =
      NewImageNames(database, model_dir.parent_path(), arguments.model_index, model, image_dir);
  spdlog::info("register: {} new images for model {} ({} images, {} points)", new_names.size(),
               arguments.model_index, model.images.size(), model.points3D.size());

  // 2. Matching of the pairs with a new image (it resumes).
  const MatchingSummary matching = MatchNewPairs(*workspace, context, new_names, control);
  summary.num_pairs_matched = matching.num_matched;
  summary.match_seconds = matching.seconds;
  if (matching.status == StageStatus::kCancelled) {
    summary.status = StageStatus::kCancelled;
    return summary;
  }

  // 3. Registration; nothing is written before it ends.
  const Timer register_timer;
  const MapSettings map_settings = context.MakeMapSettings(image_dir);
  std::optional<Reconstruction> result = RegisterNewImages(
      *workspace, context, map_settings, arguments, model, model_dir, new_names, control, &summary);
  if (!result || control.Cancelled()) {
    summary.status = StageStatus::kCancelled;
    spdlog::info("register: cancelled; {} is left as it was", model_dir.string());
    return summary;
  }
  // The new points take the images' colours; the held ones keep theirs.
  for (const std::string& warning :
       ColorPointsFromImages(image_dir, &*result, map_settings.num_threads)) {
    spdlog::warn("register: {}", warning);
  }
  for (const auto& [point3D_id, point3D] : model.points3D) {
    const auto kept = result->points3D.find(point3D_id);
    if (kept != result->points3D.end()) kept->second.color = point3D.color;
  }
  summary.register_seconds = register_timer.ElapsedSeconds();
  summary.num_images_after = result->images.size();
  summary.num_points_after = result->points3D.size();

  // 4. The model, by the manifest's exporters as `map` writes it, and the summary, as
  // one set: sparse/N (and what the exporters write for model N) is replaced, nothing
  // else of the workspace's outputs.
  OutputTransaction outputs(arguments.output, OutputTransaction::Mode::kAddToSet);
  outputs.Protect(image_dir);
  outputs.Protect(ImageFolder({}, database));
  std::vector<std::string> quarantined;
  ExportModel(*result, static_cast<size_t>(arguments.model_index), georeference, map_settings,
              image_dir, arguments.output, workspace->crash_log(), &outputs, &quarantined);
  summary.seconds = timer.ElapsedSeconds();
  WriteFileAtomically(outputs.StageFor("tessera") / kRegisterSummaryFile,
                      summary.ToJson().dump(2) + "\n");
  outputs.Commit();
  return summary;
}

}  // namespace tessera
