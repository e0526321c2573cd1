#pragma once

// Tessera::sfm (libtessera_sfm.so) is built with hidden visibility: what its headers
// mark TESSERA_SFM_EXPORT is its API, for the bundled mappers and third parties' alike.
#define TESSERA_SFM_EXPORT __attribute__((visibility("default")))
