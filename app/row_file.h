#pragma once
// A text file written row by row (CSV indexes and statistics) that stays
// whole on a full disk: rows wait in memory until Flush(); a flush that
// cannot be written is cut off again, so the file always ends after its last
// whole row, and its rows are counted as lost. Writing goes on when there is
// room again. Threads: one writer at a time.

#include <cstdint>
#include <string>

namespace sandbox::app {

class RowFile {
 public:
  // Creates (truncates) `path` and writes `header` (a row without its '\n').
  // Throws std::runtime_error naming the file when it cannot be created.
  RowFile(const std::string& path, const std::string& header);
  ~RowFile();
  RowFile(const RowFile&) = delete;
  RowFile& operator=(const RowFile&) = delete;

  // A row without its '\n'; written at the next Flush().
  void Add(const std::string& row);
  std::size_t pending_rows() const { return pending_rows_; }
  // Writes the waiting rows; false when they could not be written (lost).
  bool Flush();

  const std::string& path() const { return path_; }
  std::int64_t lost_rows() const { return lost_rows_; }
  const std::string& error() const { return error_; }  // the first failure; empty: none

 private:
  std::string path_;
  int fd_{-1};
  std::int64_t whole_bytes_{0};  // the file's size after its last whole row
  std::string pending_;
  std::size_t pending_rows_{0};
  std::int64_t lost_rows_{0};
  std::string error_;
};

}  // namespace sandbox::app
