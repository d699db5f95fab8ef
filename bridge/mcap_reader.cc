#include "bridge/mcap_reader.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>

#include "bridge/mcap_records.h"
#include "scene/files.h"

namespace sandbox::bridge {

namespace {

std::uint64_t LittleEndian(const unsigned char* bytes, int n) {
  std::uint64_t v = 0;
  for (int i = n - 1; i >= 0; --i) v = v << 8 | bytes[i];
  return v;
}

}  // namespace

McapReader::McapReader(const std::string& path, std::uint64_t max_record_bytes)
    : path_(path), max_record_bytes_(max_record_bytes) {
  if (const std::string problem = scene::RegularFileProblem(path); !problem.empty()) {
    throw std::runtime_error("cannot read the MCAP file '" + path + "': " + problem);
  }
  file_ = std::fopen(path.c_str(), "rb");
  if (file_ == nullptr) throw std::runtime_error("cannot read the MCAP file '" + path + "'");
  size_ = std::max<std::uint64_t>(1, scene::FileBytes(path));
  char magic[sizeof(mcap::kMagic)];
  std::uint8_t opcode = 0;
  const bool has_magic = std::fread(magic, 1, sizeof(magic), file_) == sizeof(magic) &&
                         std::memcmp(magic, mcap::kMagic, sizeof(magic)) == 0;
  if (has_magic) {
    offset_ = sizeof(magic);
    data_crc_ = mcap::Crc32(std::string_view(magic, sizeof(magic)));
  }
  if (!has_magic || !ReadRecord(&opcode) || opcode != mcap::kHeader) {
    std::fclose(file_);
    file_ = nullptr;
    throw std::runtime_error("'" + path + "' is not an MCAP file: " +
                             (!has_magic               ? std::string("no MCAP magic at byte 0")
                              : stopped_early_.empty() ? "the record at byte 8 is not a header"
                                                       : stopped_early_));
  }
}

McapReader::~McapReader() {
  if (file_ != nullptr) std::fclose(file_);
}

void McapReader::Stop(std::uint64_t offset, const std::string& why) {
  if (stopped_early_.empty()) {
    stopped_early_ = "damaged at byte " + std::to_string(offset) + ": " + why;
  }
  chunk_.clear();
  chunk_at_ = 0;
}

bool McapReader::ReadRecord(std::uint8_t* opcode) {
  if (ended_ || !stopped_early_.empty()) return false;
  record_offset_ = offset_;
  const std::uint64_t left = size_ - std::min(size_, offset_);
  unsigned char prefix[mcap::kRecordPrefix];
  if (left == 0) {
    Stop(offset_, "the file ends without a data end record (cut short)");
    return false;
  }
  if (left < sizeof(prefix) || std::fread(prefix, 1, sizeof(prefix), file_) != sizeof(prefix)) {
    Stop(offset_, "a record cut short (" + std::to_string(left) + " bytes left)");
    return false;
  }
  *opcode = prefix[0];
  const std::uint64_t length = LittleEndian(prefix + 1, 8);
  if (length > left - sizeof(prefix)) {
    Stop(offset_, "a record of " + std::to_string(length) + " bytes, the file has " +
                      std::to_string(left - sizeof(prefix)) + " left");
    return false;
  }
  if (length > max_record_bytes_) {
    Stop(offset_, "a record of " + std::to_string(length) + " bytes, over the limit of " +
                      std::to_string(max_record_bytes_));
    return false;
  }
  record_.resize(length);
  if (std::fread(record_.data(), 1, length, file_) != length) {
    Stop(offset_, "the file ends inside a record");
    return false;
  }
  offset_ += sizeof(prefix) + length;
  if (*opcode == mcap::kDataEnd) {
    ended_ = true;
    try {
      mcap::Cursor cursor(record_);
      const std::uint32_t crc = cursor.U32("the data section's CRC");
      if (crc != 0 && crc != data_crc_) {
        Stop(record_offset_, "the data section's CRC is " + std::to_string(data_crc_) +
                                 ", the data end says " + std::to_string(crc));
      }
    } catch (const std::out_of_range& e) {
      Stop(record_offset_, e.what());
    }
    return false;
  }
  data_crc_ =
      mcap::Crc32(std::string_view(reinterpret_cast<char*>(prefix), sizeof(prefix)), data_crc_);
  data_crc_ = mcap::Crc32(record_, data_crc_);
  return true;
}

void McapReader::OpenChunk(std::string_view body) {
  try {
    mcap::Cursor cursor(body);
    cursor.U64("message_start_time");
    cursor.U64("message_end_time");
    const std::uint64_t size = cursor.U64("uncompressed_size");
    const std::uint32_t crc = cursor.U32("uncompressed_crc");
    const std::string compression(cursor.String("compression"));
    const std::string_view records = cursor.Bytes(cursor.U64("records length"), "records");
    if (size > max_record_bytes_) {
      return Stop(record_offset_, "a chunk of " + std::to_string(size) +
                                      " bytes uncompressed, over the limit of " +
                                      std::to_string(max_record_bytes_));
    }
    chunk_ = mcap::Decompress(compression, records, size);
    chunk_at_ = 0;
    if (crc != 0 && mcap::Crc32(chunk_) != crc) {
      Stop(record_offset_, "the chunk's CRC is " + std::to_string(mcap::Crc32(chunk_)) +
                               ", it says " + std::to_string(crc));
    }
  } catch (const std::exception& e) {  // a field past the end, a bad compressed stream
    Stop(record_offset_, std::string("chunk: ") + e.what());
  }
}

bool McapReader::Handle(std::uint8_t opcode, std::string_view body, std::string* channel,
                        std::vector<std::uint8_t>* data, std::int64_t* utime) {
  mcap::Cursor cursor(body);
  if (opcode == mcap::kChannel) {
    const std::uint16_t id = cursor.U16("channel id");
    cursor.U16("schema id");
    const std::string topic(cursor.String("topic"));
    const std::string encoding(cursor.String("message_encoding"));
    channels_[id] = Channel{topic, encoding == "lcm"};
    return false;
  }
  if (opcode != mcap::kMessage) return false;  // schemas, indexes, statistics, unknown records
  const std::uint16_t id = cursor.U16("channel id");
  cursor.U32("sequence");
  const std::uint64_t log_time = cursor.U64("log_time");
  cursor.U64("publish_time");
  const auto found = channels_.find(id);
  if (found == channels_.end()) {
    throw std::out_of_range("a message on channel " + std::to_string(id) +
                            ", which no channel record before it declares");
  }
  if (!found->second.lcm) {
    ++skipped_;
    return false;
  }
  const std::string_view bytes = cursor.Bytes(cursor.left(), "data");
  *channel = found->second.topic;
  data->assign(bytes.begin(), bytes.end());
  *utime = std::int64_t(log_time / 1000);
  ++events_;
  return true;
}

bool McapReader::Next(std::string* channel, std::vector<std::uint8_t>* data, std::int64_t* utime) {
  for (;;) {
    if (!stopped_early_.empty()) return false;
    if (chunk_at_ < chunk_.size()) {  // the open chunk's next record
      const std::size_t at = chunk_at_;
      const std::string where =
          "the chunk's record at byte " + std::to_string(at) + " of its records";
      try {
        mcap::Cursor cursor(std::string_view(chunk_).substr(at));
        const std::uint8_t opcode = cursor.U8("opcode");
        const std::string_view body = cursor.Bytes(cursor.U64("record length"), "record");
        chunk_at_ += mcap::kRecordPrefix + body.size();
        if (Handle(opcode, body, channel, data, utime)) return true;
      } catch (const std::out_of_range& e) {
        Stop(record_offset_, where + ": " + e.what());
      }
      continue;
    }
    std::uint8_t opcode = 0;
    if (!ReadRecord(&opcode)) return false;
    if (opcode == mcap::kChunk) {
      OpenChunk(record_);
      continue;
    }
    try {
      if (Handle(opcode, record_, channel, data, utime)) return true;
    } catch (const std::out_of_range& e) {
      Stop(record_offset_, e.what());
    }
  }
}

double McapReader::fraction_read() const {
  if (ended_ && stopped_early_.empty()) return 1.0;  // the summary after the data is not read
  return std::min(1.0, double(offset_) / double(size_));
}

}  // namespace sandbox::bridge
