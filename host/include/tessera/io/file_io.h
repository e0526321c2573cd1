#pragma once

// Reading whole files, and writing output files so that a reader never sees a
// half-written one.

#include <filesystem>
#include <string>

#include "tessera/io/export.h"

namespace tessera {

// The bytes of a file. Throws InputError naming the file when it cannot be read.
TESSERA_IO_EXPORT std::string ReadFileContents(const std::filesystem::path& path);

// Writes `contents` to a temporary file in the folder of `path` and renames it to `path`
// when complete (replacing an existing file), so that `path` holds either its old
// contents or all of the new ones. Throws InputError naming the file when it cannot be
// written; the temporary file is removed then.
TESSERA_IO_EXPORT void WriteFileAtomically(const std::filesystem::path& path,
                                           const std::string& contents);

// Creates `dir` and its parents when missing. Throws InputError naming the folder.
TESSERA_IO_EXPORT void CreateFolder(const std::filesystem::path& dir);

}  // namespace tessera
