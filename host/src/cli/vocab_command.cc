// `tessera vocab`: trains a retrieval codebook once from a folder of images, for the
// `retrieval` pair selector's `codebook` option. Features are detected with the
// manifest's detector into a workspace (a temporary one unless --workspace is given),
// then the manifest's `retrieval` pair selector (or a default one) trains on them.

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <map>

#include "cli/commands.h"
#include "database/database.h"
#include "feature/database_feature_reader.h"
#include "pipeline/extract_stage.h"
#include "pipeline/pipeline_context.h"
#include "pipeline/workspace.h"
#include "plugin/plugin_call.h"
#include "util/exit_codes.h"
#include "util/paths.h"
#include "util/strings.h"
#include "util/timer.h"

namespace tessera {
namespace {

struct VocabOptions {
  std::string images;
  std::string output;
  std::string manifest;
  std::string workspace;
  int codebook_size = 0;
  int threads = 0;
};

// The manifest's `retrieval` slot (or a new one when it has none), made to train:
// without its `codebook` (the file this command writes), with --codebook-size.
PluginSlot TrainingSlot(const Manifest& manifest, int codebook_size) {
  PluginSlot slot{"retrieval", nlohmann::json::object(), "pipeline.pair_selector", ""};
  const auto it = std::find_if(manifest.pair_selectors.begin(), manifest.pair_selectors.end(),
                               [](const PluginSlot& s) { return s.plugin == "retrieval"; });
  if (it != manifest.pair_selectors.end()) slot = *it;
  if (slot.options.is_object()) slot.options.erase("codebook");
  if (codebook_size > 0) slot.options["codebook_size"] = codebook_size;
  return slot;
}

// Every image of the workspace in capture order, with its camera and metadata.
PairSelectionInput ReadSelectionInput(const Database& database, std::vector<image_t>* image_ids) {
  std::vector<Image> images = database.ReadAllImages();
  std::sort(images.begin(), images.end(),
            [](const Image& a, const Image& b) { return NaturalLess(a.name, b.name); });
  std::map<camera_t, Camera> cameras;
  for (const Camera& camera : database.ReadAllCameras()) cameras[camera.camera_id] = camera;
  const std::map<image_t, ImageMetadata> metadata = database.ReadAllImageMetadata();
  PairSelectionInput input;
  for (const Image& image : images) {
    PairSelectionImage entry;
    entry.image_id = image.image_id;
    entry.name = image.name;
    entry.camera = cameras.at(image.camera_id);
    if (auto found = metadata.find(image.image_id); found != metadata.end()) {
      entry.metadata = found->second;
    }
    input.images.push_back(std::move(entry));
    image_ids->push_back(image.image_id);
  }
  return input;
}

}  // namespace

CommandRegistration RegisterVocabCommand(CLI::App& app, const GlobalOptions&) {
  auto options = std::make_shared<VocabOptions>();
  CLI::App* sub = app.add_subcommand(
      "vocab", "Train a retrieval codebook from a folder of images (retrieval's `codebook`)");
  sub->add_option("--images", options->images, "Folder of images to train on")->required();
  sub->add_option("--output", options->output, "Codebook file to write")->required();
  sub->add_option("--manifest", options->manifest,
                  "Manifest whose detector (and retrieval pair selector's options) to use "
                  "(default: default.json)");
  sub->add_option("--codebook-size", options->codebook_size,
                  "Centres of the codebook (default: the manifest's retrieval codebook_size, "
                  "else 64)")
      ->check(CLI::Range(1, 65536));
  sub->add_option("--workspace", options->workspace,
                  "Workspace folder for the features, kept (default: a temporary one)");
  sub->add_option("--threads", options->threads,
                  "Worker threads (default: manifest, else all cores)")
      ->check(CLI::Range(0, 1024));
  return {
      sub, [options]() {
        const Timer timer;
        Manifest manifest =
            Manifest::Load(options->manifest.empty() ? DefaultManifestFile()
                                                     : std::filesystem::path(options->manifest));
        if (options->threads > 0) manifest.num_threads = options->threads;
        // Only the detector and the training selector are needed.
        manifest.pair_selectors = {TrainingSlot(manifest, options->codebook_size)};
        manifest.matcher.reset();
        manifest.bundle_adjuster.reset();
        manifest.exporters.clear();
        PipelineContext context = PipelineContext::Create(std::move(manifest));
        context.Require("detector", "vocab");
        const DescriptorMetric metric = context.detector.Call(
            PluginStage::kOptions, "", [](const Detector& detector) { return detector.Metric(); });
        context.CheckPairSelectorDescriptors(metric, 0);

        const bool temporary = options->workspace.empty();
        std::filesystem::path folder = options->workspace;
        if (temporary) {
          std::string pattern =
              (std::filesystem::temp_directory_path() / "tessera-vocab-XXXXXX").string();
          if (mkdtemp(pattern.data()) == nullptr) {
            throw InputError(std::filesystem::path(pattern).parent_path().string() +
                             ": cannot create a temporary workspace: " + std::strerror(errno));
          }
          folder = pattern;
        }
        struct Cleanup {
          std::filesystem::path dir;
          ~Cleanup() {
            std::error_code error;
            if (!dir.empty()) std::filesystem::remove_all(dir, error);
          }
        } cleanup{temporary ? folder : std::filesystem::path()};
        // Opened as every stage opens it: locked, its crash log kept, its folder left out
        // of the image scan.
        const auto workspace = Workspace::Open(folder);
        const ExtractionSummary extraction =
            ExtractFeatures(*workspace, context.MakeExtractSettings(options->images));
        const Database& database = workspace->database();
        const int dimension = database.DescriptorDimension().value_or(0);
        context.CheckPairSelectorDescriptors(metric, dimension);

        std::vector<image_t> image_ids;
        PairSelectionInput input = ReadSelectionInput(database, &image_ids);
        input.num_threads = context.manifest.EffectiveNumThreads();
        const DatabaseFeatureReader reader(&database, image_ids, metric, dimension);
        input.features = &reader;
        const auto& selector = context.pair_selectors.front();
        try {
          selector.Call(PluginStage::kTrain, std::to_string(input.images.size()) + " images",
                        [&](PairSelector& plugin) { plugin.Train(input, options->output); });
        } catch (const PluginError& train_error) {
          if (!train_error.input_error()) throw;
          throw InputError(options->images + ": cannot train a codebook: " + train_error.what());
        }
        spdlog::info(
            "vocab: codebook of {} centres trained on {} images ({} features), written to "
            "{}; {:.2f} s",
            selector.EffectiveOptions().value("codebook_size", 0), extraction.num_images,
            extraction.num_features, options->output, timer.ElapsedSeconds());
        return static_cast<int>(kExitSuccess);
      }};
}

}  // namespace tessera
