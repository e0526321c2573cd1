// `tessera register --output WS [--images DIR] [--manifest M] [--camera-K K.txt]
// [--model-index N] [--refine-existing] [--json]`: new photos placed into model N of a workspace,
// its cameras, poses and points held (toolbox/register_images.h does the work).

#include <spdlog/spdlog.h>

#include <iostream>

#include "cli/commands.h"
#include "cli/interrupt.h"
#include "toolbox/register_images.h"
#include "util/exit_codes.h"

namespace tessera {

CommandRegistration RegisterRegisterCommand(CLI::App& app, const GlobalOptions&) {
  struct Options {
    std::string output;
    std::string images;
    bool json = false;
    RegisterArguments arguments;
  };
  auto options = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand(
      "register", "Register new images into an existing model, holding it (no re-map)");
  sub->add_option("--output", options->output, "Workspace folder (database.db, sparse/N)")
      ->required();
  sub->add_option("--images", options->images,
                  "Folder of the model's images and the new ones (default: the workspace's)");
  sub->add_option("--manifest", options->arguments.stage.manifest,
                  "Pipeline manifest (default: default.json)");
  sub->add_option("--camera-K", options->arguments.stage.camera_K,
                  "Known intrinsics, as the workspace was extracted with (a K.txt file)");
  sub->add_option("--model-index", options->arguments.model_index,
                  "Model to register into: sparse/N (default 0)")
      ->check(AtLeast(0));
  sub->add_flag("--refine-existing", options->arguments.refine_existing,
                "Then adjust the whole model globally (the existing poses move too)");
  sub->add_option("--threads", options->arguments.stage.threads,
                  "Worker threads (default: manifest, else all cores)")
      ->check(CLI::Range(0, 1024));
  sub->add_flag("--json", options->json, "Print a JSON summary on stdout");

  auto run = [options]() {
    RegisterArguments arguments = options->arguments;
    arguments.output = options->output;
    arguments.images = options->images;
    StageControl control;
    control.cancel = &InterruptToken();
    const RegisterSummary summary = RegisterIntoModel(arguments, control);
    if (summary.status == StageStatus::kCancelled) return ReportInterrupted("register");
    for (const std::string& line : DescribeRegistration(summary)) spdlog::info("{}", line);
    if (options->json) std::cout << summary.ToJson().dump(2) << std::endl;
    return static_cast<int>(kExitSuccess);
  };
  return {sub, run};
}

}  // namespace tessera
