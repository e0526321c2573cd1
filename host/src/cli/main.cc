// The `tessera` command line: one subcommand per verb. Every verb maps bad input to
// exit code 2 with a one-line message, and unexpected failures to exit code 1.

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <iostream>

#include "cli/commands.h"
#include "cli/interrupt.h"
#include "plugin/plugin_call.h"
#include "tessera/errors.h"
#include "util/exit_codes.h"
#include "util/warning_count.h"

int main(int argc, char** argv) {
  using namespace tessera;
  InstallPluginCrashHandler(kExitPluginCrash);
  CLI::App app{"Tessera: Structure-from-Motion whose every stage is a plugin"};
  app.require_subcommand(1);
  app.set_version_flag("--version", TESSERA_VERSION);
  GlobalOptions global;
  app.add_flag("-q,--quiet", global.quiet, "Only warnings and errors on stderr");
  app.add_flag("-v,--verbose", global.verbose, "Debug output");
  // -q and -v are taken after the verb too (`tessera map ... -v`): what a verb does not
  // know falls through to these.
  app.fallthrough();

  std::vector<CommandRegistration> commands = RegisterCommands(app, global);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    const int code = app.exit(error);
    return code == 0 ? kExitSuccess : kExitBadInput;
  }

  auto logger = spdlog::stderr_color_mt("tessera");
  logger->sinks().push_back(WarningCountingSink());  // "see the warnings above" only if any
  spdlog::set_default_logger(logger);
  spdlog::set_pattern("%^[%l]%$ %v");
  spdlog::set_level(global.quiet ? spdlog::level::warn
                                 : (global.verbose ? spdlog::level::debug : spdlog::level::info));

  for (const auto& command : commands) {
    if (!command.subcommand->parsed()) continue;
    const std::string verb = command.subcommand->get_name();
    // What fails once Ctrl-C or SIGTERM came (a plugin scan cut short, a child ended) is
    // the interrupt's doing: reported as the interrupt, exit 130, never as a crash.
    const auto interrupted = [&](const std::exception& error) {
      spdlog::warn("{}: stopped by the interrupt: {}", verb, error.what());
      return ReportInterrupted(verb.c_str());
    };
    try {
      return command.run();
    } catch (const PluginError& error) {
      if (InterruptRequested()) return interrupted(error);
      spdlog::error("{}", error.what());
      return error.input_error() ? kExitBadInput : kExitInternalError;
    } catch (const InputError& error) {
      if (InterruptRequested()) return interrupted(error);
      spdlog::error("{}", error.what());
      return kExitBadInput;
    } catch (const std::exception& error) {
      if (InterruptRequested()) return interrupted(error);
      spdlog::error("internal error: {}", error.what());
      return kExitInternalError;
    }
  }
  return kExitInternalError;
}
