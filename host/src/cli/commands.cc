#include "cli/commands.h"

namespace tessera {

std::vector<CommandRegistration> RegisterCommands(CLI::App& app, const GlobalOptions& global) {
  return {RegisterPluginsCommand(app, global)};
}

}  // namespace tessera
