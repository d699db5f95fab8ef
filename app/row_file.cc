#include "app/row_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace sandbox::app {

RowFile::RowFile(const std::string& path, const std::string& header) : path_(path) {
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) throw std::runtime_error("cannot create " + path + ": " + std::strerror(errno));
  Add(header);
  if (!Flush()) {
    ::close(fd_);
    throw std::runtime_error(error_);
  }
}

RowFile::~RowFile() {
  Flush();
  ::close(fd_);
}

void RowFile::Add(const std::string& row) {
  pending_ += row;
  pending_ += '\n';
  ++pending_rows_;
}

bool RowFile::Flush() {
  std::size_t written = 0;
  while (written < pending_.size()) {
    const ssize_t n = ::write(fd_, pending_.data() + written, pending_.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      // Cut back to the last whole row; these rows are lost.
      if (error_.empty())
        error_ = "cannot write " + path_ + ": " + std::strerror(errno ? errno : EIO);
      if (::ftruncate(fd_, whole_bytes_) != 0 || ::lseek(fd_, whole_bytes_, SEEK_SET) < 0) {
        // The file keeps a cut row; nothing more can be done about it here.
      }
      lost_rows_ += std::int64_t(pending_rows_);
      pending_.clear();
      pending_rows_ = 0;
      return false;
    }
    written += std::size_t(n);
  }
  whole_bytes_ += std::int64_t(pending_.size());
  pending_.clear();
  pending_rows_ = 0;
  return true;
}

}  // namespace sandbox::app
