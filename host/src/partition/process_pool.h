#pragma once

// Runs commands as child processes, at most `jobs` at once, in the given order: the
// clusters of `map --hierarchical` on one host, each a `tessera map --cluster K`. The
// children stop with the pool (util/child_process.h): a stop request is passed on to
// them as SIGTERM, and they are killed (SIGKILL) when the pool's process ends first.

#include <functional>
#include <string>
#include <vector>

namespace tessera {

// The exit code of a command the pool never started, because it was asked to stop.
constexpr int kNotStarted = -1;

// Each command is argv (argv[0] an executable path). Returns each one's exit code (128 +
// N for a child killed by signal N, 127 when it could not be started, kNotStarted), in
// the order of `commands`. Children inherit stdout and stderr. Once `stop_requested`
// (may be empty) returns true, no command is started and the running ones get SIGTERM
// (once); the pool returns when they have ended.
std::vector<int> RunProcessPool(const std::vector<std::vector<std::string>>& commands, int jobs,
                                const std::function<bool()>& stop_requested = {});

}  // namespace tessera
