#pragma once
// Recordings of a run's messages, whatever their file format: an LCM log
// (lcm-logger's) or an MCAP file, chosen by the file's name when writing and
// by its first bytes when reading. Threads: the caller's (a writer may keep a
// thread of its own behind Write()).

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "bridge/foxglove_views.h"

namespace sandbox::bridge {

// Events in, one at a time. Write errors are kept, not thrown: the first one
// stops the writing and error() says what happened.
class EventWriter {
 public:
  virtual ~EventWriter() = default;
  // Appends one event (the bytes are copied before it returns); false once
  // writing has failed.
  virtual bool Write(const std::string& channel, const void* data, unsigned size,
                     std::int64_t utime) = 0;
  // Appends an input the run received: as Write(), without the Foxglove views
  // (the robot's frame comes from its STATE, in the world's convention).
  virtual bool WriteInput(const std::string& channel, const void* data, unsigned size,
                          std::int64_t utime) {
    return Write(channel, data, size, utime);
  }
  // Appends a message in one of Foxglove's schemas that no LCM message
  // carries (a robot's link frames, a camera image, the scene), made by
  // `make` on the writer's own time from about `bytes` of data it holds;
  // formats without such channels (LCM logs) skip it and return true.
  virtual bool WriteView(MakeView /*make*/, std::int64_t /*utime*/, std::size_t /*bytes*/) {
    return true;
  }
  // Whether WriteView() keeps what it is given (the caller may skip making it).
  virtual bool TakesViews() const { return false; }
  // Whether the run's inputs go in too, beside what it publishes (MCAP: a
  // recording to review; an LCM log holds outputs alone, so that playing it
  // onto a network never drives another run).
  virtual bool TakesInputs() const { return false; }
  // Finishes the file; false when that or any earlier write failed.
  virtual bool Close() = 0;
  // Empty while everything was written, else what failed and where.
  virtual std::string error() const = 0;
  bool failed() const { return !error().empty(); }
  virtual std::int64_t events() const = 0;
};

// Events out, in the file's order, for replays and conversions.
class EventReader {
 public:
  virtual ~EventReader() = default;
  // The next event, or false at the end of the file or of its valid part.
  virtual bool Next(std::string* channel, std::vector<std::uint8_t>* data, std::int64_t* utime) = 0;
  // How far reading is, 0 .. 1.
  virtual double fraction_read() const = 0;
  virtual std::int64_t events() const = 0;   // read so far
  virtual std::int64_t skipped() const = 0;  // not LCM messages, or over the size limit
  // Empty after a clean end; otherwise where and why reading stopped.
  virtual const std::string& stopped_early() const = 0;
};

// An MCAP file for a name ending in ".mcap", else an LCM log. Throws
// std::runtime_error naming the file when it cannot be written.
std::unique_ptr<EventWriter> OpenEventWriter(const std::string& path);
// An MCAP reader when the file starts with MCAP's magic, else an LCM log
// reader. Throws std::runtime_error naming the file when it is neither.
std::unique_ptr<EventReader> OpenEventReader(const std::string& path);

}  // namespace sandbox::bridge
