#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace tessera {

// Loads each file in a child process before the host loads it, as GStreamer's plugin
// scanner does: a library whose static initialisers crash, exit or hang is refused
// instead of taking the host down. One child loads the files in order; when it dies on
// one, a new child goes on with the next. Returns one entry per file: empty when the
// child loaded and unloaded it, else why it is refused, e.g. "crashes on load
// (SIGSEGV)". A file the child only refuses (not a plugin, wrong ABI) probes fine:
// InspectPluginFile says why.
std::vector<std::string> ProbePluginFiles(const std::vector<std::filesystem::path>& files,
                                          int timeout_seconds = 30);

}  // namespace tessera
