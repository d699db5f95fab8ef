#include "bridge/mcap_records.h"

#include <lz4frame.h>
#include <zlib.h>
#include <zstd.h>

#include <memory>

namespace sandbox::bridge::mcap {

std::uint32_t Crc32(std::string_view bytes, std::uint32_t crc) {
  // zlib's CRC-32 is MCAP's (ISO-HDLC), in pieces of at most 1 GiB (uInt).
  while (!bytes.empty()) {
    const std::size_t n = std::min<std::size_t>(bytes.size(), 1u << 30);
    crc = std::uint32_t(crc32(crc, reinterpret_cast<const Bytef*>(bytes.data()), uInt(n)));
    bytes.remove_prefix(n);
  }
  return crc;
}

Builder& Builder::Int(std::uint64_t v, int n) {
  for (int i = 0; i < n; ++i, v >>= 8) out_.push_back(char(v & 0xff));
  return *this;
}

std::size_t Builder::BeginRecord(Opcode op) {
  U8(op);
  const std::size_t begin = out_.size();
  U64(0);
  return begin;
}

void Builder::EndRecord(std::size_t begin) {
  std::uint64_t length = out_.size() - begin - 8;
  for (int i = 0; i < 8; ++i, length >>= 8) out_[begin + i] = char(length & 0xff);
}

std::uint64_t Cursor::Int(int n, const char* field) {
  if (left() < std::size_t(n)) {
    throw std::out_of_range(std::string(field) + " runs past its record's end");
  }
  std::uint64_t v = 0;
  for (int i = n - 1; i >= 0; --i) v = v << 8 | std::uint8_t(bytes_[at_ + i]);
  at_ += n;
  return v;
}

std::string_view Cursor::Bytes(std::uint64_t n, const char* field) {
  if (left() < n) {
    throw std::out_of_range(std::string(field) + " says " + std::to_string(n) +
                            " bytes, its record has " + std::to_string(left()) + " left");
  }
  const std::string_view bytes = bytes_.substr(at_, n);
  at_ += n;
  return bytes;
}

std::string Compress(const std::string& compression, std::string_view bytes) {
  if (compression.empty()) return std::string(bytes);
  if (compression == "zstd") {
    std::string out(ZSTD_compressBound(bytes.size()), '\0');
    const std::size_t n = ZSTD_compress(out.data(), out.size(), bytes.data(), bytes.size(), 3);
    if (ZSTD_isError(n)) throw std::runtime_error(std::string("zstd: ") + ZSTD_getErrorName(n));
    out.resize(n);
    return out;
  }
  if (compression == "lz4") {
    LZ4F_preferences_t preferences{};
    preferences.frameInfo.contentSize = bytes.size();
    std::string out(LZ4F_compressFrameBound(bytes.size(), &preferences), '\0');
    const std::size_t n =
        LZ4F_compressFrame(out.data(), out.size(), bytes.data(), bytes.size(), &preferences);
    if (LZ4F_isError(n)) throw std::runtime_error(std::string("lz4: ") + LZ4F_getErrorName(n));
    out.resize(n);
    return out;
  }
  throw std::invalid_argument("no compression '" + compression + "' (zstd, lz4 or none)");
}

std::string Decompress(const std::string& compression, std::string_view bytes, std::uint64_t size) {
  if (compression.empty()) {
    if (bytes.size() != size) {
      throw std::runtime_error("an uncompressed chunk of " + std::to_string(bytes.size()) +
                               " bytes says " + std::to_string(size));
    }
    return std::string(bytes);
  }
  std::string out(size, '\0');
  if (compression == "zstd") {
    const std::size_t n = ZSTD_decompress(out.data(), out.size(), bytes.data(), bytes.size());
    if (ZSTD_isError(n)) throw std::runtime_error(std::string("zstd: ") + ZSTD_getErrorName(n));
    if (n != size) {
      throw std::runtime_error("zstd gave " + std::to_string(n) + " bytes, the chunk says " +
                               std::to_string(size));
    }
    return out;
  }
  if (compression == "lz4") {
    LZ4F_dctx* raw = nullptr;
    if (LZ4F_isError(LZ4F_createDecompressionContext(&raw, LZ4F_VERSION))) {
      throw std::runtime_error("lz4: no decompression context");
    }
    const std::unique_ptr<LZ4F_dctx, decltype(&LZ4F_freeDecompressionContext)> context(
        raw, &LZ4F_freeDecompressionContext);
    std::size_t written = 0, read = 0;
    for (;;) {
      std::size_t out_n = out.size() - written, in_n = bytes.size() - read;
      const std::size_t hint = LZ4F_decompress(context.get(), out.data() + written, &out_n,
                                               bytes.data() + read, &in_n, nullptr);
      if (LZ4F_isError(hint))
        throw std::runtime_error(std::string("lz4: ") + LZ4F_getErrorName(hint));
      written += out_n;
      read += in_n;
      if (hint == 0) break;  // the frame is whole
      if (out_n == 0 && in_n == 0) {
        throw std::runtime_error("lz4: the frame needs more than the chunk's " +
                                 std::to_string(size) + " bytes or is cut short");
      }
    }
    if (written != size) {
      throw std::runtime_error("lz4 gave " + std::to_string(written) + " bytes, the chunk says " +
                               std::to_string(size));
    }
    return out;
  }
  throw std::runtime_error("unknown compression '" + compression + "'");
}

}  // namespace sandbox::bridge::mcap
