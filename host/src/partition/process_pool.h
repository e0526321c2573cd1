#pragma once

// Runs commands as child processes, at most `jobs` at once, in the given order: the
// clusters of `map --hierarchical` on one host, each a `tessera map --cluster K`.

#include <string>
#include <vector>

namespace tessera {

// Each command is argv (argv[0] an executable path). Returns each one's exit code (128 +
// N for a child killed by signal N, 127 when it could not be started), in the order of
// `commands`. Children inherit stdout and stderr.
std::vector<int> RunProcessPool(const std::vector<std::vector<std::string>>& commands, int jobs);

}  // namespace tessera
