// Fuzz target: the MCAP reader (sandbox run --replay, convert, topics --log)
// on any file: it reads messages up to a clean end or says where it stopped,
// never past the end of the file, a record or a chunk.

#include <sys/mman.h>
#include <unistd.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "bridge/mcap_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // The bytes as a file that lives in memory.
  const int fd = memfd_create("fuzz.mcap", 0);
  if (fd < 0 || write(fd, data, size) != ssize_t(size)) std::abort();
  const std::string path = "/proc/self/fd/" + std::to_string(fd);
  try {
    sandbox::bridge::McapReader reader(path, 1u << 20);
    std::string channel;
    std::vector<std::uint8_t> message;
    std::int64_t utime = 0;
    std::int64_t read = 0;
    while (reader.Next(&channel, &message, &utime)) {
      if (message.size() > (1u << 20)) std::abort();  // within the reader's record limit
      ++read;
    }
    if (read != reader.events()) std::abort();
    if (reader.fraction_read() < 0.0 || reader.fraction_read() > 1.0) std::abort();
  } catch (const std::runtime_error&) {  // not an MCAP file
  }
  close(fd);
  return 0;
}
