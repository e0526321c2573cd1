#pragma once

// Names from outside Tessera (image names read from COLMAP models and databases, video
// file names, option values written into scripts): the one check an image name passes
// before it becomes a path below a folder, and how such names are shown in messages.
// Compiled into libtessera_io, so that its COLMAP model reader calls it too, but host
// only: this header is not part of the SDK (host/include/tessera), and no plugin may
// include it.

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

}  // namespace tessera
