#include "outputs/output_transaction.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <map>
#include <sstream>

#include "tessera/errors.h"
#include "test_support.h"
#include "text_files.h"

namespace tessera {
namespace {

using ::tessera::testing::ReadTextFile;
using ::tessera::testing::WriteTextFile;

namespace fs = std::filesystem;

// One committed set: writer name to {relative path: contents}.
OutputTransaction::Result CommitSet(
    const fs::path& output, const std::map<std::string, std::map<std::string, std::string>>& set,
    OutputTransaction::Mode mode = OutputTransaction::Mode::kWholeSet) {
  OutputTransaction outputs(output, mode);
  for (const auto& [writer, files] : set) {
    const fs::path staged = outputs.StageFor(writer);
    for (const auto& [relative, text] : files) WriteTextFile(staged / relative, text);
  }
  return outputs.Commit();
}

bool Mentions(const std::vector<std::string>& lines, const std::string& text) {
  for (const std::string& line : lines) {
    if (line.find(text) != std::string::npos) return true;
  }
  return false;
}

TEST(OutputTransaction, PlacesTheSetAndRecordsIt) {
  const testing::TemporaryDir dir;
  const auto result = CommitSet(dir.path(), {{"colmap_binary", {{"sparse/0/images.bin", "a"}}},
                                             {"ply", {{"model.ply", "p"}}}});
  EXPECT_EQ(result.files_placed, 2u);
  EXPECT_EQ(ReadTextFile(dir.path() / "sparse/0/images.bin"), "a");
  EXPECT_EQ(ReadTextFile(dir.path() / "model.ply"), "p");
  const OutputLedger ledger = OutputLedger::Read(dir.path());
  EXPECT_TRUE(ledger.Owns(dir.path(), "sparse"));
  EXPECT_TRUE(ledger.Owns(dir.path(), "model.ply"));
  EXPECT_FALSE(fs::exists(dir.path() / OutputTransaction::kStagingFolderName));
}

// Two models, binary and a PLY; then one model, text, no PLY: nothing of the first set
// is left to be read in place of the second.
TEST(OutputTransaction, ARerunRemovesWhatItsSetNoLongerHolds) {
  const testing::TemporaryDir dir;
  CommitSet(dir.path(),
            {{"colmap_binary", {{"sparse/0/images.bin", "0"}, {"sparse/1/images.bin", "1"}}},
             {"ply", {{"model.ply", "p"}}},
             {"transforms_json", {{"transforms_1.json", "t"}}}});
  const auto result = CommitSet(dir.path(), {{"colmap_text", {{"sparse/0/images.txt", "text"}}}});
  EXPECT_EQ(ReadTextFile(dir.path() / "sparse/0/images.txt"), "text");
  EXPECT_FALSE(fs::exists(dir.path() / "sparse/0/images.bin"));
  EXPECT_FALSE(fs::exists(dir.path() / "sparse/1"));
  EXPECT_FALSE(fs::exists(dir.path() / "model.ply"));
  EXPECT_FALSE(fs::exists(dir.path() / "transforms_1.json"));
  EXPECT_TRUE(result.warnings.empty());
}

// A COLMAP project's own model folders and notes are never touched, and named where a
// reader would take them for Tessera's models.
TEST(OutputTransaction, WhatTesseraDidNotWriteIsLeftAndNamed) {
  const testing::TemporaryDir dir;
  WriteTextFile(dir.path() / "sparse/1/notes.txt", "mine");
  WriteTextFile(dir.path() / "sparse/2/images.bin", "theirs");
  CommitSet(dir.path(), {{"colmap_binary", {{"sparse/0/images.bin", "a"}}}});
  const auto result = CommitSet(dir.path(), {{"colmap_binary", {{"sparse/0/images.bin", "b"}}}});
  EXPECT_EQ(ReadTextFile(dir.path() / "sparse/1/notes.txt"), "mine");
  EXPECT_EQ(ReadTextFile(dir.path() / "sparse/2/images.bin"), "theirs");
  EXPECT_EQ(ReadTextFile(dir.path() / "sparse/0/images.bin"), "b");
  EXPECT_TRUE(Mentions(result.warnings, (dir.path() / "sparse/1").string()));
  EXPECT_TRUE(Mentions(result.warnings, (dir.path() / "sparse/2").string()));
}

// A model folder the user added a note to: Tessera's files in it are replaced one by
// one, and the note stays.
TEST(OutputTransaction, AFolderWithAFileOfTheUsersIsReplacedFileByFile) {
  const testing::TemporaryDir dir;
  CommitSet(dir.path(), {{"colmap_binary", {{"sparse/0/images.bin", "a"}}}});
  WriteTextFile(dir.path() / "sparse/0/notes.txt", "mine");
  CommitSet(dir.path(), {{"colmap_text", {{"sparse/0/images.txt", "b"}}}});
  EXPECT_EQ(ReadTextFile(dir.path() / "sparse/0/notes.txt"), "mine");
  EXPECT_EQ(ReadTextFile(dir.path() / "sparse/0/images.txt"), "b");
  EXPECT_FALSE(fs::exists(dir.path() / "sparse/0/images.bin"));
}

TEST(OutputTransaction, RefusesToReplaceAFileTesseraDidNotWriteAndMovesNothing) {
  const testing::TemporaryDir dir;
  WriteTextFile(dir.path() / "sparse/0/images.bin", "theirs");
  OutputTransaction outputs(dir.path());
  WriteTextFile(outputs.StageFor("colmap_binary") / "sparse/0/images.bin", "ours");
  WriteTextFile(outputs.StageFor("ply") / "model.ply", "p");
  try {
    outputs.Commit();
    FAIL() << "no error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find((dir.path() / "sparse/0/images.bin").string()),
              std::string::npos)
        << error.what();
    EXPECT_NE(std::string(error.what()).find("colmap_binary"), std::string::npos);
  }
  EXPECT_EQ(ReadTextFile(dir.path() / "sparse/0/images.bin"), "theirs");
  EXPECT_FALSE(fs::exists(dir.path() / "model.ply"));  // nothing of the set moved
  EXPECT_TRUE(fs::exists(outputs.staging_folder()));   // kept until the next run
}

TEST(OutputTransaction, ChangedOutputsOfAnEarlierRunAreLeftWithAWarning) {
  const testing::TemporaryDir dir;
  CommitSet(dir.path(), {{"ply", {{"model.ply", "p"}}}});
  WriteTextFile(dir.path() / "model.ply", "edited by hand");
  const auto result = CommitSet(dir.path(), {{"colmap_binary", {{"sparse/0/images.bin", "a"}}}});
  EXPECT_EQ(ReadTextFile(dir.path() / "model.ply"), "edited by hand");
  EXPECT_TRUE(Mentions(result.warnings, "model.ply"));
  // No longer Tessera's: a later set may not replace it either.
  EXPECT_THROW(CommitSet(dir.path(), {{"ply", {{"model.ply", "q"}}}}), InputError);
}

TEST(OutputTransaction, AnExporterMayNotWriteTheWorkspacesOwnFiles) {
  const testing::TemporaryDir dir;
  WriteTextFile(dir.path() / "database.db", "db");
  for (const std::string name :
       {"database.db", "cache/x", ".tessera.lock", "run_summary.json", "mapping_summary.json"}) {
    EXPECT_THROW(CommitSet(dir.path(), {{"transforms_json", {{name, "{}"}}}}), InputError) << name;
  }
  EXPECT_EQ(ReadTextFile(dir.path() / "database.db"), "db");
}

// run_summary.json: the host's, recorded like any output, and removed by the next whole
// set (a map that does not write one), so that it never describes models not there.
TEST(OutputTransaction, TheRunSummaryIsAnOutputRemovedWithTheNextSet) {
  const testing::TemporaryDir dir;
  CommitSet(dir.path(), {{"tessera", {{"sparse/0/images.bin", "a"}}}});
  CommitSet(dir.path(), {{"tessera", {{"run_summary.json", "{}"}}}},
            OutputTransaction::Mode::kAddToSet);
  EXPECT_TRUE(OutputLedger::Read(dir.path()).Owns(dir.path(), "run_summary.json"));
  EXPECT_TRUE(fs::exists(dir.path() / "sparse/0/images.bin"));
  CommitSet(dir.path(), {{"tessera", {{"sparse/0/images.bin", "b"}}}});
  EXPECT_FALSE(fs::exists(dir.path() / "run_summary.json"));
  EXPECT_FALSE(OutputLedger::Read(dir.path()).HasFile("run_summary.json"));
}

TEST(OutputTransaction, TwoWritersOfOneFileAreRefusedNamingBoth) {
  const testing::TemporaryDir dir;
  try {
    CommitSet(dir.path(), {{"colmap_binary", {{"sparse/0/images.bin", "a"}}},
                           {"gaussian_splatting", {{"sparse/0/images.bin", "b"}}}});
    FAIL() << "no error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("'colmap_binary' and 'gaussian_splatting'"),
              std::string::npos)
        << error.what();
  }
  EXPECT_FALSE(fs::exists(dir.path() / "sparse"));
}

