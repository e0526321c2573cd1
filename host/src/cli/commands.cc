#include "cli/commands.h"

#include <cstdint>
#include <string>

namespace tessera {

std::vector<CommandRegistration> RegisterCommands(CLI::App& app, const GlobalOptions& global) {
  return {RegisterRunCommand(app, global),      RegisterExtractCommand(app, global),
          RegisterMatchCommand(app, global),    RegisterMapCommand(app, global),
          RegisterExportCommand(app, global),   RegisterEvalCommand(app, global),
          RegisterBenchCommand(app, global),    RegisterPluginsCommand(app, global),
          RegisterVocabCommand(app, global),    RegisterPartitionCommand(app, global),
          RegisterMergeCommand(app, global),    RegisterSlurmCommand(app, global),
          RegisterGuiCommand(app, global),      RegisterTriangulateCommand(app, global),
          RegisterRegisterCommand(app, global), RegisterAdjustCommand(app, global),
          RegisterAlignCommand(app, global),    RegisterImportCommand(app, global)};
}

CLI::Validator AtLeast(int64_t minimum) {
  return CLI::Validator(
      [minimum](std::string& text) -> std::string {
        int64_t value = 0;
        if (CLI::detail::lexical_cast(text, value) && value >= minimum) return "";
        return "Value " + text + " is not a whole number of at least " + std::to_string(minimum);
      },
      "INT>=" + std::to_string(minimum));
}

}  // namespace tessera
