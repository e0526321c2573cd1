// `tessera plugins [--json] [--manifest FILE]`: every plugin found on the search path,
// with the ones the host would refuse marked and why. `tessera plugins NAME [--json |
// --markdown]`: one plugin, with its options described (name, type, default, range or
// choices, help), for any plugin on the path. `tessera plugins --forget-crashes
// OUTPUT`: forgets the workspace's plugin crash records, and so its quarantine.

#include <iostream>
#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "manifest/manifest.h"
#include "plugin/option_descriptions.h"
#include "plugin/plugin_crash_log.h"
#include "plugin/plugin_registry.h"
#include "util/exit_codes.h"
#include "util/paths.h"

namespace tessera {

namespace {

// `tessera plugins NAME`: the record and the options of one plugin.
template <typename Options>
int DescribePlugin(const PluginRegistry& registry, const std::string& name,
                   const Options& options) {
  if (options.json && options.markdown) throw InputError("--json and --markdown: give one");
  const PluginRecord& record = registry.Find(name);
  if (options.json) {
    std::cout << DescribedPluginJson(registry, record).dump(2) << std::endl;
    return static_cast<int>(kExitSuccess);
  }
  const std::optional<std::vector<OptionDescription>> described = registry.DescribeOptions(record);
  if (options.markdown) {
    if (!described) throw InputError(PluginDoesNotDescribe(record));
    std::cout << OptionDescriptionsMarkdown(*described);
    return static_cast<int>(kExitSuccess);
  }
  std::cout << record.kind << " '" << record.name << "' " << record.version << ": "
            << record.description << "\n  " << record.file.string() << "\n";
  if (!described) {
    std::cout << PluginDoesNotDescribe(record) << "\n";
  } else if (described->empty()) {
    std::cout << "It takes no options.\n";
  } else {
    std::cout << "Options (\"options\": {...} in its manifest slot):\n"
              << OptionDescriptionsText(*described);
  }
  return static_cast<int>(kExitSuccess);
}

}  // namespace

CommandRegistration RegisterPluginsCommand(CLI::App& app, const GlobalOptions&) {
  struct Options {
    bool json = false;
    bool markdown = false;
    std::string name;
    std::string manifest;
    std::string forget_crashes;
  };
  auto options = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand("plugins", "List the plugins found and the ones refused");
  sub->add_option("name", options->name, "Describe this plugin and its options");
  sub->add_flag("--json", options->json, "Print JSON instead of a table");
  sub->add_flag("--markdown", options->markdown,
                "With NAME: print the options as the Markdown table of the plugin's page");
  sub->add_option("--manifest", options->manifest, "Also search the plugin_paths of this manifest");
  sub->add_option("--forget-crashes", options->forget_crashes,
                  "Forget the plugin crashes recorded in this output folder (plugin_crashes.tsv), "
                  "and so their quarantine, instead of listing plugins");

  auto run = [options]() {
    if (!options->forget_crashes.empty()) {
      const size_t forgotten = ForgetPluginCrashes(options->forget_crashes);
      std::cout << "Forgot " << forgotten << " plugin crash record(s) in "
                << options->forget_crashes << "\n";
      return static_cast<int>(kExitSuccess);
    }
    std::vector<std::filesystem::path> manifest_paths;
    if (!options->manifest.empty()) manifest_paths = Manifest::Load(options->manifest).plugin_paths;
    const PluginRegistry registry = PluginRegistry::Discover(PluginSearchPath(manifest_paths));
    if (!options->name.empty()) return DescribePlugin(registry, options->name, *options);
    if (options->markdown) throw InputError("--markdown: give the plugin's NAME too");

    if (options->json) {
      std::cout << registry.ToJson().dump(2) << std::endl;
      return static_cast<int>(kExitSuccess);
    }
    std::cout << "Plugin ABI version " << kPluginAbiVersion << "; searched:";
    for (const auto& path : registry.search_paths()) std::cout << ' ' << path.string();
    std::cout << "\n";
    for (const auto& record : registry.records()) {
      if (record.usable()) {
        std::printf("  %-16s %-18s %-8s %s\n", record.kind.c_str(), record.name.c_str(),
                    record.version.c_str(), record.file.string().c_str());
      } else {
        std::printf("  REFUSED %s\n", record.refusal.c_str());
      }
    }
    if (registry.records().empty()) std::cout << "  (no plugins found)\n";
    return static_cast<int>(kExitSuccess);
  };
  return {sub, run};
}

}  // namespace tessera
