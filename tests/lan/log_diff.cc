// Compares the messages of two LCM log files on the channels a regular
// expression matches: the same channels, the same payloads in the same order
// (event times and numbers aside). Exit 0 when identical.
//
//   log_diff A.lcmlog B.lcmlog CHANNEL_REGEX

#include <cstdio>
#include <lcm/lcm-cpp.hpp>
#include <regex>
#include <string>
#include <vector>

namespace {

struct Event {
  std::string channel;
  std::vector<unsigned char> data;
};

bool Read(const char* path, const std::regex& channels, std::vector<Event>* events) {
  lcm::LogFile log(path, "r");
  if (!log.good()) {
    std::fprintf(stderr, "log_diff: cannot read '%s'\n", path);
    return false;
  }
  while (const lcm::LogEvent* event = log.readNextEvent()) {
    if (!std::regex_match(event->channel, channels)) continue;
    const auto* bytes = static_cast<const unsigned char*>(event->data);
    events->push_back({event->channel, {bytes, bytes + event->datalen}});
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: log_diff A.lcmlog B.lcmlog CHANNEL_REGEX\n");
    return 2;
  }
  const std::regex channels(argv[3]);
  std::vector<Event> a, b;
  if (!Read(argv[1], channels, &a) || !Read(argv[2], channels, &b)) return 2;
  std::size_t same = 0;
  while (same < a.size() && same < b.size() && a[same].channel == b[same].channel &&
         a[same].data == b[same].data) {
    ++same;
  }
  if (same == a.size() && same == b.size()) {
    std::printf("log_diff: %zu messages on '%s', byte-identical\n", same, argv[3]);
    return 0;
  }
  std::printf("log_diff: %zu and %zu messages on '%s'; the first %zu are identical\n", a.size(),
              b.size(), argv[3], same);
  return 1;
}
