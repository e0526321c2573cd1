#pragma once

// Tessera::io (libtessera_io.so) is built with hidden visibility; its public API,
// and only that, is exported with TESSERA_IO_EXPORT.
#define TESSERA_IO_EXPORT __attribute__((visibility("default")))
