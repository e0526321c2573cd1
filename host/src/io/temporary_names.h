#pragma once

// The names of the temporary files of atomic writes (WriteFileAtomically): a token only
// Tessera writes, so that a leftover of an interrupted write is told from a user's file
// by its name alone. Host only, like names.h: not part of the SDK.
//   .NAME.tessera-tmp-PID-RANDOM   NAME the file written, PID the writing process,
//                                  RANDOM 16 lowercase hex digits, new for every write

#include <optional>
#include <string>
#include <string_view>

#include "tessera/io/export.h"

namespace tessera {

inline constexpr std::string_view kTemporaryToken = ".tessera-tmp-";

// A new temporary name for a file named `name` (a file name, no folder): unique to this
// process and this call (another thread writing the same file gets another name).
TESSERA_IO_EXPORT std::string NewTemporaryFileName(const std::string& name);

struct TemporaryFileName {
  std::string target;  // NAME: the file the write was for
  long pid = 0;        // the process that wrote it
};

// `name` read as such a temporary name; nullopt unless it is exactly one (a user's
// ".notes.tmp-999999" is none).
TESSERA_IO_EXPORT std::optional<TemporaryFileName> ParseTemporaryFileName(std::string_view name);

}  // namespace tessera
