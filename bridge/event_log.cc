#include "bridge/event_log.h"

#include <cstdio>
#include <cstring>

#include "bridge/lcm_link.h"
#include "bridge/mcap_reader.h"
#include "bridge/mcap_records.h"
#include "bridge/mcap_writer.h"
#include "scene/files.h"

namespace sandbox::bridge {

namespace {

bool EndsWith(const std::string& text, const std::string& end) {
  return text.size() >= end.size() && text.compare(text.size() - end.size(), end.size(), end) == 0;
}

bool StartsWithMcapMagic(const std::string& path) {
  // Regular files only: opening a FIFO would block (the readers say what it is).
  if (!scene::RegularFileProblem(path).empty()) return false;
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) return false;
  char magic[sizeof(mcap::kMagic)];
  const bool mcap = std::fread(magic, 1, sizeof(magic), file) == sizeof(magic) &&
                    std::memcmp(magic, mcap::kMagic, sizeof(magic)) == 0;
  std::fclose(file);
  return mcap;
}

}  // namespace

std::unique_ptr<EventWriter> OpenEventWriter(const std::string& path) {
  if (EndsWith(path, ".mcap")) return std::make_unique<McapWriter>(path);
  return std::make_unique<LogWriter>(path);
}

std::unique_ptr<EventReader> OpenEventReader(const std::string& path) {
  if (StartsWithMcapMagic(path)) return std::make_unique<McapReader>(path);
  return std::make_unique<LogReader>(path);
}
}  // namespace sandbox::bridge
