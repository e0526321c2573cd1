// A forged or edited ledger (OUTPUT/.tessera_outputs.json) never makes Tessera delete,
// replace or write anything it did not write (issue 46): every entry is checked before
// anything is removed, and a violation names the ledger and the entry.

#include "outputs/output_ledger.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "outputs/output_transaction.h"
#include "tessera/errors.h"
#include "test_support.h"
#include "text_files.h"
#include "util/workspace_layout.h"

namespace tessera {
namespace {

using ::tessera::testing::ReadTextFile;
using ::tessera::testing::WriteTextFile;

namespace fs = std::filesystem;

void CommitFiles(const fs::path& output, const std::map<std::string, std::string>& files,
                 const std::vector<fs::path>& inputs = {}) {
  OutputTransaction outputs(output);
  for (const fs::path& input : inputs) outputs.Protect(input);
  for (const auto& [relative, text] : files)
    WriteTextFile(outputs.StageFor("ply") / relative, text);
  outputs.Commit();
}

// Adds to the ledger of `output` an entry `entry` with the real size and XXH3 of
// `file`, as a forger would; or, with no file, a folder entry.
void Forge(const fs::path& output, const std::string& entry, const fs::path& file = {}) {
  const fs::path ledger = output / OutputLedger::kFileName;
  nlohmann::json json = nlohmann::json::parse(ReadTextFile(ledger));
  if (file.empty()) {
    json["folders"].push_back(entry);
  } else {
    const FileDigest digest = DigestFile(file);
    char hex[17];
    std::snprintf(hex, sizeof(hex), "%016llx", static_cast<unsigned long long>(digest.xxh3));
    json["files"].push_back({{"path", entry}, {"size", digest.size}, {"xxh3", hex}});
  }
  std::ofstream(ledger) << json.dump(1);
}

// The text of the InputError that committing a set into `output` throws; "" when none.
std::string CommitError(const fs::path& output, const std::vector<fs::path>& inputs = {}) {
  try {
    CommitFiles(output, {{"transforms.json", "t"}}, inputs);
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

bool Has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// A workspace whose earlier run placed model.ply, and a victim beside it, outside.
struct Workspace {
  testing::TemporaryDir dir;
  fs::path output = dir.path() / "out";
  fs::path victim = dir.path() / "victim.txt";
  Workspace() {
    WriteTextFile(victim, "precious");
    CommitFiles(output, {{"model.ply", "p"}});
  }
  // Nothing moved: the victim and the earlier output are there, the new set is not.
  void ExpectNothingDone() const {
    EXPECT_EQ(ReadTextFile(victim), "precious");
    EXPECT_EQ(ReadTextFile(output / "model.ply"), "p");
    EXPECT_FALSE(fs::exists(output / "transforms.json"));
  }
};

TEST(ForgedLedger, AnEntryOutsideTheOutputFolderIsRefusedAndNothingIsDeleted) {
  for (const std::string kind : {"../", "absolute", "sparse/0/../../../"}) {
    Workspace workspace;
    const std::string entry = kind == "absolute" ? workspace.victim.string() : kind + "victim.txt";
    Forge(workspace.output, entry, workspace.victim);
    const std::string error = CommitError(workspace.output);
    EXPECT_TRUE(Has(error, (workspace.output / OutputLedger::kFileName).string())) << error;
    EXPECT_TRUE(Has(error, "the entry '" + entry + "'")) << error;
    EXPECT_TRUE(Has(error, kind == "absolute" ? "absolute" : "'..'")) << error;
    EXPECT_TRUE(Has(error, "nothing was removed")) << error;
    workspace.ExpectNothingDone();
  }
}

TEST(ForgedLedger, AnEntryThatIsNotInNormalFormIsRefused) {
  for (const std::string entry : {"./model.ply", "sparse//x", "sparse/", "a\\..\\x", ""}) {
    Workspace workspace;
    WriteTextFile(workspace.output / "sparse/x", "mine");
    Forge(workspace.output, entry, workspace.output / "sparse/x");
    const std::string error = CommitError(workspace.output);
    EXPECT_TRUE(Has(error, OutputLedger::kFileName)) << entry << ": " << error;
    workspace.ExpectNothingDone();
    EXPECT_EQ(ReadTextFile(workspace.output / "sparse/x"), "mine");
  }
}

// A ledger forged to name `entry`, one of the workspace's own files, is refused naming
// it, and the file stays as it was.
void ExpectForgedWorkspaceEntryRefused(const std::string& entry) {
  Workspace workspace;
  WriteTextFile(workspace.output / entry, "workspace");
  Forge(workspace.output, entry, workspace.output / entry);
  const std::string error = CommitError(workspace.output);
  EXPECT_TRUE(Has(error, "the entry '" + entry + "'")) << error;
  EXPECT_TRUE(Has(error, "the workspace's own")) << error;
  workspace.ExpectNothingDone();
  EXPECT_EQ(ReadTextFile(workspace.output / entry), "workspace") << entry;
}

TEST(ForgedLedger, TheWorkspacesOwnFilesAreRefused) {
  for (const std::string entry :
       {"database.db", "database.db-wal", "cache/matcher/x.idx", "shards/extract-0-of-2.db",
        "video_frames/clip/frame_000000_0.000s.jpg", "frames.json", "clusters.json",
        ".tessera.lock", ".tessera_staging/1/x", "plugin_crashes.log"}) {
    ExpectForgedWorkspaceEntryRefused(entry);
  }
}

// Every entry of the workspace layout that is the workspace's own state, so that a new
// one is refused without a word here.
TEST(ForgedLedger, EveryStateEntryOfTheWorkspaceLayoutIsRefused) {
  for (const WorkspaceEntry& layout_entry : WorkspaceEntries()) {
    // The ledger itself is the file the forger writes.
    if (layout_entry.role != WorkspaceEntry::Role::kWorkspaceState ||
        layout_entry.name == workspace_layout::kOutputLedger) {
      continue;
    }
    const std::string entry = std::string(layout_entry.name) +
                              (layout_entry.kind == WorkspaceEntry::Kind::kFolder ? "/x" : "");
    ExpectForgedWorkspaceEntryRefused(entry);
  }
}

TEST(ForgedLedger, AFolderOutsideTheOutputFolderIsRefused) {
  Workspace workspace;
  fs::create_directories(workspace.dir.path() / "empty");
  Forge(workspace.output, "../empty");
  const std::string error = CommitError(workspace.output);
  EXPECT_TRUE(Has(error, "the entry '../empty'")) << error;
  workspace.ExpectNothingDone();
  EXPECT_TRUE(fs::is_directory(workspace.dir.path() / "empty"));
  // An empty workspace folder, too.
  Workspace cache;
  fs::create_directories(cache.output / "cache");
  Forge(cache.output, "cache");
  EXPECT_TRUE(Has(CommitError(cache.output), "the entry 'cache'"));
  EXPECT_TRUE(fs::is_directory(cache.output / "cache"));
}

// The images and the masks lie in OUTPUT: whatever the ledger says of them, they stay,
// and the run says why.
TEST(ForgedLedger, InputsAreNeverRemovedOnTheLedgersWord) {
  Workspace workspace;
  const fs::path images = workspace.output / "photos";
  const fs::path masks = workspace.output / "masks";
  WriteTextFile(images / "a.jpg", "image");
  fs::create_directories(masks);
  Forge(workspace.output, "photos/a.jpg", images / "a.jpg");
  Forge(workspace.output, "photos");
  Forge(workspace.output, "masks");
  OutputTransaction outputs(workspace.output);
  outputs.Protect(images);
  outputs.Protect(masks);
  WriteTextFile(outputs.StageFor("ply") / "transforms.json", "t");
  const OutputTransaction::Result result = outputs.Commit();
  EXPECT_EQ(ReadTextFile(images / "a.jpg"), "image");
  EXPECT_TRUE(fs::is_directory(masks));
  bool named_image = false, named_masks = false;
  for (const std::string& warning : result.warnings) {
    named_image |= Has(warning, (images / "a.jpg").string()) && Has(warning, "input folder");
    named_masks |= Has(warning, masks.string()) && Has(warning, "input folder");
  }
  EXPECT_TRUE(named_image);
  EXPECT_TRUE(named_masks);
  // They are no longer recorded as Tessera's.
  const OutputLedger ledger = OutputLedger::Read(workspace.output);
  EXPECT_FALSE(ledger.HasFile("photos/a.jpg"));
  EXPECT_FALSE(ledger.HasFolder("photos"));
  EXPECT_FALSE(ledger.HasFolder("masks"));
}

// OUTPUT/sparse turned into a link to a copy of Tessera's model: the recorded files,
// reached through it, match their digests, but nothing is removed through a link.
TEST(ForgedLedger, NothingIsRemovedThroughALinkOnTheWay) {
  Workspace workspace;
  CommitFiles(workspace.output, {{"sparse/0/images.bin", "model"}});
  const fs::path elsewhere = workspace.dir.path() / "elsewhere";
  fs::create_directories(elsewhere);
  fs::rename(workspace.output / "sparse", elsewhere / "sparse");
  fs::create_directory_symlink(elsewhere / "sparse", workspace.output / "sparse");
  const std::string error = CommitError(workspace.output);
  EXPECT_TRUE(Has(error, "the entry 'sparse/0/images.bin'")) << error;
  EXPECT_TRUE(Has(error, (workspace.output / "sparse").string() + ", a symbolic link")) << error;
  EXPECT_EQ(ReadTextFile(elsewhere / "sparse/0/images.bin"), "model");
}

// The link made while the run went on (after the transaction began): checked again
// before anything is removed.
TEST(ForgedLedger, ALinkMadeDuringTheRunIsCaughtAtCommit) {
  Workspace workspace;
  CommitFiles(workspace.output, {{"sparse/0/images.bin", "model"}});
  const fs::path elsewhere = workspace.dir.path() / "elsewhere";
  OutputTransaction outputs(workspace.output);
  WriteTextFile(outputs.StageFor("ply") / "transforms.json", "t");
  fs::create_directories(elsewhere);
  fs::rename(workspace.output / "sparse", elsewhere / "sparse");
  fs::create_directory_symlink(elsewhere / "sparse", workspace.output / "sparse");
  EXPECT_THROW(outputs.Commit(), InputError);
  EXPECT_EQ(ReadTextFile(elsewhere / "sparse/0/images.bin"), "model");
  EXPECT_FALSE(fs::exists(workspace.output / "transforms.json"));
}

// A file Tessera wrote and the user edited is called that, not "not in the ledger".
TEST(ForgedLedger, AnEditedOutputIsToldFromAForeignOne) {
  Workspace workspace;
  WriteTextFile(workspace.output / "model.ply", "edited");
  WriteTextFile(workspace.output / "notes.ply", "mine");
  try {
    CommitFiles(workspace.output, {{"model.ply", "q"}});
    FAIL() << "no error";
  } catch (const InputError& error) {
    EXPECT_TRUE(Has(error.what(), "Tessera wrote but that has changed since")) << error.what();
    EXPECT_FALSE(Has(error.what(), "not in")) << error.what();
  }
  try {
    CommitFiles(workspace.output, {{"notes.ply", "q"}});
    FAIL() << "no error";
  } catch (const InputError& error) {
    EXPECT_TRUE(Has(error.what(), "did not write (not in .tessera_outputs.json)")) << error.what();
  }
  EXPECT_EQ(ReadTextFile(workspace.output / "model.ply"), "edited");
  EXPECT_EQ(ReadTextFile(workspace.output / "notes.ply"), "mine");
}

// Tessera never records a path its reader would refuse: an exporter's file named with a
// backslash is refused when the set is placed.
TEST(ForgedLedger, AnExportersPathTheLedgerCouldNotHoldIsRefused) {
  const testing::TemporaryDir dir;
  EXPECT_THROW(CommitFiles(dir.path(), {{"a\\b.ply", "p"}}), InputError);
  EXPECT_FALSE(fs::exists(dir.path() / "a\\b.ply"));
  EXPECT_NO_THROW(OutputLedger::Read(dir.path()));
}

}  // namespace
}  // namespace tessera
