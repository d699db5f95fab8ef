// Fuzz target: the native LCM log reader (sandbox run --replay, topics --log)
// on any file: it reads events up to a clean end or says where it stopped;
// each event then goes through StatesAsInputs, as a replay's do (a STATE of
// robot "R" becomes its BONES and POSE, or is refused with a reason).

#include <sys/mman.h>
#include <unistd.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "bridge/lcm_link.h"
#include "bridge/recorded_states.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // The bytes as a file that lives in memory.
  const int fd = memfd_create("fuzz.lcmlog", 0);
  if (fd < 0 || write(fd, data, size) != ssize_t(size)) std::abort();
  const std::string path = "/proc/self/fd/" + std::to_string(fd);
  try {
    sandbox::bridge::LogReader log(path, 1u << 20);
    std::string channel;
    std::vector<std::uint8_t> event;
    std::int64_t utime = 0;
    sandbox::bridge::Translation ned{sandbox::bridge::Convention::kNed, {}};
    sandbox::bridge::StatesAsInputs states({{"R", ned, {}}});
    std::vector<sandbox::bridge::LogEvent> feed;
    while (log.Next(&channel, &event, &utime)) {
      feed.clear();
      const std::string refused = states.Translate(channel, event, &feed);
      if (refused.empty() == feed.empty()) std::abort();  // one of the two
    }
    if (log.fraction_read() < 0.0 || log.fraction_read() > 1.0) std::abort();
  } catch (const std::runtime_error&) {  // not an LCM log
  }
  close(fd);
  return 0;
}
