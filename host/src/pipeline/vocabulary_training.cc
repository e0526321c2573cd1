#include "pipeline/vocabulary_training.h"

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include "database/database_feature_reader.h"
#include "pipeline/extract_stage.h"
#include "pipeline/pair_selection_input.h"
#include "pipeline/workspace.h"
#include "plugin/plugin_call.h"
#include "util/timer.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

// A new folder under the system's temporary folder, removed with everything in it when
// this goes out of scope.
class TemporaryWorkspaceFolder {
 public:
  TemporaryWorkspaceFolder() {
    std::string pattern = (fs::temp_directory_path() / "tessera-vocab-XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) {
      throw InputError(fs::path(pattern).parent_path().string() +
                       ": cannot create a temporary workspace: " + std::strerror(errno));
    }
    path_ = pattern;
  }
  ~TemporaryWorkspaceFolder() {
    std::error_code error;
    fs::remove_all(path_, error);
  }
  TemporaryWorkspaceFolder(const TemporaryWorkspaceFolder&) = delete;
  TemporaryWorkspaceFolder& operator=(const TemporaryWorkspaceFolder&) = delete;
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

}  // namespace

void PrepareManifestForVocabulary(Manifest* manifest, int codebook_size) {
  PluginSlot slot{"retrieval", nlohmann::json::object(), "pipeline.pair_selector", ""};
  const auto it = std::find_if(manifest->pair_selectors.begin(), manifest->pair_selectors.end(),
                               [](const PluginSlot& s) { return s.plugin == "retrieval"; });
  if (it != manifest->pair_selectors.end()) slot = *it;
  if (slot.options.is_object()) slot.options.erase("codebook");
  if (codebook_size > 0) slot.options["codebook_size"] = codebook_size;
  manifest->pair_selectors = {slot};
  manifest->matcher.reset();
  manifest->bundle_adjuster.reset();
  manifest->exporters.clear();
}

VocabularySummary TrainVocabulary(const PipelineContext& context,
                                  const VocabularySettings& settings) {
  const Timer timer;
  context.Require("detector", "vocab");
  const DescriptorMetric metric = context.detector.Call(
      PluginStage::kOptions, "", [](const Detector& detector) { return detector.Metric(); });
  context.CheckPairSelectorDescriptors(metric, 0);

  std::optional<TemporaryWorkspaceFolder> temporary;
  if (settings.workspace.empty()) temporary.emplace();
  // Opened as every stage opens it: locked, its crash log kept, its folder left out of
  // the image scan.
  const auto workspace = Workspace::Open(temporary ? temporary->path() : settings.workspace);
  const ExtractionSummary extraction =
      ExtractFeatures(*workspace, context.MakeExtractSettings(settings.image_dir));
  const Database& database = workspace->database();
  const int dimension = database.DescriptorDimension().value_or(0);
  context.CheckPairSelectorDescriptors(metric, dimension);

  PairSelectionInput input = ReadPairSelectionInput(database);
  input.num_threads = context.manifest.EffectiveNumThreads();
  std::vector<image_t> image_ids;
  for (const PairSelectionImage& image : input.images) image_ids.push_back(image.image_id);
  const DatabaseFeatureReader reader(&database, image_ids, metric, dimension);
  input.features = &reader;
  const auto& selector = context.pair_selectors.front();
  try {
    selector.Call(PluginStage::kTrain, std::to_string(input.images.size()) + " images",
                  [&](PairSelector& plugin) { plugin.Train(input, settings.codebook_file); });
  } catch (const PluginError& train_error) {
    if (!train_error.input_error()) throw;
    throw InputError(settings.image_dir.string() +
                     ": cannot train a codebook: " + train_error.what());
  }
  VocabularySummary summary;
  summary.num_images = extraction.num_images;
  summary.num_features = extraction.num_features;
  summary.codebook_size = selector.EffectiveOptions().value("codebook_size", 0);
  summary.seconds = timer.ElapsedSeconds();
  return summary;
}

}  // namespace tessera
