#pragma once
// Reads an MCAP file's LCM messages in the file's order, for replays and
// conversions: record by record from the start (the summary is not needed),
// checking every length against what is left of its record and of the file,
// the chunks' CRCs and the data section's CRC. A message on a channel whose
// encoding is not "lcm" is skipped and counted. Nothing is read past the end
// of the file, of a record or of a chunk; where reading stops and why is in
// stopped_early(): "damaged at byte 1234: the chunk's CRC is ..." (the offset
// is the top-level record's, in the file).

#include <cstdint>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "bridge/event_log.h"

namespace sandbox::bridge {

class McapReader final : public EventReader {
 public:
  // A record or a chunk's records larger than this stop the reading.
  static constexpr std::uint64_t kDefaultMaxRecordBytes = 256u << 20;

  // Throws std::runtime_error naming the file when it cannot be read, is not
  // a regular file or does not start with MCAP's magic and a header.
  explicit McapReader(const std::string& path,
                      std::uint64_t max_record_bytes = kDefaultMaxRecordBytes);
  ~McapReader() override;
  McapReader(const McapReader&) = delete;
  McapReader& operator=(const McapReader&) = delete;

  bool Next(std::string* channel, std::vector<std::uint8_t>* data, std::int64_t* utime) override;
  double fraction_read() const override;  // by bytes
  std::int64_t events() const override { return events_; }
  std::int64_t skipped() const override { return skipped_; }
  const std::string& stopped_early() const override { return stopped_early_; }

 private:
  struct Channel {
    std::string topic;
    bool lcm{false};
  };
  // Reads the next top-level record into record_; false at the data end or
  // when reading stops.
  bool ReadRecord(std::uint8_t* opcode);
  // Handles one record (top-level or a chunk's); true when it was a message
  // that Next() returns.
  bool Handle(std::uint8_t opcode, std::string_view body, std::string* channel,
              std::vector<std::uint8_t>* data, std::int64_t* utime);
  void OpenChunk(std::string_view body);
  void Stop(std::uint64_t offset, const std::string& why);

  std::string path_;
  std::uint64_t max_record_bytes_;
  std::FILE* file_{nullptr};
  std::uint64_t size_{1}, offset_{0};
  std::uint32_t data_crc_{0};
  std::string record_;  // the top-level record being read
  std::uint64_t record_offset_{0};
  std::string chunk_;  // the open chunk's records, decompressed
  std::size_t chunk_at_{0};
  std::map<std::uint16_t, Channel> channels_;
  bool ended_{false};
  std::int64_t events_{0}, skipped_{0};
  std::string stopped_early_;
};

}  // namespace sandbox::bridge
