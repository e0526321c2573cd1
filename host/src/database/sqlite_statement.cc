#include "database/sqlite_statement.h"

#include <sqlite3.h>

#include <utility>

#include "tessera/errors.h"

namespace tessera {

SqliteStatement::SqliteStatement(const SqliteConnection& connection, const std::string& sql,
                                 bool persistent)
    : connection_(connection) {
  const int rc = sqlite3_prepare_v3(connection_.handle(), sql.c_str(), -1,
                                    persistent ? SQLITE_PREPARE_PERSISTENT : 0, &stmt_, nullptr);
  if (rc != SQLITE_OK) {
    sqlite3_finalize(stmt_);
    connection_.Fail(rc, "prepare the statement '" + sql + "'");
  }
}

SqliteStatement::~SqliteStatement() { sqlite3_finalize(stmt_); }

int64_t SqliteStatement::QueryInt64(const std::string& operation) const {
  Use use(*this, operation);
  use.Step();
  return use.ColumnInt64(0);
}

bool SqliteStatement::QueryExists(int64_t key, const std::string& operation) const {
  Use use(*this, operation);
  use.BindInt64(1, key);
  return use.Step();
}

SqliteStatement::Use::Use(const SqliteStatement& statement, std::string operation)
    : connection_(statement.connection_),
      stmt_(statement.stmt_),
      operation_(std::move(operation)) {}

SqliteStatement::Use::~Use() {
  sqlite3_reset(stmt_);
  sqlite3_clear_bindings(stmt_);
}

void SqliteStatement::Use::BindInt64(int index, int64_t value) const {
  connection_.Check(sqlite3_bind_int64(stmt_, index, value), operation_);
}

void SqliteStatement::Use::BindNull(int index) const {
  connection_.Check(sqlite3_bind_null(stmt_, index), operation_);
}

void SqliteStatement::Use::BindText(int index, const std::string& text) const {
  connection_.Check(sqlite3_bind_text(stmt_, index, text.c_str(), static_cast<int>(text.size()),
                                      SQLITE_TRANSIENT),
                    operation_);
}

void SqliteStatement::Use::BindBlob(int index, const void* data, size_t num_bytes) const {
  static const char kEmpty = 0;
  connection_.Check(
      sqlite3_bind_blob64(stmt_, index, num_bytes > 0 ? data : &kEmpty, num_bytes, SQLITE_STATIC),
      operation_);
}

bool SqliteStatement::Use::Step() const {
  const int rc = sqlite3_step(stmt_);
  if (rc == SQLITE_ROW) return true;
  if (rc == SQLITE_DONE) return false;
  connection_.Fail(rc, operation_);
}

int64_t SqliteStatement::Use::ColumnInt64(int column) const {
  return sqlite3_column_int64(stmt_, column);
}

bool SqliteStatement::Use::ColumnIsNull(int column) const {
  return sqlite3_column_type(stmt_, column) == SQLITE_NULL;
}

const char* SqliteStatement::Use::ColumnText(int column) const {
  return reinterpret_cast<const char*>(sqlite3_column_text(stmt_, column));
}

size_t SqliteStatement::Use::ColumnBytes(int column) const {
  return static_cast<size_t>(sqlite3_column_bytes(stmt_, column));
}

const void* SqliteStatement::Use::ColumnBlob(int column, size_t expected_bytes,
                                             const std::string& what) const {
  const size_t num_bytes = ColumnBytes(column);
  const void* data = sqlite3_column_blob(stmt_, column);
  if (num_bytes != expected_bytes) {
    throw InputError("Database '" + path().string() + "': " + what + " has " +
                     std::to_string(num_bytes) + " bytes of data, expected " +
                     std::to_string(expected_bytes) + ".");
  }
  return data;
}

void SqliteStatement::Use::CheckColumnArray(int column, int64_t rows, int64_t cols,
                                            size_t element_bytes, const std::string& what) const {
  const auto num_bytes = static_cast<uint64_t>(ColumnBytes(column));
  // rows x cols x element_bytes == num_bytes, tested without overflowing.
  const uint64_t max_rows = cols > 0 ? num_bytes / element_bytes / static_cast<uint64_t>(cols) : 0;
  const bool fits =
      rows >= 0 && cols >= 0 &&
      (rows == 0 || cols == 0
           ? num_bytes == 0
           : static_cast<uint64_t>(rows) <= max_rows &&
                 static_cast<uint64_t>(rows) * static_cast<uint64_t>(cols) * element_bytes ==
                     num_bytes);
  if (fits) return;
  throw InputError("Database '" + path().string() + "': " + what + " has " +
                   std::to_string(num_bytes) + " bytes of data, not " + std::to_string(rows) +
                   " x " + std::to_string(cols) + " elements of " + std::to_string(element_bytes) +
                   " bytes.");
}

}  // namespace tessera
