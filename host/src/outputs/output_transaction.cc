#include "outputs/output_transaction.h"

#include <fcntl.h>
#include <signal.h>
#include <spdlog/spdlog.h>
#include <stdio.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <iterator>
#include <optional>
#include <set>

#include "io/names.h"
#include "io/temporary_names.h"
#include "tessera/errors.h"
#include "util/workspace_layout.h"

namespace tessera {
namespace fs = std::filesystem;
namespace {

fs::file_type TypeOf(const fs::path& path) {
  std::error_code error;
  return fs::symlink_status(path, error).type();
}

std::string Describe(fs::file_type type) {
  switch (type) {
    case fs::file_type::symlink:
      return "a symbolic link";
    case fs::file_type::directory:
      return "a folder";
    case fs::file_type::regular:
      return "a file";
    default:
      return "a special file";
  }
}

// Every regular file below `root` (relative to it, generic form), and every folder.
// Throws InputError when the writer left a link or a special file.
void ListTree(const fs::path& root, const std::string& writer, std::vector<std::string>* files,
              std::vector<std::string>* folders) {
  std::error_code error;
  for (auto it = fs::recursive_directory_iterator(root, error);
       !error && it != fs::recursive_directory_iterator(); it.increment(error)) {
    const std::string relative = fs::relative(it->path(), root).generic_string();
    const fs::file_type type = it->symlink_status().type();
    // Recorded in the ledger, which refuses what Tessera never writes when read back.
    if (const std::string problem = RelativePathProblem(relative); !problem.empty()) {
      throw InputError("exporter '" + writer + "' wrote '" + EscapeControlCharacters(relative) +
                       "': the path " + problem + "; give it another file or folder");
    }
    if (type == fs::file_type::directory) {
      folders->push_back(relative);
    } else if (type == fs::file_type::regular) {
      files->push_back(relative);
    } else {
      throw InputError("exporter '" + writer + "' wrote " + relative + " as " + Describe(type) +
                       "; outputs must be files and folders");
    }
  }
  if (error) throw InputError(root.string() + ": cannot list it: " + error.message());
}

// Renames `from` to `to`; `to` must not exist.
void RenameNew(const fs::path& from, const fs::path& to) {
  if (renameat2(AT_FDCWD, from.c_str(), AT_FDCWD, to.c_str(), RENAME_NOREPLACE) == 0) return;
  if (errno == EINVAL || errno == ENOSYS) {  // a file system without renameat2 flags
    if (TypeOf(to) == fs::file_type::not_found && rename(from.c_str(), to.c_str()) == 0) return;
  }
  throw InputError(to.string() + ": cannot put the new output in place: " + std::strerror(errno));
}

// Swaps `from` and `to` with one rename; the old `to` ends up at `from`.
void RenameSwap(const fs::path& from, const fs::path& to) {
  if (renameat2(AT_FDCWD, from.c_str(), AT_FDCWD, to.c_str(), RENAME_EXCHANGE) == 0) return;
  if (errno == EINVAL || errno == ENOSYS) {  // no exchange: the old one aside, then the new
    const fs::path aside = from.string() + ".old";
    if (rename(to.c_str(), aside.c_str()) == 0 && rename(from.c_str(), to.c_str()) == 0) return;
  }
  throw InputError(to.string() +
                   ": cannot replace it with the new output: " + std::strerror(errno));
}

// OUTPUT/.NAME.tessera-tmp-PID-RANDOM (io/temporary_names.h), the temporary of an
// atomic write of NAME that its process left when it ended: only Tessera's token, only
// for a NAME the workspace layout records at the top of a workspace (the ledger, the
// crash records, clusters.json, frames.json: the files Tessera writes there in place;
// the outputs are written in the staging folder), and only of a process that is gone.
// Nothing else is taken for a leftover: a user's ".notes.tmp-999999" is theirs.
bool IsLeftoverTemporary(const std::string& name) {
  const std::optional<TemporaryFileName> parsed = ParseTemporaryFileName(name);
  if (!parsed || !IsWorkspaceFile(parsed->target)) return false;
  const pid_t process = static_cast<pid_t>(parsed->pid);
  return process != getpid() && kill(process, 0) != 0 && errno == ESRCH;
}

void RemoveLeftoverTemporaries(const fs::path& folder) {
  if (TypeOf(folder) != fs::file_type::directory) return;
  std::error_code error;
  for (const fs::directory_entry& entry : fs::directory_iterator(folder, error)) {
    const std::string name = entry.path().filename().string();
    if (entry.symlink_status().type() == fs::file_type::regular && IsLeftoverTemporary(name)) {
      spdlog::info("removing {}, left by an interrupted write", entry.path().string());
      fs::remove(entry.path(), error);
    }
  }
}

}  // namespace

OutputTransaction::OutputTransaction(fs::path output_folder, Mode mode)
    : output_(std::move(output_folder)), mode_(mode), ledger_(OutputLedger::Read(output_)) {
  CheckNoLinkOnTheWay();
  const fs::path root = output_ / kStagingFolderName;
  const fs::file_type type = TypeOf(root);
  if (type != fs::file_type::not_found && type != fs::file_type::directory) {
    throw InputError(root.string() + " is " + Describe(type) +
                     ", not the staging folder Tessera makes; move it away");
  }
  std::error_code error;
  if (type == fs::file_type::directory) {
    for (const fs::directory_entry& entry : fs::directory_iterator(root, error)) {
      spdlog::info("removing {}, the unfinished outputs of an earlier run", entry.path().string());
      fs::remove_all(entry.path(), error);
    }
  }
  // At the top only: the folders a ledger names may be the user's (a ledger can be
  // edited), and Tessera writes nothing in them but by renames from the staging folder.
  RemoveLeftoverTemporaries(output_);
  staging_ = root / std::to_string(static_cast<long>(getpid()));
  fs::create_directories(staging_, error);
  if (error) {
    throw InputError(staging_.string() + ": cannot create the staging folder: " + error.message());
  }
}

OutputTransaction::~OutputTransaction() {
  if (keep_ && !committed_) return;
  std::error_code error;
  fs::remove_all(staging_, error);
  fs::remove(staging_.parent_path(), error);  // only when empty
}

fs::path OutputTransaction::StageFor(const std::string& writer, size_t slot) {
  for (const Writer& known : writers_) {
    if (known.name == writer && known.slot == slot) return known.folder;
  }
  const fs::path folder = staging_ / ("writer-" + std::to_string(writers_.size()));
  std::error_code error;
  fs::create_directories(folder, error);
  if (error) throw InputError(folder.string() + ": cannot create it: " + error.message());
  writers_.push_back({writer, slot, folder});
  return folder;
}

void OutputTransaction::CheckNoLinkOnTheWay() const {
  const auto check = [&](const std::string& relative) {
    const fs::path link = LinkOnTheWay(output_, relative);
    if (link.empty()) return;
    throw InputError((output_ / OutputLedger::kFileName).string() + ": the entry '" + relative +
                     "' lies through " + link.string() +
                     ", a symbolic link; Tessera makes none and removes or replaces nothing "
                     "through one, so nothing was: replace the link with a folder, or move it "
                     "away");
  };
  for (const auto& [relative, digests] : ledger_.files()) check(relative);
  for (const std::string& relative : ledger_.folders()) check(relative);
}

void OutputTransaction::Protect(const fs::path& folder) {
  if (folder.empty()) return;
  std::error_code error;
  const fs::path absolute = fs::weakly_canonical(fs::absolute(folder), error);
  if (!error) protected_.push_back(absolute.lexically_normal());
}

std::string OutputTransaction::ProtectedAt(const std::string& relative) const {
  std::error_code error;
  const fs::path target = fs::weakly_canonical(fs::absolute(output_ / relative), error);
  if (error) return "";
  const auto within = [](const fs::path& inner, const fs::path& outer) {
    const fs::path rest = inner.lexically_relative(outer);
    return !rest.empty() && *rest.begin() != "..";
  };
  const fs::path output = fs::weakly_canonical(fs::absolute(output_), error);
  for (const fs::path& folder : protected_) {
    // Replacing or removing `target` would take the folder with it; writing below the
    // folder writes among the inputs, unless the whole output folder lies there (an
    // output inside the image folder, which the scan leaves out).
    if (within(folder, target) || (within(target, folder) && within(folder, output))) {
      return folder.string();
    }
  }
  return "";
}

std::string OutputTransaction::NamedAsOutput(const std::string& text) const {
  std::string named = text;
  for (const Writer& writer : writers_) {
    const std::string staged = writer.folder.string();
    for (size_t at = named.find(staged); at != std::string::npos;
         at = named.find(staged, at + output_.string().size())) {
      named.replace(at, staged.size(), output_.string());
    }
  }
  return named;
}

std::string OutputTransaction::WriterOf(const std::string& relative) const {
  const auto found = writer_of_file_.find(relative);
  if (found != writer_of_file_.end()) return found->second;
  // A folder: the writer of any file below it.
  const auto below = writer_of_file_.lower_bound(relative + "/");
  if (below != writer_of_file_.end() && below->first.rfind(relative + "/", 0) == 0) {
    return below->second;
  }
  return "?";
}

void OutputTransaction::MergeWriters(const fs::path& set) {
  std::map<std::string, std::string> folder_writer;
  for (const auto& [writer, slot, folder] : writers_) {
    std::vector<std::string> files, folders;
    ListTree(folder, writer, &files, &folders);
    for (const std::string& relative : folders) {
      if (writer_of_file_.count(relative) != 0) {
        throw InputError("exporters '" + writer_of_file_[relative] + "' and '" + writer +
                         "' both write " + relative + " (a file for one, a folder for the other)");
      }
      folder_writer.emplace(relative, writer);
    }
    for (const std::string& relative : files) {
      const auto other = writer_of_file_.find(relative);
      if (other != writer_of_file_.end() || folder_writer.count(relative) != 0) {
        const std::string first =
            other != writer_of_file_.end() ? other->second : folder_writer[relative];
        throw InputError("exporters '" + first + "' and '" + writer + "' both write " + relative +
                         "; give one of them another file or folder option");
      }
      writer_of_file_[relative] = writer;
    }
    std::error_code error;
    for (const std::string& relative : folders) fs::create_directories(set / relative, error);
    for (const std::string& relative : files) {
      fs::rename(folder / relative, set / relative, error);
      if (error) throw InputError((set / relative).string() + ": " + error.message());
    }
  }
}

void OutputTransaction::Plan(const fs::path& set, const fs::path& relative,
                             std::vector<Placement>* placements,
                             std::vector<std::string>* refusals) const {
  std::error_code error;
  std::vector<fs::path> children;
  for (const fs::directory_entry& entry : fs::directory_iterator(set / relative, error)) {
    children.push_back(relative / entry.path().filename());
  }
  std::sort(children.begin(), children.end());
  for (const fs::path& child : children) {
    const std::string key = child.generic_string();
    const fs::path target = output_ / child;
    const fs::file_type type = TypeOf(target);
    if (relative.empty() && IsWorkspaceFile(key)) {
      refusals->push_back("exporter '" + WriterOf(key) + "' writes " + target.string() +
                          ", a file of the workspace itself; give it another file or folder");
    } else if (relative.empty() && IsHostSummaryFile(key) && WriterOf(key) != "tessera") {
      refusals->push_back("exporter '" + WriterOf(key) + "' writes " + target.string() +
                          ", the summary Tessera writes there; give it another file or folder");
    } else if (const std::string held = ProtectedAt(key); !held.empty()) {
      refusals->push_back("exporter '" + WriterOf(key) + "' writes " + target.string() +
                          ", which is, holds or lies in the input folder " + held +
                          "; give it another file or folder");
    } else if (type == fs::file_type::not_found) {
      placements->push_back({key, false});
    } else if (!(mode_ == Mode::kAddToSet && key == workspace_layout::kModelsFolder) &&
               ledger_.Owns(output_, child)) {
      placements->push_back({key, true});
    } else if (type == fs::file_type::directory &&
               TypeOf(set / child) == fs::file_type::directory) {
      Plan(set, child, placements, refusals);  // a folder shared with others: place inside
    } else {
      refusals->push_back(target.string() + " is " + Describe(type) + NotTesserasBecause(key) +
                          ", and exporter '" + WriterOf(key) +
                          "' would replace it; move it away or choose another output folder");
    }
  }
}

std::string OutputTransaction::NotTesserasBecause(const std::string& relative) const {
  const std::string ledger = OutputLedger::kFileName;
  const fs::file_type type = TypeOf(output_ / relative);
  if (type == fs::file_type::regular && ledger_.HasFile(relative)) {
    return " that Tessera wrote but that has changed since (its size or XXH3 is not the one "
           "in " +
           ledger + ")";
  }
  if (type == fs::file_type::directory && ledger_.HasFolder(relative)) {
    return " that Tessera made, but that now holds entries it did not write or that "
           "changed since (see " +
           ledger + ")";
  }
  return " that Tessera did not write (not in " + ledger + ")";
}

void OutputTransaction::Place(const fs::path& set, const Placement& placement) const {
  const fs::path from = set / placement.relative;
  const fs::path to = output_ / placement.relative;
  if (placement.swap) {
    RenameSwap(from, to);
  } else {
    RenameNew(from, to);
  }
}

OutputTransaction::Result OutputTransaction::Commit() {
  Result result;
  const fs::path set = staging_ / "set";
  std::error_code error;
  fs::create_directories(set, error);
  if (error) throw InputError(set.string() + ": cannot create it: " + error.message());
  try {
    MergeWriters(set);
  } catch (...) {
    keep_ = true;
    throw;
  }
  // The ledger's entries again, as they lie now: nothing is removed or replaced through a
  // link made while the run went on.
  try {
    CheckNoLinkOnTheWay();
  } catch (...) {
    keep_ = true;
    throw;
  }
  std::vector<Placement> placements;
  std::vector<std::string> refusals;
  Plan(set, "", &placements, &refusals);
  if (!refusals.empty()) {
    keep_ = true;
    throw InputError(
        refusals.front() +
        (refusals.size() > 1 ? " (and " + std::to_string(refusals.size() - 1) + " more)" : "") +
        "; nothing was replaced, and this run's outputs are kept in " + staging_.string() +
        " until the next run");
  }
  // The new set, digested where it lies; then recorded beside the old before it moves.
  OutputLedger placed;
  std::vector<std::string> files, folders;
  ListTree(set, "tessera", &files, &folders);
  for (const std::string& relative : files) placed.AddFile(relative, DigestFile(set / relative));
  for (const std::string& relative : folders) placed.AddFolder(relative);
  const OutputLedger previous = ledger_;
  for (const auto& [relative, digests] : placed.files()) ledger_.AddFile(relative, digests[0]);
  for (const std::string& relative : placed.folders()) ledger_.AddFolder(relative);
  ledger_.Write(output_);

  // The host's files (the summary) last: it describes the outputs once they are there.
  std::stable_partition(placements.begin(), placements.end(), [&](const Placement& placement) {
    return WriterOf(placement.relative) != "tessera";
  });
  for (const Placement& placement : placements) Place(set, placement);
  result.files_placed = files.size();
  for (const auto& [relative, writer] : writer_of_file_) {
    const fs::path path(relative);
    auto part = path.begin();
    fs::path entry = *part;
    if (entry == workspace_layout::kModelsFolder && ++part != path.end() &&
        std::next(part) != path.end())
      entry /= *part;
    result.entries_by_writer[writer].insert((output_ / entry).string());
  }
  OutputLedger final_ledger = placed;
  if (mode_ == Mode::kWholeSet) {
    result.files_removed = RemoveStale(previous, placed, &result.warnings);
  } else {  // the earlier files that remain as they were stay Tessera's
    for (const auto& [relative, digests] : previous.files()) {
      if (!placed.HasFile(relative) && ProtectedAt(relative).empty() &&
          previous.Owns(output_, relative)) {
        for (const FileDigest& digest : digests) final_ledger.AddFile(relative, digest);
      }
    }
  }
  // The ledger now holds the set, and the earlier folders that remain.
  for (const std::string& folder : previous.folders()) {
    if (TypeOf(output_ / folder) == fs::file_type::directory && ProtectedAt(folder).empty()) {
      final_ledger.AddFolder(folder);
    }
  }
  final_ledger.Write(output_);
  ledger_ = final_ledger;
  committed_ = true;
  for (const std::string& warning : ShadowWarnings(placed)) result.warnings.push_back(warning);
  for (const std::string& warning : result.warnings) spdlog::warn("{}", warning);
  return result;
}

size_t OutputTransaction::RemoveStale(const OutputLedger& previous, const OutputLedger& placed,
                                      std::vector<std::string>* warnings) const {
  size_t removed = 0;
  std::error_code error;
  const auto left_as_input = [&](const std::string& relative, const std::string& input) {
    warnings->push_back((output_ / relative).string() +
                        " is left as it is: " + OutputLedger::kFileName +
                        " records it as Tessera's, but it is, holds or lies in the input folder " +
                        input + ", and Tessera never removes its inputs");
  };
  for (const auto& [relative, digests] : previous.files()) {
    if (placed.HasFile(relative) || TypeOf(output_ / relative) == fs::file_type::not_found) {
      continue;
    }
    if (const std::string input = ProtectedAt(relative); !input.empty()) {
      left_as_input(relative, input);
    } else if (previous.Owns(output_, relative)) {
      if (fs::remove(output_ / relative, error)) ++removed;
    } else {
      warnings->push_back((output_ / relative).string() +
                          " is left as it is: Tessera wrote it in an earlier run, but it has "
                          "changed since, and this run's outputs no longer hold it");
    }
  }
  // Folders Tessera created and the set no longer holds, deepest first, when empty.
  const std::set<std::string>& folders = previous.folders();
  for (auto it = folders.rbegin(); it != folders.rend(); ++it) {
    if (placed.HasFolder(*it) || TypeOf(output_ / *it) != fs::file_type::directory) continue;
    if (const std::string input = ProtectedAt(*it); !input.empty()) {
      if (fs::is_empty(output_ / *it, error)) left_as_input(*it, input);
    } else if (fs::is_empty(output_ / *it, error)) {
      fs::remove(output_ / *it, error);
    }
  }
  return removed;
}

std::vector<std::string> OutputTransaction::ShadowWarnings(const OutputLedger& placed) const {
  std::vector<std::string> warnings;
  std::error_code error;
  // A model folder in sparse/ that is not Tessera's is read as one of its models.
  if (placed.HasFolder(workspace_layout::kModelsFolder) ||
      TypeOf(output_ / workspace_layout::kModelsFolder) == fs::file_type::directory) {
    warnings = ForeignModelFolderWarnings(output_, ledger_);
  }
  // images.bin beside a new images.txt (or the reverse): readers take the .bin first.
  for (const auto& [relative, digests] : placed.files()) {
    const fs::path path(relative);
    const std::string stem = path.stem().string();
    if (stem != "cameras" && stem != "images" && stem != "points3D") continue;
    for (const char* other : {".bin", ".txt"}) {
      const fs::path sibling = path.parent_path() / (stem + other);
      if (sibling != path && !ledger_.HasFile(sibling.generic_string()) &&
          TypeOf(output_ / sibling) != fs::file_type::not_found) {
        warnings.push_back((output_ / sibling).string() +
                           " was not written by Tessera; readers of the model may read it in "
                           "place of " +
                           (output_ / path).string());
      }
    }
  }
  return warnings;
}

}  // namespace tessera