// OUTPUT/sparse a link to another folder: nothing is written or deleted through it.
TEST(OutputTransaction, NothingIsWrittenOrDeletedThroughALink) {
  const testing::TemporaryDir dir;
  const fs::path elsewhere = dir.path() / "elsewhere";
  WriteTextFile(elsewhere / "0/images.bin", "precious");
  const fs::path output = dir.path() / "out";
  fs::create_directories(output);
  fs::create_directory_symlink(elsewhere, output / "sparse");
  EXPECT_THROW(CommitSet(output, {{"colmap_binary", {{"sparse/0/images.bin", "a"}}}}), InputError);
  EXPECT_EQ(ReadTextFile(elsewhere / "0/images.bin"), "precious");
  // A link where Tessera's file was: not Tessera's any more, not followed.
  const fs::path output2 = dir.path() / "out2";
  CommitSet(output2, {{"ply", {{"model.ply", "p"}}}});
  fs::remove(output2 / "model.ply");
  fs::create_symlink(elsewhere / "0/images.bin", output2 / "model.ply");
  CommitSet(output2, {{"colmap_binary", {{"sparse/0/images.bin", "a"}}}});
  EXPECT_EQ(ReadTextFile(elsewhere / "0/images.bin"), "precious");
  EXPECT_TRUE(fs::is_symlink(output2 / "model.ply"));
}

