// The database file: transactions, threads, a killed process, a full disk, files that
// are not databases, and read-only opening.

#include "database/sqlite_connection.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <thread>

#include "database/database.h"
#include "database/database_test_support.h"
#include "tessera/errors.h"

namespace tessera {
namespace {

TEST_F(DatabaseTest, TransactionsCommitOrRollBack) {
  Database database(DatabasePath());
  AddCamerasAndImages(&database);
  {
    Database::Transaction transaction(&database);
    database.WriteKeypoints(1, {FeatureKeypoint(1, 1)});
    database.WriteMatches(1, 2, {{0, 0}});
    EXPECT_THROW(Database::Transaction nested(&database), std::logic_error);
  }  // not committed
  EXPECT_FALSE(database.ExistsKeypoints(1));
  EXPECT_FALSE(database.ExistsMatches(1, 2));
  {
    Database::Transaction transaction(&database);
    database.WriteKeypoints(1, {FeatureKeypoint(1, 1)});
    database.WriteMatches(1, 2, {{0, 0}});
    // Clearing inside a transaction nests (a savepoint) and rolls back with it.
    database.ClearMatches();
    database.WriteMatches(2, 3, {{0, 0}});
    transaction.Commit();
    EXPECT_THROW(transaction.Commit(), std::logic_error);
  }
  EXPECT_TRUE(database.ExistsKeypoints(1));
  EXPECT_FALSE(database.ExistsMatches(1, 2));
  EXPECT_TRUE(database.ExistsMatches(2, 3));
}

TEST_F(DatabaseTest, ConcurrentWritersShareOneConnection) {
  Database database(DatabasePath());
  Image image;
  image.camera_id = database.WriteCamera(
      Camera::Create(kInvalidCameraId, CameraModelId::kSimplePinhole, 100, 64, 48));
  constexpr image_t kNumImages = 24;
  for (image_t i = 0; i < kNumImages; ++i) {
    image.name = std::to_string(i) + ".jpg";
    database.WriteImage(image);
  }
  // Each thread writes its own pairs, with matches that encode the pair.
  const auto matches_of = [](image_t id1, image_t id2) {
    return FeatureMatches(id1 + id2, FeatureMatch{id1, id2});
  };
  std::vector<std::thread> threads;
  for (image_t t = 0; t < 4; ++t) {
    threads.emplace_back([&, t] {
      for (image_t id1 = 1; id1 <= kNumImages; ++id1) {
        for (image_t id2 = id1 + 1; id2 <= kNumImages; ++id2) {
          if ((id1 + id2) % 4 != t) continue;
          database.WriteMatches(id2, id1, matches_of(id2, id1));
          EXPECT_EQ(database.ReadMatches(id1, id2).size(), id1 + id2);
        }
      }
    });
  }
  for (std::thread& thread : threads) thread.join();
  EXPECT_EQ(database.NumMatchedPairs(), kNumImages * (kNumImages - 1) / 2);
  for (image_t id1 = 1; id1 <= kNumImages; ++id1) {
    for (image_t id2 = id1 + 1; id2 <= kNumImages; ++id2) {
      ASSERT_EQ(database.ReadMatches(id2, id1), matches_of(id2, id1)) << id1 << " " << id2;
    }
  }
}

TEST_F(DatabaseTest, KilledProcessLeavesTheCommittedState) {
  {
    Database database(DatabasePath());
    AddCamerasAndImages(&database);
  }
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    // The child commits one batch, starts a second and is killed in the middle of it.
    Database database(DatabasePath());
    {
      Database::Transaction transaction(&database);
      database.WriteKeypoints(1, {FeatureKeypoint(1, 1), FeatureKeypoint(2, 2)});
      database.WriteMatches(1, 2, {{0, 1}});
      transaction.Commit();
    }
    Database::Transaction transaction(&database);
    database.WriteKeypoints(2, {FeatureKeypoint(3, 3)});
    database.WriteMatches(1, 3, {{0, 1}});
    raise(SIGKILL);
    _exit(0);
  }
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFSIGNALED(status));
  EXPECT_EQ(WTERMSIG(status), SIGKILL);

