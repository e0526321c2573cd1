#include "pipeline/map_inputs.h"

#include <link.h>
#include <spdlog/spdlog.h>
#include <xxhash.h>

#include <algorithm>
#include <ctime>
#include <memory>
#include <type_traits>
#include <vector>

#include "outputs/output_ledger.h"
#include "pipeline/run_summary.h"
#include "tessera/errors.h"
#include "util/workspace_layout.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

// One part's digest: values fed in a fixed order, each text with its length, so that
// no two different inputs feed the same bytes.
class PartDigest {
 public:
  PartDigest() : state_(XXH3_createState(), &XXH3_freeState) { XXH3_64bits_reset(state_.get()); }

  template <typename T>
  void Value(const T& value) {
    static_assert(std::is_arithmetic_v<T>);
    XXH3_64bits_update(state_.get(), &value, sizeof(value));
  }
  void Doubles(const double* values, size_t count) {
    XXH3_64bits_update(state_.get(), values, count * sizeof(double));
  }
  void Text(const std::string& text) {
    Value(text.size());
    XXH3_64bits_update(state_.get(), text.data(), text.size());
  }
  void Pose(const Rigid3d& pose) {
    Doubles(pose.rotation.coeffs().data(), 4);
    Doubles(pose.translation.data(), 3);
  }
  // A file by its content (size and XXH3), or the reason it has none.
  void File(const fs::path& file) {
    if (file.empty()) return Text("no file");
    try {
      const FileDigest digest = DigestFile(file);
      Value(digest.size);
      Value(digest.xxh3);
    } catch (const InputError&) {
      Text("unreadable " + file.string());
    }
  }
  std::string Hex() const { return fmt::format("{:016x}", XXH3_64bits_digest(state_.get())); }

 private:
  std::unique_ptr<XXH3_state_t, decltype(&XXH3_freeState)> state_;
};

std::string NowUtc() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[64];
  std::strftime(text, sizeof(text), "%Y-%m-%d %H:%M:%S UTC", &utc);
  return text;
}

std::string Provenance(const Database& database, const char* stage) {
  const std::optional<nlohmann::json> provenance = database.ReadStageProvenance(stage);
  return provenance ? provenance->dump() : "none";
}

// A folder as one path, whichever way it was named.
std::string FolderText(const fs::path& folder) {
  if (folder.empty()) return "";
  std::error_code error;
  const fs::path canonical = fs::weakly_canonical(fs::absolute(folder), error);
  return error ? folder.string() : canonical.string();
}

template <typename Interface>
void AddPlugin(const PluginInstance<Interface>* plugin, PartDigest* digest) {
  if (plugin == nullptr) return digest->Text("none");
  digest->Text(plugin->Provenance().dump());
  digest->File(plugin->file());
}

// The SDK's libraries that the mapper, the bundle adjuster and the exporters call
// besides their own code (the sfm building blocks, Ceres, the model writers), as loaded.
// The host's own binary is left out: the CLI and the Python module keep each other's
// models.
std::vector<fs::path> SdkLibraries() {
  std::vector<fs::path> files;
  dl_iterate_phdr(
      [](dl_phdr_info* object, size_t, void* data) {
        const std::string name = fs::path(object->dlpi_name).filename().string();
        for (const char* library :
             {"libtessera_sfm.so", "libtessera_ceres.so", "libtessera_io.so"}) {
          if (name.rfind(library, 0) == 0) {
            static_cast<std::vector<fs::path>*>(data)->emplace_back(object->dlpi_name);
          }
        }
        return 0;
      },
      &files);
  std::sort(files.begin(), files.end());
  return files;
}

std::string CamerasDigest(const MapperInput& input, const Database& database) {
  PartDigest digest;
  digest.Text(Provenance(database, Database::kCamerasStage));
  for (const auto& [camera_id, camera] : input.cameras) {
    digest.Value(camera_id);
    digest.Value(static_cast<int>(camera.model_id));
    digest.Value(camera.width);
    digest.Value(camera.height);
    digest.Value(camera.params.size());
    digest.Doubles(camera.params.data(), camera.params.size());
    digest.Value(camera.has_prior_focal_length);
    digest.Value(static_cast<int>(camera.calibration_source));
  }
  return digest.Hex();
}

