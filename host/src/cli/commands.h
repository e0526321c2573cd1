#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <vector>

namespace tessera {

struct GlobalOptions {
  bool quiet = false;
  bool verbose = false;
};

// A verb: its CLI11 subcommand and what runs when it was given. run() returns the
// exit code and may throw InputError (exit 2) or any other exception (exit 1).
struct CommandRegistration {
  CLI::App* subcommand = nullptr;
  std::function<int()> run;
};

std::vector<CommandRegistration> RegisterCommands(CLI::App& app, const GlobalOptions& global);

// A whole number of at least `minimum`, refused plainly ("--frames: Value -1 is not a
// whole number of at least 1"): CLI11's PositiveNumber and NonNegativeNumber write their
// upper bound, DBL_MAX, out in full.
CLI::Validator AtLeast(int64_t minimum);

// One registration function per verb, each in its own file.
CommandRegistration RegisterPluginsCommand(CLI::App& app, const GlobalOptions& global);
CommandRegistration RegisterRunCommand(CLI::App& app, const GlobalOptions& global);
CommandRegistration RegisterExtractCommand(CLI::App& app, const GlobalOptions& global);
CommandRegistration RegisterMatchCommand(CLI::App& app, const GlobalOptions& global);
CommandRegistration RegisterMapCommand(CLI::App& app, const GlobalOptions& global);
CommandRegistration RegisterEvalCommand(CLI::App& app, const GlobalOptions& global);
CommandRegistration RegisterExportCommand(CLI::App& app, const GlobalOptions& global);
CommandRegistration RegisterBenchCommand(CLI::App& app, const GlobalOptions& global);
CommandRegistration RegisterVocabCommand(CLI::App& app, const GlobalOptions& global);
CommandRegistration RegisterPartitionCommand(CLI::App& app, const GlobalOptions& global);
CommandRegistration RegisterMergeCommand(CLI::App& app, const GlobalOptions& global);
CommandRegistration RegisterSlurmCommand(CLI::App& app, const GlobalOptions& global);
CommandRegistration RegisterGuiCommand(CLI::App& app, const GlobalOptions& global);
CommandRegistration RegisterTriangulateCommand(CLI::App& app, const GlobalOptions& global);
CommandRegistration RegisterRegisterCommand(CLI::App& app, const GlobalOptions& global);
CommandRegistration RegisterAdjustCommand(CLI::App& app, const GlobalOptions& global);
CommandRegistration RegisterAlignCommand(CLI::App& app, const GlobalOptions& global);
CommandRegistration RegisterImportCommand(CLI::App& app, const GlobalOptions& global);

}  // namespace tessera