  Database database(DatabasePath());
  EXPECT_EQ(database.ReadKeypoints(1).size(), 2u);
  EXPECT_EQ(database.ReadMatches(2, 1), (FeatureMatches{{1, 0}}));
  EXPECT_FALSE(database.ExistsKeypoints(2));
  EXPECT_FALSE(database.ExistsMatches(1, 3));
  RawDatabase raw(DatabasePath());
  EXPECT_EQ(raw.Row("PRAGMA integrity_check;"), std::vector<std::string>{"ok"});
}

TEST_F(DatabaseTest, TextFileIsAnInputErrorNamingTheFile) {
  const fs::path path = dir_.path() / "notes.db";
  std::ofstream(path) << "This is a text file, long enough to fill a SQLite header and more of "
                         "it: lorem ipsum dolor sit amet, consectetur adipiscing elit.\n";
  try {
    Database database(path);
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("'" + path.string() + "' is not a valid SQLite database"),
              std::string::npos)
        << message;
  }
}

TEST_F(DatabaseTest, MissingFolderIsAnInputError) {
  const fs::path path = dir_.path() / "no" / "such" / "folder" / "database.db";
  try {
    Database database(path);
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("Cannot open database file '" + path.string()),
              std::string::npos)
        << error.what();
  }
}

// The message of the InputError that opening a new database at `path` gives after
// `bytes` are written over its header at `offset`; empty when it opens.
std::string OpenErrorAfterOverwritingHeader(const fs::path& path, std::streamoff offset,
                                            const std::string& bytes) {
  { Database database(path); }
  {
    std::fstream file(path, std::ios::in | std::ios::out | std::ios::binary);
    file.seekp(offset);
    file.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  }
  try {
    Database database(path);
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

// Found by tests/fuzz (database target): a file SQLite refuses to read ("unsupported
// file format": a schema format number above 4) is bad input, not an internal failure.
TEST_F(DatabaseTest, UnsupportedSchemaFormatIsAnInputError) {
  // 44: the schema format number, big-endian.
  const std::string error =
      OpenErrorAfterOverwritingHeader(DatabasePath(), 44, std::string("\0\0\0\x09", 4));
  EXPECT_NE(error.find("unsupported file format"), std::string::npos) << error;
}

// Found by tests/fuzz (database target): a header whose file format write version is
// above 2 makes SQLite open the file read-only without an error; writing the journal
// mode then failed as an internal error. It is bad input, named before any write.
TEST_F(DatabaseTest, AHeaderSQLiteMayNotWriteIsAnInputError) {
  // 18: the file format write version.
  EXPECT_EQ(OpenErrorAfterOverwritingHeader(DatabasePath(), 18, "\x41"),
            "Database file '" + DatabasePath().string() +
                "' can only be read: the file is not writable, or its header names a file "
                "format version that SQLite does not write (a damaged or newer file).");
}

// A full disk (here a file size limit, as `ulimit -f`) is an InputError naming the
// file, and the database keeps its last committed state.
TEST_F(DatabaseTest, AFullDiskIsAnInputErrorAndKeepsTheCommittedState) {
  {
    Database database(DatabasePath());
    AddCamerasAndImages(&database);
  }
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    signal(SIGXFSZ, SIG_IGN);
    const rlimit limit = {256 * 1024, 256 * 1024};
    if (setrlimit(RLIMIT_FSIZE, &limit) != 0) _exit(3);
    try {
      Database database(DatabasePath());
      FeatureDescriptors descriptors;
      descriptors.data = FeatureDescriptors::Matrix::Constant(20000, 128, 1);  // 2.5 MB
      Database::Transaction transaction(&database);
      database.WriteDescriptors(1, descriptors);
      transaction.Commit();
      _exit(4);  // written past the limit
    } catch (const InputError& error) {
      const std::string message = error.what();
      const bool named = message.find(DatabasePath().string()) != std::string::npos &&
                         message.find("is the disk full?") != std::string::npos;
      _exit(named ? 0 : 5);
    } catch (...) {
      _exit(6);
    }
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "3: setrlimit, 4: no error, 5: message, 6: other error";
  Database database(DatabasePath());
  EXPECT_EQ(database.NumImages(), 3u);
  EXPECT_FALSE(database.ExistsDescriptors(1));
}

// Both read-only modes read an existing file without changing it, refuse writes, and
// never create a missing file; the immutable one also leaves no -wal or -shm file.
void ExpectReadsWithoutWriting(Database::Mode mode) {
  testing::TemporaryDir dir;
  const fs::path path = dir.path() / "what?#%.db";  // characters a URI must encode
  std::mt19937 rng(3);
  {
    Database database(path);
    database.WriteCamera(Camera::Create(kInvalidCameraId, CameraModelId::kPinhole, 500, 640, 480));
    Image image;
    image.name = "a.jpg";
    image.camera_id = 1;
    database.WriteImage(image);
    database.WriteKeypoints(1, RandomKeypoints(7, &rng));
    database.WriteStageProvenance("x", {{"a", 1}});
    database.WriteStageProvenance("y", {{"b", 2}});
    database.DeleteStageProvenance("y");
  }
  ASSERT_FALSE(fs::exists(path.string() + "-wal"));
  const auto modified = fs::last_write_time(path);
  {
    const Database reader(path, mode);
    const Database other(path, mode);
    EXPECT_EQ(reader.ReadAllImages().size(), 1u);
    EXPECT_EQ(reader.ReadNumKeypointsPerImage(), (std::map<image_t, size_t>{{1, 7}}));
    EXPECT_EQ(other.ReadKeypoints(1).size(), 7u);
    EXPECT_EQ(reader.ReadStageProvenance("x"), nlohmann::json({{"a", 1}}));
    EXPECT_FALSE(reader.ReadStageProvenance("y"));
    Database writer(path, mode);
    EXPECT_THROW(writer.WriteKeypoints(1, RandomKeypoints(2, &rng)), std::exception);
    if (mode == Database::Mode::kImmutable) {
      EXPECT_FALSE(fs::exists(path.string() + "-wal"));
      EXPECT_FALSE(fs::exists(path.string() + "-shm"));
    }
  }
  EXPECT_EQ(fs::last_write_time(path), modified);
  EXPECT_EQ(Database(path).ReadKeypoints(1).size(), 7u);
  EXPECT_THROW(Database(dir.path() / "missing.db", mode), InputError);
  EXPECT_FALSE(fs::exists(dir.path() / "missing.db"));
}

TEST(DatabaseReadOnly, ReadsWithoutWritingAndRefusesWrites) {
  ExpectReadsWithoutWriting(Database::Mode::kReadOnly);
}

TEST(DatabaseImmutable, ReadsWithoutWritingOrLockingAndRefusesWrites) {
  ExpectReadsWithoutWriting(Database::Mode::kImmutable);
}

// A reader beside the workspace's writer (the GUI's match matrix during a run): it sees
// each committed state, never a transaction in progress, and sees new commits as they
// land, which the immutable mode does not promise.
TEST(DatabaseReadOnly, ReadsEachCommittedStateBesideAWriter) {
  testing::TemporaryDir dir;
  const fs::path path = dir.path() / "database.db";
  std::mt19937 rng(5);
  Database writer(path);
  writer.WriteCamera(Camera::Create(kInvalidCameraId, CameraModelId::kPinhole, 500, 640, 480));
  for (const char* name : {"a.jpg", "b.jpg"}) {
    Image image;
    image.name = name;
    image.camera_id = 1;
    writer.WriteImage(image);
  }
  writer.WriteKeypoints(1, RandomKeypoints(5, &rng));
  const Database reader(path, Database::Mode::kReadOnly);
  EXPECT_EQ(reader.ReadNumKeypointsPerImage(), (std::map<image_t, size_t>{{1, 5}}));
  {
    Database::Transaction transaction(&writer);
    writer.WriteKeypoints(2, RandomKeypoints(9, &rng));
    EXPECT_FALSE(reader.ExistsKeypoints(2)) << "a transaction in progress was seen";
    transaction.Commit();
  }
  EXPECT_TRUE(reader.ExistsKeypoints(2));
  EXPECT_EQ(reader.ReadKeypoints(2).size(), 9u);
}

}  // namespace
}  // namespace tessera
