#pragma once

// A plugin's option description (tessera/option_list.h, exported by
// TESSERA_PLUGIN_OPTIONS) as the host reads it: checked as input, since a third-party
// plugin may describe its options wrongly, and printed as `tessera plugins NAME` prints it.

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tessera/option_list.h"

namespace tessera {

// The options a plugin described, checked: an array of objects with a unique, non-empty
// `name`, a known `type`, a `default` of that type inside its range and choices, `min`
// and `max` (numbers or null, numeric types only), `choices` (strings) and `help`.
// Throws InputError "WHO: options[3] ('ratio'): ..." on the first fault.
std::vector<OptionDescription> ParseOptionDescriptions(const nlohmann::json& described,
                                                       const std::string& who);

// "[1, 1000000]", ">= 0", "'huber', 'cauchy'" or "" for an option without either.
std::string OptionRangeText(const OptionDescription& option);

// The options as a Markdown table (option, type, default, range or choices, meaning):
// the table the plugin pages carry between their generated-table markers.
std::string OptionDescriptionsMarkdown(const std::vector<OptionDescription>& options);

struct PluginRecord;
// "plugin 'x' (FILE) does not describe its options (it exports no tessera_plugin_options)".
std::string PluginDoesNotDescribe(const PluginRecord& record);

class PluginRegistry;
// What `tessera plugins NAME --json` prints and tessera.plugin_options returns: the
// record (PluginRecord::ToJson) with "options", the described options as JSON, or null
// when the plugin does not describe them. Throws as PluginRegistry::DescribeOptions.
nlohmann::json DescribedPluginJson(const PluginRegistry& registry, const PluginRecord& record);

// The options as aligned plain text, for a terminal.
std::string OptionDescriptionsText(const std::vector<OptionDescription>& options);

}  // namespace tessera
