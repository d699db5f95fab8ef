#pragma once
// Writes a run's LCM messages to an MCAP file (https://mcap.dev/spec): a
// header, chunks of records compressed with zstd or lz4, each followed by its
// message indexes, then the data end with the data section's CRC and a
// summary (schemas, channels, statistics, chunk indexes, summary offsets)
// with its own CRC. A channel's schema is the sandbox type's .lcm text
// (schema and message encoding "lcm"); a message of another type goes on a
// channel without a schema. Poses, face scans and lidar sweeps are also
// written as Foxglove's well-known schemas in JSON (foxglove_views.h).
//
// Threads: Write() copies the message into a queue and returns; a thread of
// the writer's takes the queue every kWritePeriod (sooner past kWakeBytes)
// and builds, compresses and writes the chunks. Write() waits only when over
// kMaxQueuedBytes are queued (the disk is slower than the run: nothing is
// dropped).

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <deque>
#include <map>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>
#include <tuple>
#include <utility>
#include <vector>

#include "bridge/event_log.h"

namespace sandbox::bridge {

class McapWriter final : public EventWriter {
 public:
  struct Options {
    std::string compression = "zstd";    // "zstd", "lz4" or "" (none)
    std::size_t chunk_bytes = 4u << 20;  // records a chunk holds before it is written
    // Also each pose, face scan and lidar sweep as Foxglove's FrameTransform
    // or PointCloud, on a channel of its own (bridge/foxglove_views.h).
    bool foxglove_views = true;
  };
  static constexpr std::size_t kMaxQueuedBytes = 256u << 20;
  static constexpr std::size_t kWakeBytes = 8u << 20;  // wakes the writer's thread early
  static constexpr std::chrono::milliseconds kWritePeriod{20};

  // Throws std::runtime_error naming the file when it cannot be opened for
  // writing (or is a FIFO, a socket or a folder), std::invalid_argument for
  // an unknown compression.
  explicit McapWriter(const std::string& path, Options options);
  explicit McapWriter(const std::string& path) : McapWriter(path, Options()) {}
  ~McapWriter() override;
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  bool Write(const std::string& channel, const void* data, unsigned size,
             std::int64_t utime) override;
  bool WriteInput(const std::string& channel, const void* data, unsigned size,
                  std::int64_t utime) override;
  bool WriteView(MakeView make, std::int64_t utime, std::size_t bytes) override;
  bool TakesViews() const override { return options_.foxglove_views; }
  bool TakesInputs() const override { return true; }
  bool Close() override;
  std::string error() const override;
  std::int64_t events() const override;

 private:
  struct Event {
    std::string channel;
    std::string data;
    std::int64_t utime;
    bool with_views{true};      // an LCM message's Foxglove views too (not for inputs)
    MakeView make;              // a view given as one (WriteView): made on the writer's thread
    std::size_t view_bytes{0};  // what `make` holds, counted against kMaxQueuedBytes
  };
  struct ChannelKey {
    std::string topic;
    std::uint16_t schema;
    bool operator<(const ChannelKey& o) const {
      return std::tie(schema, topic) < std::tie(o.schema, o.topic);
    }
  };

  bool Queue(Event event);
  void Run();  // the writer's thread
  void Add(const Event& event);
  void AddMessage(std::uint16_t channel, std::uint64_t time, std::string_view data);
  std::uint16_t SchemaId(const std::string& name, const std::string& encoding,
                         const std::string& text);
  std::uint16_t ChannelId(const std::string& topic, std::uint16_t schema,
                          const std::string& message_encoding);
  void FinishChunk();
  void Finish();  // data end, summary, footer, magic
  void Put(const std::string& bytes);
  void Fail(const std::string& why);

  const std::string path_;
  const Options options_;
  std::FILE* file_{nullptr};

  // Shared with the writer's thread.
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Event> queue_;
  std::size_t queued_bytes_{0};
  bool closing_{false};
  std::int64_t events_{0};
  std::string error_;
  std::atomic<bool> failed_{false};  // error_ is set (read without the lock)
  std::thread thread_;

  // The writer's thread only.
  std::uint64_t offset_{0};    // bytes written
  std::uint32_t data_crc_{0};  // of every byte before the data end
  std::string chunk_;          // the open chunk's records
  std::uint64_t chunk_start_{0}, chunk_end_{0};
  std::map<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>> chunk_index_;
  std::string schemas_, channels_, chunk_indexes_;  // the summary's groups
  std::map<std::string, std::uint16_t> schema_ids_;
  std::map<ChannelKey, std::uint16_t> channel_ids_;
  std::map<std::uint16_t, std::uint64_t> channel_counts_;
  std::map<std::uint16_t, std::uint32_t> sequence_;
  std::uint64_t messages_{0}, first_time_{0}, last_time_{0};
  std::uint32_t chunks_{0};
};

}  // namespace sandbox::bridge
