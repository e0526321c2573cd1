#pragma once

// COLMAP's rows of `tessera bench`: which COLMAP binaries run, their versions, and either
// their whole pipeline or their mappers alone on a copy of a Tessera row's database. Each
// binary works in OUTPUT/colmap/<label>/: features/ (its extraction and matching), and
// one folder per mapper (global/, incremental/), each a row's own.

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "bench/bench.h"
#include "bench/bench_rows.h"

namespace tessera {

// What a COLMAP binary's `-h` says of its version.
struct ColmapVersion {
  std::string text;  // "3.8", "4.2.0.dev0": as printed, escaped and at most 64 characters
  int major = 0;
  int minor = 0;
};

// The first "COLMAP <major>.<minor>[...]" in `help`, read without std::regex (whose
// recursion has no stack bound on a long line); nullopt when there is none.
std::optional<ColmapVersion> ParseColmapVersion(std::string_view help);

struct ColmapBinary {
  std::string path;  // as given, found on the PATH, or the COLMAP 4 anchor
  ColmapVersion version;
  bool has_global_mapper = false;  // `global_mapper` among its commands (COLMAP 4)
  // "colmap-<version>" of [A-Za-z0-9._-], unique among the bench's binaries and rows
  // (AssignColmapLabels): its rows' names and its folder's, never its version as printed.
  std::string label;
};

// Where the COLMAP 4 build is looked for when neither --colmap nor TESSERA_COLMAP names
// one, relative to the working directory and then to the repository of this executable.
constexpr const char* kColmap4Anchor = "../shared/anchors/colmap-4/bin/colmap";

// The COLMAP binaries that --with-colmap runs, each asked its version:
//  - every --colmap PATH, in order (a name without a slash is looked up on the PATH);
//  - without --colmap: $TESSERA_COLMAP if set, else kColmap4Anchor where present; then
//    `colmap` on the PATH (Debian's 3.8) where present and another file.
// Throws InputError, one line naming the binary, when one named or found cannot be used:
// missing, not executable, crashing, silent past its timeout, or not COLMAP 3.8 or later.
// Their labels are set with AssignColmapLabels(binaries, {}).
std::vector<ColmapBinary> FindColmapBinaries(const BenchOptions& options);

// Gives each binary a label of its own: "colmap-<version>" made a file name, then "-2",
// "-3", ... where an earlier binary has it or one of its rows' names is in `taken` (the
// Tessera rows' names).
void AssignColmapLabels(std::vector<ColmapBinary>* binaries, const std::vector<std::string>& taken);

// The rows a binary gives, in order: "<label>-global" where it has the global mapper,
// then "<label>-incremental".
std::vector<std::string> ColmapRowNames(const ColmapBinary& colmap);

// OUTPUT/colmap/<label>: its rows' folders, and features/ for its whole pipeline.
std::filesystem::path ColmapFolder(const BenchOptions& options, const ColmapBinary& colmap);

// Every folder a binary's rows may write (for CheckBenchWorkspace before any row runs).
std::vector<std::filesystem::path> ColmapWorkspaces(const BenchOptions& options,
                                                    const ColmapBinary& colmap);

// COLMAP's whole pipeline on the images: feature extraction (CPU, one shared camera or
// one per folder) and exhaustive matching once, then each mapper on its own copy of that
// database; every row carries the shared extraction and matching seconds. A step that
// fails is its rows' error; nothing is thrown.
std::vector<BenchRow> RunColmapPipeline(const BenchOptions& options, const ColmapBinary& colmap,
                                        const BenchGroundTruth* ground_truth);

// COLMAP's mappers alone, each on its own copy of `source`'s database.db (COLMAP 4
// upgrades a database in place; the original stays as it was). Nothing is thrown.
std::vector<BenchRow> RunColmapMappers(const BenchOptions& options, const ColmapBinary& colmap,
                                       const BenchGroundTruth* ground_truth,
                                       const BenchRow& source);

}  // namespace tessera
