#pragma once

// One SQLite connection to a workspace database file, and the one place that turns a
// failed SQLite call into an exception naming the file and the operation.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>

struct sqlite3;

namespace tessera {

class SqliteConnection {
 public:
  // How the file is opened (Database::Mode's meanings).
  enum class Access { kReadWrite, kReadOnly, kImmutable };
  // Opens the file: read-write (created if missing) with WAL journal; read only, with
  // SQLite's locks, beside a writer on this host (the file must exist); or read only in
  // SQLite's immutable mode (no lock, no -wal/-shm file; the file must exist, and no one
  // may write it meanwhile). Throws InputError naming the file if it cannot be opened or
  // is not a SQLite database.
  SqliteConnection(const std::filesystem::path& path, Access access);
  // Rolls back an open transaction and closes (after every statement is finalized).
  ~SqliteConnection();
  SqliteConnection(const SqliteConnection&) = delete;
  SqliteConnection& operator=(const SqliteConnection&) = delete;

  const std::filesystem::path& path() const { return path_; }
  bool read_only() const { return read_only_; }
  sqlite3* handle() const { return db_; }

  // Until this is called, an SQL error comes from what the file holds (a file format
  // SQLite does not know, a malformed schema) and is an InputError like a file that is
  // no database at all; after it, an error is the failure of an operation.
  void EndOpening() { opening_ = false; }

  // Throws for the failed SQLite call `rc` of `operation` ("write camera 3"): InputError
  // for a file that is not (or no longer) a database or a full disk, std::runtime_error
  // otherwise.
  [[noreturn]] void Fail(int rc, const std::string& operation) const;
  void Check(int rc, const std::string& operation) const;
  void Exec(const std::string& sql, const std::string& operation) const;
  // For rollbacks on a path that is already failing: SQLite may have rolled back
  // itself after an I/O error, and the first error is the one to report.
  void ExecIgnoringErrors(const char* sql) const;

  // Runs `fn` atomically: a savepoint nests inside an open transaction, and stands for
  // one on its own.
  void Atomically(const std::string& operation, const std::function<void()>& fn) const;

  int64_t LastInsertRowId() const;
  int64_t NumChangedRows() const;  // by the last INSERT, UPDATE or DELETE

  // The caller's transaction (Database::Transaction). IMMEDIATE takes the write lock at
  // once, so a batch never fails half-way on a lock another connection took first.
  bool in_transaction() const { return in_transaction_; }
  void BeginTransaction();
  void CommitTransaction();
  void RollbackTransaction();

 private:
  std::filesystem::path path_;
  bool read_only_ = false;
  bool opening_ = true;
  bool in_transaction_ = false;
  sqlite3* db_ = nullptr;
};

}  // namespace tessera
