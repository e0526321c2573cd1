#pragma once

namespace tessera {

// Exit codes of the `tessera` executable, documented in the README.
enum ExitCode : int {
  kExitSuccess = 0,
  kExitInternalError = 1,  // a bug or an unexpected failure (please report it)
  kExitBadInput = 2,       // bad input or configuration: the message says what to fix
  kExitNoModel = 3,        // the inputs were fine but no model could be built from them
  kExitPluginCrash = 4,    // a plugin crashed (fatal signal) or called exit(); resumable
  kExitInterrupted = 130,  // SIGINT (Ctrl-C) or SIGTERM: stopped cleanly; the workspace resumes
};

}  // namespace tessera
