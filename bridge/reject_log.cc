#include "bridge/reject_log.h"

namespace sandbox::bridge {

void RejectLog::Note(const std::string& source, const std::string& reason) {
  Entry& entry = entries_[source + '\n' + reason];
  const auto now = std::chrono::steady_clock::now();
  ++entry.unlogged;
  if (entry.logged && now - entry.last < std::chrono::seconds(1)) return;
  *out_ << "sandbox: " << source << ": rejected (" << reason << ")";
  if (entry.unlogged > 1) *out_ << " x" << entry.unlogged << " in the last second";
  *out_ << "\n";
  entry.logged = true;
  entry.last = now;
  entry.unlogged = 0;
}

}  // namespace sandbox::bridge
