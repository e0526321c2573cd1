#include "cli/commands.h"

namespace tessera {

std::vector<CommandRegistration> RegisterCommands(CLI::App& app, const GlobalOptions& global) {
  return {RegisterRunCommand(app, global),    RegisterExtractCommand(app, global),
          RegisterMatchCommand(app, global),  RegisterMapCommand(app, global),
          RegisterExportCommand(app, global), RegisterEvalCommand(app, global),
          RegisterBenchCommand(app, global),  RegisterPluginsCommand(app, global),
          RegisterVocabCommand(app, global),  RegisterMergeCommand(app, global),
          RegisterSlurmCommand(app, global),  RegisterGuiCommand(app, global)};
}

}  // namespace tessera
