#include "bridge/reject_log.h"

namespace sandbox::bridge {

void RejectLog::Note(const std::string& source, const std::string& reason) {
  // Causes may quote what arrived: a bounded number are logged apart.
  std::string key = source + '\n' + reason;
  if (entries_.size() >= kMaxCauses && entries_.count(key) == 0) {
    key = source + "\nother reasons";
  }
  Entry& entry = entries_[key];
  const auto now = std::chrono::steady_clock::now();
  ++entry.unlogged;
  if (entry.logged && now - entry.last < std::chrono::seconds(1)) return;
  *out_ << "sandbox: " << key.substr(0, key.find('\n')) << ": rejected ("
        << key.substr(key.find('\n') + 1) << ")";
  if (entry.unlogged > 1) *out_ << " x" << entry.unlogged << " in the last second";
  *out_ << "\n";
  entry.logged = true;
  entry.last = now;
  entry.unlogged = 0;
}

}  // namespace sandbox::bridge
