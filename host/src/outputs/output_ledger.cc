#include "outputs/output_ledger.h"

#include <fcntl.h>
#include <unistd.h>
#include <xxhash.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "io/names.h"
#include "tessera/errors.h"
#include "tessera/io/file_io.h"

namespace tessera {
namespace fs = std::filesystem;
namespace {

constexpr int kLedgerVersion = 1;

std::string Hex(uint64_t value) {
  char text[17];
  std::snprintf(text, sizeof(text), "%016llx", static_cast<unsigned long long>(value));
  return text;
}

bool ParseHex(const std::string& text, uint64_t* value) {
  if (text.size() != 16 || text.find_first_not_of("0123456789abcdef") != std::string::npos) {
    return false;
  }
  *value = std::stoull(text, nullptr, 16);
  return true;
}

// Why `path`, an entry of the ledger, is not one Tessera writes; empty when it is.
std::string EntryProblem(const std::string& path) {
  if (std::string problem = RelativePathProblem(path); !problem.empty()) return problem;
  const std::string top = path.substr(0, path.find('/'));
  if (IsWorkspaceFile(top)) {
    return (top == path ? "is the workspace's own " + top
                        : "lies in the workspace's own " + top + "/") +
           ", which Tessera never records as an output";
  }
  return "";
}

}  // namespace

std::vector<std::string> ForeignModelFolderWarnings(const fs::path& output_folder,
                                                    const OutputLedger& ledger) {
  std::vector<std::string> warnings;
  std::error_code error;
  const fs::path models = output_folder / workspace_layout::kModelsFolder;
  for (const fs::directory_entry& entry : fs::directory_iterator(models, error)) {
    const std::string relative =
        std::string(workspace_layout::kModelsFolder) + "/" + entry.path().filename().string();
    if (!ledger.HasFolder(relative)) {
      warnings.push_back(entry.path().string() + " was not written by Tessera; readers of " +
                         models.string() + " will take it for a model");
    }
  }
  return warnings;
}

FileDigest DigestFile(const fs::path& path) {
  const int fd = open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) {
    throw InputError(path.string() + ": cannot read it to check it: " + std::strerror(errno));
  }
  std::unique_ptr<XXH3_state_t, decltype(&XXH3_freeState)> state(XXH3_createState(),
                                                                 &XXH3_freeState);
  XXH3_64bits_reset(state.get());
  FileDigest digest;
  std::vector<char> buffer(1 << 20);
  while (true) {
    const ssize_t count = read(fd, buffer.data(), buffer.size());
    if (count < 0 && errno == EINTR) continue;
    if (count < 0) {
      const int error = errno;
      close(fd);
      throw InputError(path.string() + ": cannot read it to check it: " + std::strerror(error));
    }
    if (count == 0) break;
    XXH3_64bits_update(state.get(), buffer.data(), static_cast<size_t>(count));
    digest.size += static_cast<uint64_t>(count);
  }
  close(fd);
  digest.xxh3 = XXH3_64bits_digest(state.get());
  return digest;
}

OutputLedger OutputLedger::Read(const fs::path& output_folder) {
  OutputLedger ledger;
  const fs::path file = output_folder / kFileName;
  std::error_code error;
  const fs::file_status status = fs::symlink_status(file, error);
  if (status.type() == fs::file_type::not_found) return ledger;
  const auto fail = [&](const std::string& why) {
    throw InputError(file.string() + ": " + why +
                     "; it records what Tessera wrote here: move it away only together with "
                     "those outputs");
  };
  if (status.type() != fs::file_type::regular) fail("is not a regular file");
  // An entry Tessera never writes: the ledger was edited, and nothing it names is acted on.
  const auto check_entry = [&](const std::string& path) {
    if (const std::string problem = EntryProblem(path); !problem.empty()) {
      throw InputError(file.string() + ": the entry '" + EscapeControlCharacters(path) + "' " +
                       problem + "; Tessera writes no such entry, so nothing was removed: " +
                       "delete the entry (or the whole ledger: then nothing here counts as "
                       "Tessera's)");
    }
  };
  std::ifstream stream(file);
  nlohmann::json json;
  try {
    json = nlohmann::json::parse(stream);
    if (json.at("version").get<int>() != kLedgerVersion) fail("has an unknown version");
    for (const nlohmann::json& entry : json.at("files")) {
      FileDigest digest;
      digest.size = entry.at("size").get<uint64_t>();
      const std::string path = entry.at("path").get<std::string>();
      if (!ParseHex(entry.at("xxh3").get<std::string>(), &digest.xxh3) || path.empty()) {
        fail("has a malformed file entry");
      }
      check_entry(path);
      ledger.AddFile(path, digest);
    }
    for (const nlohmann::json& folder : json.at("folders")) {
      check_entry(folder.get<std::string>());
      ledger.AddFolder(folder.get<std::string>());
    }
  } catch (const nlohmann::json::exception& exception) {
    fail(std::string("is not a ledger of outputs (") + exception.what() + ")");
  }
  return ledger;
}

void OutputLedger::Write(const fs::path& output_folder) const {
  nlohmann::json files = nlohmann::json::array();
  for (const auto& [path, digests] : files_) {
    for (const FileDigest& digest : digests) {
      files.push_back({{"path", path}, {"size", digest.size}, {"xxh3", Hex(digest.xxh3)}});
    }
  }
  const nlohmann::json json = {{"version", kLedgerVersion},
                               {"written_by", "tessera"},
                               {"files", files},
                               {"folders", folders_}};
  WriteFileAtomically(output_folder / kFileName, json.dump(1) + "\n");
}

void OutputLedger::AddFile(const std::string& relative, const FileDigest& digest) {
  std::vector<FileDigest>& digests = files_[relative];
  if (std::find(digests.begin(), digests.end(), digest) == digests.end()) {
    digests.push_back(digest);
  }
}

bool OutputLedger::Owns(const fs::path& output_folder, const fs::path& relative) const {
  const fs::path path = output_folder / relative;
  const std::string key = relative.generic_string();
  std::error_code error;
  const fs::file_status status = fs::symlink_status(path, error);
  if (status.type() == fs::file_type::regular) {
    const auto found = files_.find(key);
    if (found == files_.end()) return false;
    const uint64_t size = fs::file_size(path, error);
    if (error) return false;
    const bool size_matches = std::any_of(found->second.begin(), found->second.end(),
                                          [&](const FileDigest& d) { return d.size == size; });
    if (!size_matches) return false;
    try {
      const FileDigest digest = DigestFile(path);
      return std::find(found->second.begin(), found->second.end(), digest) != found->second.end();
    } catch (const InputError&) {
      return false;
    }
  }
  if (status.type() != fs::file_type::directory || folders_.count(key) == 0) return false;
  for (const fs::directory_entry& entry : fs::directory_iterator(path, error)) {
    if (!Owns(output_folder, relative / entry.path().filename())) return false;
  }
  return !error;
}

}  // namespace tessera
