#pragma once

// COLMAP's rows of `tessera bench`: which COLMAP binaries run, their versions, and either
// their whole pipeline or their mappers alone on a copy of a Tessera row's database.

#include <filesystem>
#include <string>
#include <vector>

#include "bench/bench.h"
#include "bench/bench_rows.h"

namespace tessera {

struct ColmapBinary {
  std::string path;                // as given, found on the PATH, or the COLMAP 4 anchor
  std::string version;             // "3.8", "4.2.0.dev0": what its `-h` says
  bool has_global_mapper = false;  // `global_mapper` among its commands (COLMAP 4)
};

// Where the COLMAP 4 build is looked for when neither --colmap nor TESSERA_COLMAP names
// one, relative to the working directory and then to the repository of this executable.
constexpr const char* kColmap4Anchor = "../shared/anchors/colmap-4/bin/colmap";

// The COLMAP binaries that --with-colmap runs, each asked its version:
//  - every --colmap PATH, in order (a name without a slash is looked up on the PATH);
//  - without --colmap: $TESSERA_COLMAP if set, else kColmap4Anchor where present; then
//    `colmap` on the PATH (Debian's 3.8) where present and another file.
// Throws InputError, one line naming the binary, when one named or found cannot be used:
// missing, not executable, crashing, or not COLMAP 3.8 or later. `scratch` (a folder)
// takes the probes' output.
std::vector<ColmapBinary> FindColmapBinaries(const BenchOptions& options,
                                             const std::filesystem::path& scratch);

// The rows a binary gives, in order: "colmap-<version>-global" where it has the global
// mapper, then "colmap-<version>-incremental".
std::vector<std::string> ColmapRowNames(const ColmapBinary& colmap);

// COLMAP's whole pipeline on the images: feature extraction (CPU, one shared camera or
// one per folder) and exhaustive matching once, then each mapper on its own copy of that
// database; every row carries the shared extraction and matching seconds.
std::vector<BenchRow> RunColmapPipeline(const BenchOptions& options, const ColmapBinary& colmap,
                                        const BenchGroundTruth* ground_truth);

// COLMAP's mappers alone, each on its own copy of `source`'s database.db (COLMAP 4
// upgrades a database in place; the original stays as it was).
std::vector<BenchRow> RunColmapMappers(const BenchOptions& options, const ColmapBinary& colmap,
                                       const BenchGroundTruth* ground_truth,
                                       const BenchRow& source);

}  // namespace tessera
