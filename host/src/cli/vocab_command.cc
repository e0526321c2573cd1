// `tessera vocab`: trains a retrieval codebook once from a folder of images, for the
// `retrieval` pair selector's `codebook` option. The work is the pipeline's
// (pipeline/vocabulary_training.h); this parses the arguments and prints the summary.

#include <spdlog/spdlog.h>

#include <filesystem>
#include <memory>
#include <string>
#include <utility>

#include "cli/commands.h"
#include "pipeline/pipeline_context.h"
#include "pipeline/vocabulary_training.h"
#include "util/exit_codes.h"
#include "util/paths.h"

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
  return {sub, [options]() {
            Manifest manifest = Manifest::Load(options->manifest.empty()
                                                   ? DefaultManifestFile()
                                                   : std::filesystem::path(options->manifest));
            if (options->threads > 0) manifest.num_threads = options->threads;
            PrepareManifestForVocabulary(&manifest, options->codebook_size);
            const PipelineContext context = PipelineContext::Create(std::move(manifest));
            const VocabularySummary summary =
                TrainVocabulary(context, {options->images, options->output, options->workspace});
            spdlog::info(
                "vocab: codebook of {} centres trained on {} images ({} features), written to "
                "{}; {:.2f} s",
                summary.codebook_size, summary.num_images, summary.num_features, options->output,
                summary.seconds);
            return static_cast<int>(kExitSuccess);
          }};
}

}  // namespace tessera
