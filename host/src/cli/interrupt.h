#pragma once

// Ctrl-C (SIGINT) and SIGTERM during a pipeline verb: the first one cancels the stages
// through a CancellationToken, so that every image and pair finished is kept and the
// same command resumes; a second one ends the process at once (the workspace stays
// consistent: each unit of work is its own transaction).

#include "pipeline/stage_control.h"

namespace tessera {

// Installs the handlers for the life of the process (idempotent) and returns the token
// they cancel.
const CancellationToken& InterruptToken();

// Whether SIGINT or SIGTERM came since InterruptToken installed the handlers (false before):
// an error that follows an interrupt is reported as the interrupt (main.cc).
bool InterruptRequested();

// Logs that the verb was interrupted, what was kept and how to resume; returns
// kExitInterrupted (cli/exit_codes.h).
int ReportInterrupted(const char* verb);

}  // namespace tessera
