#include "toolbox/feature_import.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>

#include "image/image_folder_scan.h"
#include "pipeline/extract_stage.h"
#include "plugin/plugin_call.h"
#include "util/parallel.h"
#include "util/timer.h"

namespace tessera {

std::string ImportedFeatures::Where(size_t row) const {
  if (first_line > 0) return source + ":" + std::to_string(first_line + row);
  return source + " row " + std::to_string(row);
}

namespace {

// The whitespace-separated values of one line, parsed as numbers; the index of the first
// token that is no number, or -1.
struct LineValues {
  std::vector<double> values;
  std::string bad_token;
};

LineValues ParseLine(const std::string& line) {
  LineValues parsed;
  const char* cursor = line.c_str();
  while (true) {
    while (*cursor == ' ' || *cursor == '\t' || *cursor == '\r') ++cursor;
    if (*cursor == '\0') break;
    const char* start = cursor;
    while (*cursor != '\0' && *cursor != ' ' && *cursor != '\t' && *cursor != '\r') ++cursor;
    const std::string token(start, cursor);
    char* end = nullptr;
    errno = 0;
    const double value = std::strtod(token.c_str(), &end);
    if (end != token.c_str() + token.size() || token.empty()) {
      if (parsed.bad_token.empty()) parsed.bad_token = token;
      parsed.values.push_back(std::nan(""));
    } else {
      parsed.values.push_back(value);
    }
  }
  return parsed;
}

bool IsBlank(const std::string& line) {
  return line.find_first_not_of(" \t\r") == std::string::npos;
}

// "N D" as two whole numbers, N >= 0 and D >= 1.
std::pair<size_t, size_t> ParseHeader(const std::string& line, const std::string& where) {
  std::istringstream stream(line);
  long long count = -1, dimension = -1;
  std::string rest;
  if (!(stream >> count >> dimension) || (stream >> rest) || count < 0 || dimension < 1 ||
      dimension > 100000) {
    throw InputError(where +
                     ": the first line must be `N D` (the number of keypoints and the "
                     "descriptor width, D at least 1), not '" +
                     line + "'");
  }
  return {static_cast<size_t>(count), static_cast<size_t>(dimension)};
}

}  // namespace

ImportedFeatures ParseFeatureFile(const std::filesystem::path& file, const std::string& name) {
  std::ifstream stream(file, std::ios::binary);
  if (!stream) throw InputError(file.string() + ": cannot be read");
  ImportedFeatures features;
  features.name = name;
  features.source = file.string();
  features.first_line = 2;
  std::string line;
  if (!std::getline(stream, line)) {
    throw InputError(file.string() + ":1: empty file; the first line must be `N D`");
  }
  const auto [count, dimension] = ParseHeader(line, file.string() + ":1");
  features.keypoints.reserve(count);
  features.descriptors.resize(static_cast<Eigen::Index>(count),
                              static_cast<Eigen::Index>(dimension));
  for (size_t k = 0; k < count; ++k) {
    const std::string where = features.Where(k);
    if (!std::getline(stream, line)) {
      throw InputError(where + ": truncated: the header announces " + std::to_string(count) +
                       " keypoints, the file ends after " + std::to_string(k));
    }
    const LineValues parsed = ParseLine(line);
    if (parsed.values.size() != 4 + dimension) {
      throw InputError(where + ": " + std::to_string(parsed.values.size()) + " values; " +
                       std::to_string(4 + dimension) +
                       " expected (x y scale orientation and the header's " +
                       std::to_string(dimension) + " descriptor values)");
    }
    if (!parsed.bad_token.empty()) {
      throw InputError(where + ": '" + parsed.bad_token + "' is not a number");
    }
    const std::vector<double>& v = parsed.values;
    if (!std::isfinite(v[0]) || !std::isfinite(v[1])) {
      throw InputError(where + ": keypoint coordinates (" + std::to_string(v[0]) + ", " +
                       std::to_string(v[1]) + ") are not finite");
    }
    if (!std::isfinite(v[2]) || !std::isfinite(v[3]) || v[2] < 0) {
      throw InputError(where + ": scale " + std::to_string(v[2]) + " and orientation " +
                       std::to_string(v[3]) +
                       " must be finite, the scale not negative (write 1 0 when the detector "
                       "gives none)");
    }
    features.keypoints.emplace_back(static_cast<float>(v[0]), static_cast<float>(v[1]),
                                    static_cast<float>(v[2]), static_cast<float>(v[3]));
    for (size_t d = 0; d < dimension; ++d) {
      if (!std::isfinite(v[4 + d])) {
        throw InputError(where + ": descriptor value " + std::to_string(d + 1) + " is not finite");
      }
      features.descriptors(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(d)) =
          static_cast<float>(v[4 + d]);
    }
  }
  size_t line_number = count + 1;
  while (std::getline(stream, line)) {
    ++line_number;
    if (!IsBlank(line)) {
      throw InputError(file.string() + ":" + std::to_string(line_number) +
                       ": more lines than the header's " + std::to_string(count) + " keypoints");
    }
  }
  return features;
}

const char* DescriptorEncodingName(DescriptorEncoding encoding) {
  return encoding == DescriptorEncoding::kBytes ? "uint8" : "unit_float";
}

bool AllBytes(const DescriptorValues& values) {
  for (Eigen::Index i = 0; i < values.size(); ++i) {
    const float value = values.data()[i];
    if (!(value >= 0 && value <= 255 && value == std::round(value))) return false;
  }
  return true;
}

FeatureDescriptors EncodeDescriptors(const DescriptorValues& values, DescriptorEncoding encoding) {
  FeatureDescriptors descriptors;
  descriptors.metric = DescriptorMetric::kL2;
  descriptors.data.resize(values.rows(), values.cols());
  for (Eigen::Index r = 0; r < values.rows(); ++r) {
    const double norm = values.row(r).cast<double>().norm();
    for (Eigen::Index c = 0; c < values.cols(); ++c) {
      double value = values(r, c);
      if (encoding == DescriptorEncoding::kUnitFloat) {
        value = 128.0 + 256.0 * (norm > 0 ? value / norm : 0.0);
      }
      descriptors.data(r, c) = static_cast<uint8_t>(std::clamp(std::round(value), 0.0, 255.0));
    }
  }
  return descriptors;
}

FeatureSource FeatureFolderSource(const std::filesystem::path& folder) {
  std::error_code error;
  if (!std::filesystem::is_directory(folder, error)) {
    throw InputError(folder.string() + ": no such folder (the features, one NAME.txt per image)");
  }
  FeatureSource source;
  source.description = folder.string();
  for (auto it = std::filesystem::recursive_directory_iterator(folder, error);
       !error && it != std::filesystem::recursive_directory_iterator(); it.increment(error)) {
    const std::filesystem::path& path = it->path();
    if (!it->is_regular_file(error) || path.extension() != ".txt") continue;
    const std::string relative = path.lexically_relative(folder).generic_string();
    source.names.push_back(relative.substr(0, relative.size() - 4));
  }
  if (error) throw InputError(folder.string() + ": cannot be listed: " + error.message());
  std::sort(source.names.begin(), source.names.end());
  source.load = [folder](const std::string& name) {
    return ParseFeatureFile(folder / (name + ".txt"), name);
  };
  return source;
}

FeatureSource FeatureMemorySource(std::vector<ImportedFeatures> features) {
  auto by_name = std::make_shared<std::map<std::string, ImportedFeatures>>();
  FeatureSource source;
  source.description = "the features given";
  for (ImportedFeatures& image : features) {
    source.names.push_back(image.name);
    if (!by_name->emplace(image.name, std::move(image)).second) {
      throw InputError("features: '" + source.names.back() + "' is given twice");
    }
  }
  std::sort(source.names.begin(), source.names.end());
  source.load = [by_name](const std::string& name) { return by_name->at(name); };
  return source;
}

FeatureImportSettings MakeFeatureImportSettings(const PipelineContext& context,
                                                const MatchSettings& matching,
                                                const Workspace& workspace,
                                                const std::filesystem::path& images) {
  FeatureImportSettings settings;
  settings.image_dir = ImageFolder(images, workspace.database());
  if (settings.image_dir.empty()) {
    throw InputError("--images: " + workspace.folder().string() +
                     " records no image folder yet; give the folder of the images");
  }
  CheckImageFolderApart(settings.image_dir, workspace.folder());
  const ExtractSettings extract = context.MakeExtractSettings(settings.image_dir);
  settings.camera = extract.camera;
  settings.max_image_pixels = extract.max_image_pixels;
  settings.num_threads = extract.num_threads;
  settings.matching = &matching;
  return settings;
}

nlohmann::json FeatureImportSummary::ToJson() const {
  return {{"status", status == StageStatus::kCompleted ? "completed" : "cancelled"},
          {"num_images", num_images},
          {"num_imported", num_imported},
          {"num_reused", num_reused},
          {"num_replaced", num_replaced},
          {"num_without_features", num_without},
          {"num_features", num_features},
          {"dimension", dimension},
          {"descriptors", encoding},
          {"seconds", seconds}};
}

namespace {

// What pass 1 learnt of one image's features.
struct CheckedImage {
  size_t num_keypoints = 0;
  int dimension = 0;
  bool bytes = true;
  std::string header;  // where its width is said, for messages
};

// Arrays are checked as the text parser checks its lines: finite values, one
// descriptor row per keypoint.
void CheckValues(const ImportedFeatures& features) {
  if (static_cast<size_t>(features.descriptors.rows()) != features.keypoints.size()) {
    throw InputError(features.source + ": " + std::to_string(features.keypoints.size()) +
                     " keypoints but " + std::to_string(features.descriptors.rows()) +
                     " descriptor rows");
  }
  if (features.descriptors.cols() < 1) {
    throw InputError(features.source + ": descriptors of width 0");
  }
  for (size_t k = 0; k < features.keypoints.size(); ++k) {
    const FeatureKeypoint& keypoint = features.keypoints[k];
    if (!std::isfinite(keypoint.x) || !std::isfinite(keypoint.y)) {
      throw InputError(features.Where(k) + ": keypoint coordinates (" + std::to_string(keypoint.x) +
                       ", " + std::to_string(keypoint.y) + ") are not finite");
    }
    if (!std::isfinite(keypoint.a11) || !std::isfinite(keypoint.a12) ||
        !std::isfinite(keypoint.a21) || !std::isfinite(keypoint.a22)) {
      throw InputError(features.Where(k) + ": keypoint scale or orientation is not finite");
    }
    if (!features.descriptors.row(static_cast<Eigen::Index>(k)).allFinite()) {
      throw InputError(features.Where(k) + ": a descriptor value is not finite");
    }
  }
}

// Keypoints must lie in the image they were made on: features of a resized copy would
// otherwise be mapped as if they were the image's own.
void CheckKeypointsInside(const ImportedFeatures& features, const ImageEntry& entry) {
  for (size_t k = 0; k < features.keypoints.size(); ++k) {
    const FeatureKeypoint& keypoint = features.keypoints[k];
    if (keypoint.x >= 0 && keypoint.y >= 0 && keypoint.x <= entry.width &&
        keypoint.y <= entry.height) {
      continue;
    }
    throw InputError(features.Where(k) + ": keypoint (" + std::to_string(keypoint.x) + ", " +
                     std::to_string(keypoint.y) + ") lies outside image '" + entry.name + "' (" +
                     std::to_string(entry.width) + "x" + std::to_string(entry.height) +
                     "; coordinates are in pixels of the image as given, the centre of the "
                     "top-left pixel at (0.5, 0.5))");
  }
}

// The matcher and the pair selectors must take descriptors of this width: a probe match
// of two rows, and PairSelector::CheckDescriptors.
void CheckMatchable(const MatchSettings& matching, int dimension, const std::string& where) {
  CheckPairSelectors(matching, DescriptorMetric::kL2, dimension);
  if (matching.matcher == nullptr || !*matching.matcher) return;
  FeatureDescriptors probe;
  probe.metric = DescriptorMetric::kL2;
  probe.data = FeatureDescriptors::Matrix::Zero(2, dimension);
  probe.data(1, 0) = 1;
  try {
    matching.matcher->Call(PluginStage::kMatch, "descriptors of width " + std::to_string(dimension),
                           [&](auto& plugin) { return plugin.Match(probe, probe); });
  } catch (const PluginError& error) {
    if (!error.input_error()) throw;
    throw InputError(where + ": descriptors of width " + std::to_string(dimension) +
                     ": the manifest's matcher '" + matching.matcher->name() +
                     "' cannot take them: " + error.message());
  }
}

struct ImportPlan {
  ImageScan scan;                       // the images to hold: with features given or held
  std::map<std::string, size_t> given;  // image name -> index in scan, features given
  int dimension = 0;
  DescriptorEncoding encoding = DescriptorEncoding::kBytes;
};

// One width and one kind of descriptors for the workspace's features: the images given
// against each other and against those held. Returns where the width is said.
std::string ChooseWidthAndEncoding(const std::vector<CheckedImage>& checked,
                                   const Database& database, const std::string& description,
                                   ImportPlan* plan) {
  const auto stored = database.ReadStageProvenance(Database::kFeaturesStage);
  const std::vector<int64_t> widths = database.DescriptorWidths();
  std::optional<int> dimension;
  std::string dimension_source = database.path().string() + " (imported before)";
  if (!widths.empty()) dimension = static_cast<int>(widths.front());
  bool bytes = true;
  for (size_t k = 0; k < checked.size(); ++k) {
    if (!dimension) {
      dimension = checked[k].dimension;
      dimension_source = checked[k].header;
    } else if (checked[k].dimension != *dimension) {
      throw InputError(checked[k].header + ": descriptors of width " +
                       std::to_string(checked[k].dimension) + ", where " + dimension_source +
                       " has width " + std::to_string(*dimension) +
                       "; every image's descriptors must have one width");
    }
    bytes = bytes && checked[k].bytes;
  }
  plan->dimension = dimension.value_or(0);
  plan->encoding = bytes ? DescriptorEncoding::kBytes : DescriptorEncoding::kUnitFloat;
  if (stored && IsImportedFeatures(*stored) && database.NumKeypoints() > 0 && !checked.empty() &&
      stored->value("descriptors", std::string()) != DescriptorEncodingName(plan->encoding)) {
    // Held features of the other encoding: an import of whole numbers after floats is
    // still stored as floats were.
    if (stored->value("descriptors", std::string()) ==
        DescriptorEncodingName(DescriptorEncoding::kUnitFloat)) {
      plan->encoding = DescriptorEncoding::kUnitFloat;
    } else {
      throw InputError(description +
                       ": descriptors with fractional values, where the workspace holds "
                       "imported descriptors of whole numbers 0 to 255 (stored as they are); "
                       "import all of one kind");
    }
  }
  return dimension_source;
}

// Pass 1: every file read and checked, nothing written.
ImportPlan PlanImport(const Workspace& workspace, const FeatureImportSettings& settings,
                      const FeatureSource& source, FeatureImportSummary* summary) {
  const Database& database = workspace.database();
  const auto stored = database.ReadStageProvenance(Database::kFeaturesStage);
  if (stored && !IsImportedFeatures(*stored) && database.NumKeypoints() > 0) {
    throw InputError(database.path().string() + ": the workspace holds features of detector '" +
                     stored->value("plugin", std::string("?")) +
                     "'; import into a new workspace (imported and detected features never "
                     "meet in a matcher)");
  }
  ImageScan scan =
      ScanImageFolder(settings.image_dir,
                      workspace.ScanOptions(settings.camera.mask_path, settings.max_image_pixels));
  for (const auto& warning : scan.warnings) spdlog::warn("{}", warning);
  std::map<std::string, const ImageEntry*> scanned;
  for (const ImageEntry& entry : scan.images) scanned[entry.name] = &entry;
  for (const std::string& name : source.names) {
    if (!scanned.count(name)) {
      throw InputError(source.description + ": features for '" + name + "', which is no image of " +
                       settings.image_dir.string());
    }
  }
  // Which images to hold: those given features, and those holding imported ones.
  const std::set<std::string> given(source.names.begin(), source.names.end());
  std::set<std::string> held;
  const std::map<image_t, size_t> counts = database.ReadNumKeypointsPerImage();
  for (const Image& image : database.ReadAllImages()) {
    if (counts.count(image.image_id)) held.insert(image.name);
  }
  ImportPlan plan;
  std::vector<std::string> without;
  for (ImageEntry& entry : scan.images) {
    if (given.count(entry.name) || held.count(entry.name)) {
      if (given.count(entry.name)) plan.given[entry.name] = plan.scan.images.size();
      plan.scan.images.push_back(std::move(entry));
    } else {
      without.push_back(entry.name);
    }
  }
  summary->num_without = without.size();
  if (!without.empty()) {
    spdlog::warn("import: {} images of {} have no features in {} and are left out (first: '{}')",
                 without.size(), settings.image_dir.string(), source.description, without.front());
  }
  if (plan.scan.images.size() < 2) {
    throw InputError(source.description + ": features for " +
                     std::to_string(plan.scan.images.size()) + " image(s) of " +
                     settings.image_dir.string() + "; at least 2 are needed");
  }
  // Every image given, read and checked on its own, in parallel.
  std::vector<CheckedImage> checked(source.names.size());
  std::vector<std::string> errors(source.names.size());
  ParallelFor(source.names.size(), settings.num_threads, [&](size_t k) {
    try {
      const ImportedFeatures features = source.load(source.names[k]);
      CheckValues(features);
      CheckKeypointsInside(features, *scanned.at(source.names[k]));
      checked[k] = {features.keypoints.size(), static_cast<int>(features.descriptors.cols()),
                    AllBytes(features.descriptors),
                    features.first_line > 0 ? features.source + ":1" : features.source};
    } catch (const InputError& error) {
      errors[k] = error.what();
    }
  });
  for (const std::string& error : errors) {
    if (!error.empty()) throw InputError(error);
  }
  const std::string dimension_source =
      ChooseWidthAndEncoding(checked, database, source.description, &plan);
  if (settings.matching != nullptr && plan.dimension > 0) {
    CheckMatchable(*settings.matching, plan.dimension, dimension_source);
  }
  return plan;
}

// Whether the workspace holds exactly these features for the image.
bool HoldsSame(const Database& database, image_t image_id, const FeatureKeypoints& keypoints,
               const FeatureDescriptors& descriptors) {
  if (!database.ExistsKeypoints(image_id)) return false;
  const FeatureKeypoints held = database.ReadKeypoints(image_id);
  if (held.size() != keypoints.size()) return false;
  for (size_t k = 0; k < held.size(); ++k) {
    const FeatureKeypoint &a = held[k], &b = keypoints[k];
    if (a.x != b.x || a.y != b.y || a.a11 != b.a11 || a.a12 != b.a12 || a.a21 != b.a21 ||
        a.a22 != b.a22) {
      return false;
    }
  }
  const FeatureDescriptors stored = database.ReadDescriptors(image_id, DescriptorMetric::kL2);
  return stored.data.rows() == descriptors.data.rows() &&
         stored.data.cols() == descriptors.data.cols() && stored.data == descriptors.data;
}

}  // namespace

FeatureImportSummary ImportFeatures(const Workspace& workspace,
                                    const FeatureImportSettings& settings,
                                    const FeatureSource& source, const StageControl& control) {
  const Timer timer;
  FeatureImportSummary summary;
  Database* database = &workspace.database();
  const ImportPlan plan = PlanImport(workspace, settings, source, &summary);
  summary.num_images = plan.scan.images.size();
  summary.dimension = plan.dimension;
  summary.encoding = DescriptorEncodingName(plan.encoding);

  database->WriteStageProvenance(Database::kFeaturesStage,
                                 {{"imported", "tessera import"},
                                  {"metric", DescriptorMetricName(DescriptorMetric::kL2)},
                                  {"descriptors", summary.encoding}});
  database->WriteStageProvenance(
      Database::kImagesStage,
      {{"folder", std::filesystem::absolute(settings.image_dir).lexically_normal().string()}});
  ExtractionSummary ingest;
  const IngestedImages ingested = IngestImages(plan.scan, settings.camera, database, &ingest);

  std::vector<std::pair<std::string, size_t>> todo(plan.given.begin(), plan.given.end());
  std::mutex mutex;  // the counters and progress
  size_t done = 0;
  std::atomic<size_t> num_features{0};
  control.Report("import", 0, todo.size());
  ParallelFor(todo.size(), settings.num_threads, [&](size_t k) {
    if (control.Cancelled()) return;
    const auto& [name, index] = todo[k];
    const image_t image_id = ingested.images.at(index).image_id;
    if (image_id == kInvalidImageId) {  // an earlier extract could not decode it
      spdlog::warn("import: '{}' was skipped before ({}); its features are left out", name,
                   ingested.skipped_before.at(name));
      std::lock_guard<std::mutex> lock(mutex);
      control.Report("import", ++done, todo.size());
      return;
    }
    const ImportedFeatures features = source.load(name);
    const FeatureDescriptors descriptors = EncodeDescriptors(features.descriptors, plan.encoding);
    std::lock_guard<std::mutex> lock(mutex);
    if (HoldsSame(*database, image_id, features.keypoints, descriptors)) {
      ++summary.num_reused;
    } else {
      Database::Transaction transaction(database);
      if (database->ExistsKeypoints(image_id)) {
        database->DeletePairsOfImage(image_id);
        ++summary.num_replaced;
        spdlog::info("import: '{}': features changed; its matches and geometries are discarded",
                     name);
      }
      database->WriteKeypoints(image_id, features.keypoints);
      database->WriteDescriptors(image_id, descriptors);
      transaction.Commit();
      ++summary.num_imported;
      num_features += features.keypoints.size();
    }
    control.Report("import", ++done, todo.size());
  });
  summary.num_features = num_features;
  summary.seconds = timer.ElapsedSeconds();
  if (done < todo.size()) {
    summary.status = StageStatus::kCancelled;
    spdlog::info("import: cancelled after {} of {} images", done, todo.size());
    return summary;
  }
  spdlog::info(
      "import: {} images with features from {}: {} imported ({} keypoints, {} replaced), {} "
      "unchanged; descriptors {} wide, stored as {}; {:.2f} s",
      summary.num_images, source.description, summary.num_imported, summary.num_features,
      summary.num_replaced, summary.num_reused, summary.dimension, summary.encoding,
      summary.seconds);
  return summary;
}

}  // namespace tessera