// The image folder inside a folder Tessera wrote (a 3DGS export's images) is never
// replaced or emptied.
TEST(OutputTransaction, AProtectedFolderIsNeverReplacedOrWrittenIn) {
  const testing::TemporaryDir dir;
  CommitSet(dir.path(), {{"gaussian_splatting", {{"gaussian_splatting/images/a.jpg", "a"}}}});
  {
    OutputTransaction outputs(dir.path());
    outputs.Protect(dir.path() / "gaussian_splatting/images");
    WriteTextFile(outputs.StageFor("gaussian_splatting") / "gaussian_splatting/images/b.jpg", "b");
    EXPECT_THROW(outputs.Commit(), InputError);
  }
  EXPECT_EQ(ReadTextFile(dir.path() / "gaussian_splatting/images/a.jpg"), "a");
  {
    OutputTransaction outputs(dir.path());  // a set without it would remove it
    outputs.Protect(dir.path() / "gaussian_splatting/images");
    WriteTextFile(outputs.StageFor("ply") / "model.ply", "p");
    outputs.Commit();
  }
  EXPECT_EQ(ReadTextFile(dir.path() / "gaussian_splatting/images/a.jpg"), "a");
}

// A kill between the ledger's journal and the last rename leaves files that all count
// as Tessera's: the next set replaces them. Its leftovers are removed.
TEST(OutputTransaction, LeftoversOfAKilledRunAreRemovedAndItsOutputsStayTesseras) {
  const testing::TemporaryDir dir;
  CommitSet(dir.path(), {{"colmap_binary", {{"sparse/0/images.bin", "old"}}}});
  // As a kill leaves it: the journal accepts both versions, one is in place, the
  // staging folder and an atomic write's temporary remain.
  OutputLedger journal = OutputLedger::Read(dir.path());
  WriteTextFile(dir.path() / "new.bin", "new");
  journal.AddFile("sparse/0/images.bin", DigestFile(dir.path() / "new.bin"));
  fs::remove(dir.path() / "new.bin");
  journal.Write(dir.path());
  WriteTextFile(dir.path() / "sparse/0/images.bin", "new");
  const fs::path leftover = dir.path() / OutputTransaction::kStagingFolderName / "1/set/x";
  WriteTextFile(leftover, "partial");
  // The ledger's temporary, as a kill during its write leaves it ("." + ".tessera_outputs...").
  const fs::path ledger_temporary =
      dir.path() / "..tessera_outputs.json.tessera-tmp-999999999-0123456789abcdef";
  WriteTextFile(ledger_temporary, "partial");
  CommitSet(dir.path(), {{"colmap_binary", {{"sparse/0/images.bin", "newer"}}}});
  EXPECT_EQ(ReadTextFile(dir.path() / "sparse/0/images.bin"), "newer");
  EXPECT_FALSE(fs::exists(leftover));
  EXPECT_FALSE(fs::exists(ledger_temporary));
}

