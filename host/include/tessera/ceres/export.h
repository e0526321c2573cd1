#pragma once

// Tessera::ceres (libtessera_ceres.so) is built with hidden visibility: what its headers
// mark TESSERA_CERES_EXPORT is its API, for the bundled `ceres` adjuster and third
// parties' bundle adjusters alike.
#define TESSERA_CERES_EXPORT __attribute__((visibility("default")))
