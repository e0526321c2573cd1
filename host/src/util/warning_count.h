#pragma once

// How many warnings (and errors) the process has logged, for a verdict that points at
// "the warnings above" only where there are some. Counted by a sink that the command
// line adds to its logger (WarningCountingSink); 0 where none was added.

#include <spdlog/sinks/sink.h>

#include <cstddef>
#include <memory>

namespace tessera {

// A sink that writes nothing and counts the messages at warning level or above.
std::shared_ptr<spdlog::sinks::sink> WarningCountingSink();

// The messages at warning level or above that the sinks of WarningCountingSink saw.
size_t NumWarningsLogged();

}  // namespace tessera