std::string ImagesDigest(const MapperInput& input, const Database& database,
                         const fs::path& image_dir) {
  PartDigest digest;
  digest.Text(Provenance(database, Database::kFeaturesStage));
  digest.Text(FolderText(image_dir));
  for (const auto& [image_id, image] : input.images) {
    digest.Value(image_id);
    digest.Value(image.camera_id);
    digest.Text(image.name);
    digest.Pose(image.cam_from_world);
    digest.Value(image.points2D.size());
    for (const Point2D& point : image.points2D) digest.Doubles(point.xy.data(), 2);
  }
  for (const auto& [image_id, metadata] : input.metadata) {
    digest.Value(image_id);
    digest.Text(ImageMetadataToJson(metadata).dump());
  }
  // The files the features were detected in: the descriptors a mapper may read, and
  // the colours of the points.
  for (const Database::ImageFile& file : database.ReadImageFiles()) {
    digest.Text(file.name);
    digest.Value(file.image_id.value_or(kInvalidImageId));
    digest.Value(file.size);
    digest.Text(file.content_hash);
    digest.Text(file.skip_reason);
  }
  return digest.Hex();
}

std::string MatchesDigest(const MapperInput& input, const Database& database) {
  PartDigest digest;
  for (const char* stage : {Database::kMatchesStage, Database::kTwoViewGeometriesStage,
                            Database::kPairSelectionStage}) {
    digest.Text(Provenance(database, stage));
  }
  for (const MapperInput::Pair& pair : input.pairs) {
    digest.Value(pair.image_id1);
    digest.Value(pair.image_id2);
    const TwoViewGeometry& geometry = pair.geometry;
    digest.Value(geometry.config);
    digest.Doubles(geometry.E.data(), 9);
    digest.Doubles(geometry.F.data(), 9);
    digest.Doubles(geometry.H.data(), 9);
    digest.Pose(geometry.cam2_from_cam1);
    digest.Value(geometry.inlier_matches.size());
    for (const FeatureMatch& match : geometry.inlier_matches) {
      digest.Value(match.point2D_idx1);
      digest.Value(match.point2D_idx2);
    }
  }
  return digest.Hex();
}

std::string RigDigest(const MapperInput& input, const MapSettings& settings) {
  PartDigest digest;
  digest.Text(settings.rig != nullptr ? settings.rig->path().string() + " " + settings.rig->digest()
                                      : "none");
  for (const CameraRig& rig : input.rigs) {
    digest.Value(rig.reference_camera);
    digest.Value(rig.poses_known);
    for (const auto& [camera_id, cam_from_rig] : rig.cam_from_rig) {
      digest.Value(camera_id);
      digest.Pose(cam_from_rig);
    }
    for (const auto& frame : rig.frames) {
      digest.Value(frame.size());
      for (const auto& [camera_id, image_id] : frame) {
        digest.Value(camera_id);
        digest.Value(image_id);
      }
    }
  }
  return digest.Hex();
}

// What a part is called in the line that says it changed.
std::string PartName(const std::string& part) {
  static const std::map<std::string, std::string> kNames = {
      {"cameras", "the cameras or the camera settings"},
      {"images", "the images, their features or the image folder"},
      {"matches", "the matches, their verification or the selected pairs"},
      {"rig", "the rig"},
      {"mapper", "the mapper, its options or the seed"},
      {"bundle_adjuster", "the bundle adjuster or its options"},
      {"outputs", "the exporters, their options or the mask folder"},
      {"tessera", "Tessera's build"}};
  const auto name = kNames.find(part);
  return name != kNames.end() ? name->second : part;
}

}  // namespace

nlohmann::json MapInputs::ToJson() const { return {{"mapped_at", mapped_at}, {"parts", parts}}; }

std::optional<MapInputs> MapInputs::FromJson(const nlohmann::json& json) {
  if (!json.is_object() || !json.contains("parts") || !json.at("parts").is_object()) {
    return std::nullopt;
  }
  MapInputs inputs;
  inputs.mapped_at = json.value("mapped_at", std::string("an unknown time"));
  for (const auto& [part, digest] : json.at("parts").items()) {
    if (!digest.is_string()) return std::nullopt;
    inputs.parts[part] = digest.get<std::string>();
  }
  return inputs;
}

