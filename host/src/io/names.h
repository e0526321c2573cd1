#pragma once

// Names from outside Tessera (image names read from COLMAP models and databases, video
// file names, option values written into scripts): the one check an image name passes
// before it becomes a path below a folder, and how such names are shown in messages.
// Compiled into libtessera_io, so that its COLMAP model reader calls it too, but host
// only: this header is not part of the SDK (host/include/tessera), and no plugin may
// include it.

#include <filesystem>
#include <string>
#include <string_view>

#include "tessera/io/export.h"

namespace tessera {

// `text` with each control character (below 0x20, and 0x7f) written as an escape (\n,
// \r, \t, \0, else \xHH), so that a message naming it stays on one line and shows it.
TESSERA_IO_EXPORT std::string EscapeControlCharacters(std::string_view text);

// Whether `text` holds a control character (below 0x20, or 0x7f).
TESSERA_IO_EXPORT bool HasControlCharacter(std::string_view text);

// Why the image name `name` cannot name a file below a folder, as a phrase that follows
// "the name" ("is an absolute path", "has a '..' component, ..."): empty, absolute, a
// ".." component, a control character. Empty when the name is fine.
TESSERA_IO_EXPORT std::string ImageNameProblem(std::string_view name);

// Throws InputError "<where>: the image name '<name, escaped>' <problem>." when `name`
// has an ImageNameProblem. `where` names the file and record, e.g. "x/images.bin: image 3".
TESSERA_IO_EXPORT void CheckImageName(std::string_view name, const std::string& where);

// Paths Tessera reads back from its own files (the outputs ledger, frames.json) and then
// deletes, replaces or reads: the one check each passes before anything acts on it.
// Tessera writes such paths relative and lexically normal, so anything else was edited.

// Why `path` cannot be such a path below a folder, as a phrase that follows "the path"
// ("is an absolute path", "has a '..' component, ..."): empty, absolute, not lexically
// normal (an empty, '.' or '..' component: "a//b", "a/", "./a"), a backslash (another
// system's separator), a control character. Empty when the path is fine.
TESSERA_IO_EXPORT std::string RelativePathProblem(std::string_view path);

// The first of folder/C1, folder/C1/C2, ... (every folder on the way to folder/relative,
// not folder/relative itself) that is a symbolic link now; empty when none is. Tessera
// makes no links, and acts on nothing through one.
TESSERA_IO_EXPORT std::filesystem::path LinkOnTheWay(const std::filesystem::path& folder,
                                                     const std::filesystem::path& relative);

// Throws InputError "<where>: the path '<path, escaped>' <problem>" when `path` has a
// RelativePathProblem, or lies through a link (LinkOnTheWay of `folder`).
TESSERA_IO_EXPORT void CheckPathBelow(const std::filesystem::path& folder, std::string_view path,
                                      const std::string& where);

}  // namespace tessera