// Issue 60 item 2: a PID that no longer runs made any ".NAME.tmp-PID" a leftover of an
// interrupted write, in OUTPUT and in every folder the ledger names (which a forged
// ledger can point at a folder of the user's). Only Tessera's token, for a file of the
// workspace layout at the top of OUTPUT, is a leftover now.
TEST(OutputTransaction, FilesNamedLikeTemporariesThatAreNotTesserasAreKept) {
  const testing::TemporaryDir dir;
  CommitSet(dir.path(), {{"colmap_binary", {{"sparse/0/images.bin", "a"}}}});
  const std::vector<fs::path> users = {
      dir.path() / ".notes.tmp-999999",
      dir.path() / "sparse/0/.draft.tmp-999998",
      dir.path() / "photos/.x.tmp-5",
      dir.path() / "photos/.x.tmp-999997",
      // Tessera's token, but for a name Tessera does not write at the top, or in a
      // folder (Tessera writes its outputs in the staging folder, never in place).
      dir.path() / ".notes.txt.tessera-tmp-999999-0123456789abcdef",
      dir.path() / "sparse/0/.images.bin.tessera-tmp-999999-0123456789abcdef",
      dir.path() / "photos/..tessera_outputs.json.tessera-tmp-999999-0123456789abcdef",
  };
  for (const fs::path& path : users) WriteTextFile(path, "mine");
  // A forged ledger naming the user's folder.
  OutputLedger forged = OutputLedger::Read(dir.path());
  forged.AddFolder("photos");
  forged.Write(dir.path());
  CommitSet(dir.path(), {{"colmap_binary", {{"sparse/0/images.bin", "b"}}}},
            OutputTransaction::Mode::kAddToSet);
  for (const fs::path& path : users) EXPECT_EQ(ReadTextFile(path), "mine") << path;
}

TEST(OutputTransaction, AddingToTheSetKeepsTheOtherModels) {
  const testing::TemporaryDir dir;
  CommitSet(
      dir.path(),
      {{"colmap_binary", {{"sparse/0/images.bin", "0"}, {"sparse/1/images.bin", "1"}}},
       {"gaussian_splatting",
        {{"gaussian_splatting/images/a.jpg", "a"}, {"gaussian_splatting/images/b.jpg", "b"}}}});
  CommitSet(dir.path(),
            {{"colmap_text", {{"sparse/1/images.txt", "1"}}},
             {"gaussian_splatting", {{"gaussian_splatting/images/a.jpg", "a2"}}}},
            OutputTransaction::Mode::kAddToSet);
  EXPECT_EQ(ReadTextFile(dir.path() / "sparse/0/images.bin"), "0");
  EXPECT_EQ(ReadTextFile(dir.path() / "sparse/1/images.txt"), "1");
  EXPECT_FALSE(fs::exists(dir.path() / "sparse/1/images.bin"));  // the model folder, whole
  EXPECT_FALSE(fs::exists(dir.path() / "gaussian_splatting/images/b.jpg"));
  // The files it kept are still Tessera's: a whole set removes them.
  CommitSet(dir.path(), {{"ply", {{"model.ply", "p"}}}});
  EXPECT_FALSE(fs::exists(dir.path() / "sparse"));
}

TEST(OutputLedger, ARecordThatIsNotALedgerIsAnErrorNamingIt) {
  const testing::TemporaryDir dir;
  WriteTextFile(dir.path() / OutputLedger::kFileName, "not json");
  try {
    OutputLedger::Read(dir.path());
    FAIL() << "no error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find(OutputLedger::kFileName), std::string::npos);
  }
}

}  // namespace
}  // namespace tessera
