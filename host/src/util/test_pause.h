#pragma once

#include <string_view>

namespace tessera {

// A named place in the pipeline where an end-to-end test can act on a running process
// without racing a timer. When the environment names the place and a count,
// TESSERA_TEST_PAUSE=match.pair_committed:5, the process stops itself (SIGSTOP) the fifth
// time it passes there; the test waits for the stopped state, sends its signal (kill -9,
// SIGINT) or starts a second writer, and resumes the process with SIGCONT. Without the
// variable, or for any other place, this is one relaxed atomic load.
void PauseIfTestAsks(std::string_view place);

}  // namespace tessera
