#pragma once

// Edits of a JSON text in place, for the manifest editor: a slot's plugin name replaced
// where it is written, every other character kept (the user's order, spacing and the
// other slots' options), instead of the whole text parsed and dumped again.

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace tessera::gui {

// `text` with pipeline.SLOT's "plugin" set to `plugin`: the name replaced in place; a
// slot without "plugin" gets it first in its object; a slot that is not an object (a
// list of pair selectors) becomes {"plugin": PLUGIN}; an absent slot is added first in
// "pipeline". Nothing when `text` has no "pipeline" object to edit (or is not JSON as
// far as the edit reads it): the caller then rewrites the JSON.
std::optional<std::string> SetPluginInText(const std::string& text, const std::string& slot,
                                           const std::string& plugin);

// `text` without the members `keys` of pipeline.SLOT.options, every other character kept
// (a member's comma goes with it; a key not there is skipped). Nothing when the text has
// no such options object to edit (or is not JSON as far as the edit reads it).
std::optional<std::string> RemoveOptionsInText(const std::string& text, const std::string& slot,
                                               const std::vector<std::string>& keys);

// What an edited manifest's "description" starts with: the recipe's words describe the
// plugins it was written with, not those chosen since.
inline constexpr std::string_view kEditedDescription =
    "(edited: its plugins were changed since this description was written) ";

// `text` with its top-level "description" (a string) starting with kEditedDescription,
// in place; `text` itself when it has none or it says so already.
std::string MarkDescriptionEditedInText(const std::string& text);

// `text` with the option `key` of the slot object at `slot_steps` (from the root: object
// keys, or an array's index in decimal, e.g. {"pipeline", "exporters", "1"}) set to
// `value`: replaced where it is written, else added after the slot's last option (an
// "options" object added after the slot's last member when it has none). With no
// `value`, the option is removed, and the "options" object with it once empty. Every
// other character kept. Nothing when the text has no such slot object (or options that
// are not an object) to edit, or is not JSON as far as the edit reads it.
std::optional<std::string> SetOptionInText(const std::string& text,
                                           const std::vector<std::string>& slot_steps,
                                           const std::string& key,
                                           const std::optional<nlohmann::json>& value);

}  // namespace tessera::gui
