#pragma once

// Writes one set of outputs (a run's models, their exports, the mapping summary) into an
// output folder whole, or not at all.
//
// Each writer (an exporter, or the host) writes into a staging folder of its own as if
// it were the output folder: OUTPUT/.tessera_staging/<pid>/<writer>. Commit() then:
//   1. merges the writers' folders, refusing two writers of one file;
//   2. plans every placement, refusing before anything moves an entry that would
//      replace what Tessera did not write (OutputLedger), a workspace file (database.db,
//      the lock, caches, shards) or anything reached through a symbolic link;
//   3. records the new files in the ledger beside the old ones, so that a kill from
//      here on leaves only files that count as Tessera's;
//   4. places each new entry with one rename: a new path is renamed into place, one of
//      Tessera's is swapped with its replacement (renameat2 RENAME_EXCHANGE), so that a
//      reader sees the old model or the new one, never a mix;
//   5. removes what Tessera wrote before and the set no longer holds (never a file it
//      did not write, never through a link) and records the set alone (Mode).
// The caller holds the output folder (the workspace lock). What an earlier process left
// in the staging folder, and the temporaries of its atomic writes at the top of OUTPUT
// (Tessera's token only: io/temporary_names.h), are removed when a transaction begins.

#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "outputs/output_ledger.h"
#include "util/workspace_layout.h"

namespace tessera {

class OutputTransaction {
 public:
  static constexpr const char* kStagingFolderName = workspace_layout::kStagingFolder;

  struct Result {
    size_t files_placed = 0;
    size_t files_removed = 0;  // Tessera's earlier outputs that the set no longer holds
    // Entries Tessera did not write that a reader would take for its outputs (a model
    // folder in sparse/, images.bin beside images.txt), and earlier outputs left
    // because they were changed since; each is logged as a warning too.
    std::vector<std::string> warnings;
    // What each writer placed, as the paths a user opens: OUTPUT/transforms.json,
    // OUTPUT/gaussian_splatting, OUTPUT/sparse/0 (a model folder in sparse/).
    std::map<std::string, std::set<std::string>> entries_by_writer;
  };

  enum class Mode {
    // The set is all of Tessera's outputs in the folder (map, run): each of Tessera's
    // folders the set writes is replaced whole, and what it no longer holds is removed.
    kWholeSet,
    // The set is added to Tessera's outputs (export): what it writes at the top of the
    // folder, and each model folder in sparse/, is replaced whole; nothing else is
    // removed.
    kAddToSet,
  };

  // Removes what an earlier process left in OUTPUT/.tessera_staging, and leftover
  // temporaries of atomic writes in OUTPUT: .NAME.tessera-tmp-PID-RANDOM of a process
  // that is gone, NAME a file of the workspace layout (util/workspace_layout.h). No
  // other name, and nothing in the folders a ledger names. Throws InputError naming the
  // path when the staging folder is a link or not a folder.
  explicit OutputTransaction(std::filesystem::path output_folder, Mode mode = Mode::kWholeSet);
  // Without Commit: the staging folder is removed, unless Keep() was called.
  ~OutputTransaction();
  OutputTransaction(const OutputTransaction&) = delete;
  OutputTransaction& operator=(const OutputTransaction&) = delete;

  // The folder writer `slot` (an exporter's place in the manifest's list) writes in as
  // if it were the output folder: created the first time, the same folder for every
  // later call with the same slot. `writer` names it in errors ("colmap_binary"); the
  // host's own files (the mapping summary) are writer "tessera", placed last, so that
  // the summary never describes outputs that are not yet in place.
  std::filesystem::path StageFor(const std::string& writer, size_t slot = 0);

  // `text` (a writer's error) with each staging folder named as the output folder, as
  // the user knows it: OUTPUT/.tessera_staging/PID/writer-0/gaussian_splatting reads
  // OUTPUT/gaussian_splatting.
  std::string NamedAsOutput(const std::string& text) const;

  // Places the set (steps 1 to 5). Throws InputError naming the path and the writer
  // when the set cannot be placed; nothing has moved then and the staging folder is
  // kept.
  Result Commit();

  // A folder nothing is placed in or removed from, nor any folder holding it, even when
  // Tessera wrote it (the image folder, the mask folder).
  void Protect(const std::filesystem::path& folder);

  // Keeps the staging folder when the set is abandoned (a writer failed), so that what
  // it holds can be read until the next transaction in this output folder.
  void Keep() { keep_ = true; }
  const std::filesystem::path& staging_folder() const { return staging_; }

 private:
  struct Placement {
    std::string relative;
    bool swap = false;  // replaces Tessera's entry; else a new path
  };

  void MergeWriters(const std::filesystem::path& set);
  void Plan(const std::filesystem::path& set, const std::filesystem::path& relative,
            std::vector<Placement>* placements, std::vector<std::string>* refusals) const;
  void Place(const std::filesystem::path& set, const Placement& placement) const;
  size_t RemoveStale(const OutputLedger& previous, const OutputLedger& placed,
                     std::vector<std::string>* warnings) const;
  std::vector<std::string> ShadowWarnings(const OutputLedger& placed) const;
  std::string WriterOf(const std::string& relative) const;
  // Throws InputError naming the ledger and the entry when an entry of the ledger lies
  // through a symbolic link (LinkOnTheWay): checked before anything is removed.
  void CheckNoLinkOnTheWay() const;
  // Why OUTPUT/relative, which the set would replace, is not Tessera's: a phrase after
  // "is a file" (not in the ledger; in it, but changed since; ...).
  std::string NotTesserasBecause(const std::string& relative) const;
  // The protected folder that OUTPUT/relative is, holds or lies in; empty when none.
  std::string ProtectedAt(const std::string& relative) const;

  std::filesystem::path output_;
  Mode mode_;
  std::filesystem::path staging_;
  struct Writer {
    std::string name;
    size_t slot = 0;
    std::filesystem::path folder;
  };
  std::vector<Writer> writers_;
  std::map<std::string, std::string> writer_of_file_;  // relative: writer
  OutputLedger ledger_;
  std::vector<std::filesystem::path> protected_;  // absolute, lexically normal
  bool committed_ = false;
  bool keep_ = false;
};

}  // namespace tessera
