#pragma once
// MCAP's building blocks (https://mcap.dev/spec, version 0), shared by the
// writer and the reader: the magic, record opcodes, little-endian fields,
// CRC-32 and chunk compression (zstd and lz4 frames from Debian's libraries).
// Debian packages no MCAP library for C++, so the format is written here;
// docs/reference/recordings.md says why and what of it is used.

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>

namespace sandbox::bridge::mcap {

inline constexpr char kMagic[8] = {'\x89', 'M', 'C', 'A', 'P', '0', '\r', '\n'};

enum Opcode : std::uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kStatistics = 0x0B,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};

// Bytes of a record's opcode and length.
inline constexpr std::size_t kRecordPrefix = 9;

std::uint32_t Crc32(std::string_view bytes, std::uint32_t crc = 0);

// Appends little-endian fields to a byte string.
class Builder {
 public:
  explicit Builder(std::string* out) : out_(*out) {}
  Builder& U8(std::uint8_t v) { return Int(v, 1); }
  Builder& U16(std::uint16_t v) { return Int(v, 2); }
  Builder& U32(std::uint32_t v) { return Int(v, 4); }
  Builder& U64(std::uint64_t v) { return Int(v, 8); }
  Builder& Bytes(std::string_view bytes) {
    out_.append(bytes);
    return *this;
  }
  Builder& String(std::string_view s) { return U32(std::uint32_t(s.size())).Bytes(s); }
  // Starts a record: its opcode and a length that EndRecord() fills in.
  std::size_t BeginRecord(Opcode op);
  void EndRecord(std::size_t begin);

 private:
  Builder& Int(std::uint64_t v, int n);
  std::string& out_;
};

// Reads little-endian fields from a span, refusing to read past its end
// (std::out_of_range naming the field).
class Cursor {
 public:
  explicit Cursor(std::string_view bytes) : bytes_(bytes) {}
  std::uint8_t U8(const char* field) { return std::uint8_t(Int(1, field)); }
  std::uint16_t U16(const char* field) { return std::uint16_t(Int(2, field)); }
  std::uint32_t U32(const char* field) { return std::uint32_t(Int(4, field)); }
  std::uint64_t U64(const char* field) { return Int(8, field); }
  std::string_view Bytes(std::uint64_t n, const char* field);
  std::string_view String(const char* field) { return Bytes(U32(field), field); }
  std::size_t offset() const { return at_; }
  std::size_t left() const { return bytes_.size() - at_; }

 private:
  std::uint64_t Int(int n, const char* field);
  std::string_view bytes_;
  std::size_t at_{0};
};

// Chunk compression: "zstd", "lz4" (a frame) or "" (none). Compress throws
// std::invalid_argument for another name; Decompress throws
// std::runtime_error when the data does not give exactly `size` bytes.
std::string Compress(const std::string& compression, std::string_view bytes);
std::string Decompress(const std::string& compression, std::string_view bytes, std::uint64_t size);

}  // namespace sandbox::bridge::mcap
