// SPDX-License-Identifier: BSD-3-Clause
// One sqlite3 file and its statements, for the rosbag2 reader and writer
// (src/io/rosbag2.cpp, src/io/rosbag2_writer.cpp); internal, not installed.
#pragma once

#include <sqlite3.h>

#include <cstdint>
#include <string>
#include <vector>

#include "radargauss/core/error.hpp"

namespace radargauss {

// One sqlite3 database and its statements; every failure
// becomes a DataError naming the file.
class Database {
 public:
  Database(const std::string& path, int flags) : path_(path) {
    if (sqlite3_open_v2(path.c_str(), &db_, flags, nullptr) != SQLITE_OK) Fail("cannot open sqlite3 file");
  }
  ~Database() { sqlite3_close(db_); }
  Database(const Database&) = delete;
  Database& operator=(const Database&) = delete;

  class Statement {
   public:
    Statement(Database& db, const std::string& sql) : db_(db) {
      if (sqlite3_prepare_v2(db.db_, sql.c_str(), -1, &statement_, nullptr) != SQLITE_OK) db.Fail("sqlite3");
    }
    ~Statement() { sqlite3_finalize(statement_); }
    Statement(const Statement&) = delete;
    Statement& operator=(const Statement&) = delete;
    bool Step() {
      const int status = sqlite3_step(statement_);
      if (status == SQLITE_ROW) return true;
      if (status != SQLITE_DONE) db_.Fail("sqlite3");
      return false;
    }
    void Bind(int index, std::int64_t value) { sqlite3_bind_int64(statement_, index, value); }
    void Bind(int index, const std::string& text) {
      sqlite3_bind_text(statement_, index, text.data(), int(text.size()), SQLITE_TRANSIENT);
    }
    void Bind(int index, const std::vector<std::uint8_t>& blob) {
      sqlite3_bind_blob64(statement_, index, blob.data(), blob.size(), SQLITE_STATIC);
    }
    void Reset() {
      sqlite3_reset(statement_);
      sqlite3_clear_bindings(statement_);
    }
    std::int64_t Int(int column) const { return sqlite3_column_int64(statement_, column); }
    std::string Text(int column) const {
      const unsigned char* text = sqlite3_column_text(statement_, column);
      return text ? std::string(reinterpret_cast<const char*>(text),
                                std::size_t(sqlite3_column_bytes(statement_, column)))
                  : std::string();
    }
    const std::uint8_t* Blob(int column, std::size_t& size) const {
      const void* blob = sqlite3_column_blob(statement_, column);
      size = std::size_t(sqlite3_column_bytes(statement_, column));
      return static_cast<const std::uint8_t*>(blob);
    }

   private:
    Database& db_;
    sqlite3_stmt* statement_ = nullptr;
  };

  void Execute(const std::string& sql) {
    if (sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, nullptr) != SQLITE_OK) Fail("sqlite3");
  }
  [[noreturn]] void Fail(const std::string& what) const {
    throw FileError(path_, what + ": " + (db_ ? sqlite3_errmsg(db_) : "out of memory"));
  }
  bool HasTable(const std::string& name) {
    Statement query(*this, "SELECT count(*) FROM sqlite_master WHERE type='table' AND name='" + name + "'");
    return query.Step() && query.Int(0) > 0;
  }

 private:
  std::string path_;
  sqlite3* db_ = nullptr;
};

}  // namespace radargauss
