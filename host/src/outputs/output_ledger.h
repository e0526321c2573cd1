#pragma once

// What Tessera wrote in an output folder, so that a rerun replaces or removes only
// that: OUTPUT/.tessera_outputs.json lists every file Tessera placed there (its path
// relative to OUTPUT, size and XXH3 digest) and every folder it created. A file counts
// as Tessera's while it still has a recorded digest; a folder while it is recorded and
// everything in it is Tessera's. Nothing reached through a symbolic link is ever
// Tessera's: Tessera writes none.

#include <cstdint>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "util/workspace_layout.h"  // IsWorkspaceFile: what no ledger names

namespace tessera {

struct FileDigest {
  uint64_t size = 0;
  uint64_t xxh3 = 0;
  bool operator==(const FileDigest& other) const {
    return size == other.size && xxh3 == other.xxh3;
  }
};

// The digest of the regular file `path` (not followed when a link). Throws InputError
// naming the file when it cannot be read.
FileDigest DigestFile(const std::filesystem::path& path);

class OutputLedger {
 public:
  static constexpr const char* kFileName = workspace_layout::kOutputLedger;

  // The ledger of `output_folder`; empty when it has none. Throws InputError naming the
  // file when it is unreadable or not a ledger, and naming the file and the entry when an
  // entry is not one Tessera writes: a path that is not relative and lexically normal
  // (RelativePathProblem: absolute, '..', ...), or one in or of a workspace file
  // (IsWorkspaceFile: database.db, cache/, the ledger itself, ...). Nothing a ledger
  // names is acted on before the whole of it has passed.
  static OutputLedger Read(const std::filesystem::path& output_folder);
  // Writes it atomically (a new file renamed over the old; no link followed).
  void Write(const std::filesystem::path& output_folder) const;

  // Whether OUTPUT/relative is, whole, what Tessera wrote there: a regular file with a
  // recorded digest, or a recorded folder (not a link) holding only such entries.
  bool Owns(const std::filesystem::path& output_folder,
            const std::filesystem::path& relative) const;

  // `digest` is accepted for `relative` (besides any accepted already: while a commit
  // is under way both the old and the new file are Tessera's).
  void AddFile(const std::string& relative, const FileDigest& digest);
  void AddFolder(const std::string& relative) { folders_.insert(relative); }
  void ForgetFile(const std::string& relative) { files_.erase(relative); }
  void ForgetFolder(const std::string& relative) { folders_.erase(relative); }

  const std::map<std::string, std::vector<FileDigest>>& files() const { return files_; }
  const std::set<std::string>& folders() const { return folders_; }
  bool HasFile(const std::string& relative) const { return files_.count(relative) != 0; }
  bool HasFolder(const std::string& relative) const { return folders_.count(relative) != 0; }

 private:
  std::map<std::string, std::vector<FileDigest>> files_;  // relative path: accepted digests
  std::set<std::string> folders_;                         // relative paths
};

// One warning for each entry of OUTPUT/sparse (workspace_layout::kModelsFolder) that `ledger` does
// not record as a folder Tessera made: readers of OUTPUT/sparse take it for one of the models.
std::vector<std::string> ForeignModelFolderWarnings(const std::filesystem::path& output_folder,
                                                    const OutputLedger& ledger);

}  // namespace tessera
