#pragma once

// A prepared SQLite statement, and one use of it (bind, step, read columns, reset),
// whose errors name the database file and the operation.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>

#include "database/sqlite_connection.h"

struct sqlite3_stmt;

namespace tessera {

class SqliteStatement {
 public:
  // Prepares `sql` on `connection`, which must outlive the statement. `persistent` for
  // statements kept for the connection's life (SQLite then keeps them out of its
  // lookaside memory). Throws as SqliteConnection::Fail, naming the statement.
  SqliteStatement(const SqliteConnection& connection, const std::string& sql,
                  bool persistent = true);
  ~SqliteStatement();
  SqliteStatement(const SqliteStatement&) = delete;
  SqliteStatement& operator=(const SqliteStatement&) = delete;

  // One execution, named by `operation` ("read camera 3") in its errors. Its end resets
  // the statement and clears the bindings, however it ends: a SELECT left un-reset
  // would keep its read transaction open.
  class Use {
   public:
    Use(const SqliteStatement& statement, std::string operation);
    ~Use();
    Use(const Use&) = delete;
    Use& operator=(const Use&) = delete;

    // Parameters count from 1, as in SQL.
    void BindInt64(int index, int64_t value) const;
    void BindNull(int index) const;
    void BindText(int index, const std::string& text) const;  // copied
    // Not copied: `data` must stay alive until the last Step. Empty data is bound as a
    // zero-length blob rather than NULL, as COLMAP writes it.
    void BindBlob(int index, const void* data, size_t num_bytes) const;

    // true for a row, false when done.
    bool Step() const;

    // Columns of the current row, counted from 0.
    int64_t ColumnInt64(int column) const;
    bool ColumnIsNull(int column) const;
    const char* ColumnText(int column) const;  // nullptr for NULL
    size_t ColumnBytes(int column) const;
    // A blob column's bytes, checked to be `expected_bytes` long; a corrupt or foreign
    // row is the user's file to fix, hence InputError naming `what`.
    const void* ColumnBlob(int column, size_t expected_bytes, const std::string& what) const;
    // Checks that a blob column holds `rows` x `cols` elements of `element_bytes`, before
    // anything is allocated for them: a corrupt row count is refused, not allocated.
    void CheckColumnArray(int column, int64_t rows, int64_t cols, size_t element_bytes,
                          const std::string& what) const;

    // The database file, for errors about what a row holds.
    const std::filesystem::path& path() const { return connection_.path(); }

   private:
    const SqliteConnection& connection_;
    sqlite3_stmt* stmt_;
    std::string operation_;
  };

  // Shorthands for one-row queries. QueryInt64: steps once and reads the first column
  // (COUNT, SUM). QueryExists: binds `key` to the one parameter; true if a row matches.
  int64_t QueryInt64(const std::string& operation) const;
  bool QueryExists(int64_t key, const std::string& operation) const;

 private:
  const SqliteConnection& connection_;
  sqlite3_stmt* stmt_ = nullptr;
};

}  // namespace tessera
