#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "plugin/plugin_registry.h"

namespace tessera {

// Inspects each file in a child process before the host loads it, as GStreamer's plugin
// scanner does: a library whose static initialisers crash, exit or hang is refused
// instead of taking the host down. One child inspects the files in order
// (InspectPluginFile) and reports each record; when it dies on one, a new child goes
// on with the next. Returns one entry per file: the child's record (its library not
// open in this process), or a record refused with why, e.g. "crashes on load
// (SIGSEGV)", or "not inspected: the plugin scan was interrupted (SIGINT)" for a child
// that SIGINT, SIGTERM or SIGHUP ended (an interrupt is never a crash); nullopt where no
// child could be started.
std::vector<std::optional<PluginRecord>> ProbePluginFiles(
    const std::vector<std::filesystem::path>& files, int timeout_seconds = 30);

}  // namespace tessera
