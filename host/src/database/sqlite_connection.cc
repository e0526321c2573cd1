#include "database/sqlite_connection.h"

#include <sqlite3.h>

#include <stdexcept>

#include "tessera/errors.h"

namespace tessera {
namespace {

// An SQLite URI for `path` with `query`: '%', '?' and '#' percent-encoded.
std::string DatabaseUri(const std::filesystem::path& path, const std::string& query) {
  std::string uri = "file:";
  for (const char c : std::filesystem::absolute(path).string()) {
    if (c == '%') {
      uri += "%25";
    } else if (c == '?') {
      uri += "%3f";
    } else if (c == '#') {
      uri += "%23";
    } else {
      uri += c;
    }
  }
  return uri + "?" + query;
}

}  // namespace

SqliteConnection::SqliteConnection(const std::filesystem::path& path, Access access)
    : path_(path), read_only_(access != Access::kReadWrite) {
  if (read_only_ && !std::filesystem::exists(path_)) {
    throw InputError("Cannot open database file '" + path_.string() + "': it does not exist.");
  }
  // Immutable: SQLite takes no lock and writes nothing (no -shm, no -wal), so readers on
  // network filesystems are safe while no one writes the file. Read only: SQLite's shared
  // locks and the writer's WAL index, so a reader beside a running writer sees each
  // committed state whole.
  const std::string uri = access == Access::kImmutable  ? DatabaseUri(path_, "immutable=1")
                          : access == Access::kReadOnly ? DatabaseUri(path_, "mode=ro")
                                                        : path_.string();
  const int flags = read_only_ ? SQLITE_OPEN_READONLY | SQLITE_OPEN_URI
                               : SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE;
  const int rc = sqlite3_open_v2(uri.c_str(), &db_, flags, nullptr);
  if (rc != SQLITE_OK) {
    const std::string message = db_ != nullptr ? sqlite3_errmsg(db_) : sqlite3_errstr(rc);
    sqlite3_close_v2(db_);
    db_ = nullptr;
    throw InputError("Cannot open database file '" + path_.string() + "': " + message + ".");
  }
  try {
    sqlite3_extended_result_codes(db_, 1);
    // Another process (a second Tessera, COLMAP's GUI) may hold a lock for a moment.
    sqlite3_busy_timeout(db_, 5000);
    // The first read of the file: a file that is not a database fails here.
    Exec("SELECT COUNT(*) FROM sqlite_master;", "read the schema");
    if (read_only_) return;
    // SQLite opens a file it may not write read-only without an error: a file without
    // write permission, or one whose header asks for a newer writer (a damaged header).
    if (sqlite3_db_readonly(db_, "main") == 1) {
      throw InputError("Database file '" + path_.string() +
                       "' can only be read: the file is not writable, or its header names a file "
                       "format version that SQLite does not write (a damaged or newer file).");
    }
    // WAL, as COLMAP uses: readers do not block the writer, and a killed process leaves
    // the last committed state. NORMAL sync is durable against process crashes (only a
    // power loss may drop the last commits, never corrupt the file).
    Exec("PRAGMA journal_mode=WAL;", "set the journal mode");
    Exec("PRAGMA synchronous=NORMAL;", "set the synchronous mode");
    Exec("PRAGMA foreign_keys=ON;", "enable foreign keys");
    Exec("PRAGMA temp_store=MEMORY;", "set the temporary store");
  } catch (...) {
    sqlite3_close_v2(db_);  // the destructor does not run for a throwing constructor
    throw;
  }
}

SqliteConnection::~SqliteConnection() {
  if (in_transaction_) ExecIgnoringErrors("ROLLBACK;");
  sqlite3_close_v2(db_);
}

void SqliteConnection::Fail(int rc, const std::string& operation) const {
  const std::string message =
      std::string(db_ != nullptr ? sqlite3_errmsg(db_) : sqlite3_errstr(rc));
  const int primary = rc & 0xff;
  // While opening, SQLite reports a damaged header or schema also as SQLITE_ERROR or as
  // SQLITE_NOMEM (sizes read from the file that it cannot allocate).
  if (primary == SQLITE_NOTADB || primary == SQLITE_CORRUPT ||
      (opening_ && (primary == SQLITE_ERROR || primary == SQLITE_NOMEM))) {
    throw InputError("Database file '" + path_.string() + "' is not a valid SQLite database (" +
                     message + ") while trying to " + operation + ".");
  }
  // A full disk (or a file size limit) is the user's to fix; SQLite rolled the
  // transaction back, so the workspace stays valid and a later run resumes.
  if (primary == SQLITE_FULL || rc == SQLITE_IOERR_WRITE || rc == SQLITE_IOERR_FSYNC ||
      rc == SQLITE_IOERR_TRUNCATE || rc == SQLITE_IOERR_SHMSIZE) {
    throw InputError("Database file '" + path_.string() + "': cannot " + operation + ": " +
                     message + " (is the disk full?).");
  }
  throw std::runtime_error("Database '" + path_.string() + "': cannot " + operation + ": " +
                           message + ".");
}

void SqliteConnection::Check(int rc, const std::string& operation) const {
  if (rc != SQLITE_OK) Fail(rc, operation);
}

void SqliteConnection::Exec(const std::string& sql, const std::string& operation) const {
  const int rc = sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, nullptr);
  if (rc != SQLITE_OK) Fail(rc, operation);
}

void SqliteConnection::ExecIgnoringErrors(const char* sql) const {
  sqlite3_exec(db_, sql, nullptr, nullptr, nullptr);
}

void SqliteConnection::Atomically(const std::string& operation,
                                  const std::function<void()>& fn) const {
  Exec("SAVEPOINT tessera_atomic;", operation);
  try {
    fn();
  } catch (...) {
    ExecIgnoringErrors("ROLLBACK TO tessera_atomic; RELEASE tessera_atomic;");
    throw;
  }
  Exec("RELEASE tessera_atomic;", operation);
}

int64_t SqliteConnection::LastInsertRowId() const { return sqlite3_last_insert_rowid(db_); }

int64_t SqliteConnection::NumChangedRows() const { return sqlite3_changes(db_); }

void SqliteConnection::BeginTransaction() {
  Exec("BEGIN IMMEDIATE;", "begin a transaction");
  in_transaction_ = true;
}

void SqliteConnection::CommitTransaction() {
  Exec("COMMIT;", "commit a transaction");
  in_transaction_ = false;
}

void SqliteConnection::RollbackTransaction() {
  ExecIgnoringErrors("ROLLBACK;");
  in_transaction_ = false;
}

}  // namespace tessera