MapInputs DigestMapInputs(const MapperInput& input, const MapSettings& settings,
                          const Database& database, const fs::path& image_dir) {
  MapInputs inputs;
  inputs.mapped_at = NowUtc();
  inputs.parts["cameras"] = CamerasDigest(input, database);
  inputs.parts["images"] = ImagesDigest(input, database, image_dir);
  inputs.parts["matches"] = MatchesDigest(input, database);
  inputs.parts["rig"] = RigDigest(input, settings);
  PartDigest mapper;
  AddPlugin(settings.mapper, &mapper);
  mapper.Value(settings.seed);
  inputs.parts["mapper"] = mapper.Hex();
  PartDigest bundle_adjuster;
  AddPlugin(settings.bundle_adjuster, &bundle_adjuster);
  inputs.parts["bundle_adjuster"] = bundle_adjuster.Hex();
  PartDigest outputs;
  if (settings.exporters != nullptr) {
    for (const PluginInstance<Exporter>& exporter : *settings.exporters) {
      AddPlugin(&exporter, &outputs);
    }
  }
  outputs.Text(FolderText(settings.mask_dir));
  inputs.parts["outputs"] = outputs.Hex();
  PartDigest tessera;
  for (const fs::path& file : SdkLibraries()) tessera.File(file);
  inputs.parts["tessera"] = tessera.Hex();
  return inputs;
}

std::string ChangedOutputs(const fs::path& output_dir) {
  OutputLedger ledger;
  try {
    ledger = OutputLedger::Read(output_dir);
  } catch (const InputError& error) {
    return error.what();
  }
  if (!ledger.HasFile(workspace_layout::kMappingSummary)) {
    return (output_dir / workspace_layout::kMappingSummary).string() + " is not one Tessera placed";
  }
  std::error_code error;
  for (const auto& [relative, digests] : ledger.files()) {
    if (relative == kRunSummaryFileName) continue;
    const fs::path path = output_dir / relative;
    if (digests.size() != 1) {
      return "placing the set was stopped (" + path.string() + " is old or new)";
    }
    if (fs::symlink_status(path, error).type() != fs::file_type::regular) {
      return path.string() + " is missing";
    }
    try {
      if (!(DigestFile(path) == digests.front())) {
        return path.string() + " was changed after Tessera wrote it";
      }
    } catch (const InputError& unreadable) {
      return unreadable.what();
    }
  }
  for (const std::string& relative : ledger.folders()) {
    if (fs::symlink_status(output_dir / relative, error).type() != fs::file_type::directory) {
      return (output_dir / relative).string() + " is missing";
    }
  }
  return "";
}

std::optional<MappingSummary> FindUnchangedModels(const fs::path& output_dir,
                                                  const MapInputs& inputs) {
  const fs::path file = output_dir / workspace_layout::kMappingSummary;
  std::error_code error;
  if (fs::symlink_status(file, error).type() != fs::file_type::regular) return std::nullopt;
  MappingSummary recorded;
  try {
    recorded = MappingSummary::Read(file);
  } catch (const InputError& unreadable) {
    spdlog::debug("map: {}", unreadable.what());
    return std::nullopt;
  }
  const std::optional<MapInputs> before = MapInputs::FromJson(recorded.inputs);
  if (!before || recorded.models.empty()) return std::nullopt;
  std::string changed;
  for (const auto& [part, digest] : inputs.parts) {
    const auto old = before->parts.find(part);
    if (old != before->parts.end() && old->second == digest) continue;
    changed += (changed.empty() ? "" : "; ") + PartName(part);
  }
  if (!changed.empty()) {
    spdlog::info("map: {} changed since the model of {}; mapping again", changed,
                 before->mapped_at);
    return std::nullopt;
  }
  if (const std::string why = ChangedOutputs(output_dir); !why.empty()) {
    spdlog::info("map: inputs unchanged since {}, but {}; mapping again", before->mapped_at, why);
    return std::nullopt;
  }
  // As a map that places its set warns (OutputTransaction::Commit).
  for (const std::string& warning :
       ForeignModelFolderWarnings(output_dir, OutputLedger::Read(output_dir))) {
    spdlog::warn("{}", warning);
  }
  return recorded;
}

}  // namespace tessera
