#include "bridge/mcap_writer.h"

#include <sys/stat.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "bridge/foxglove_views.h"
#include "bridge/lcm_types.h"
#include "bridge/mcap_records.h"

namespace sandbox::bridge {

using mcap::Builder;

namespace {

// The summary's group of one opcode, for its summary offset record.
struct Group {
  mcap::Opcode opcode;
  std::size_t start, length;  // in the summary
};

}  // namespace

McapWriter::McapWriter(const std::string& path, Options options)
    : path_(path), options_(std::move(options)) {
  if (options_.compression != "zstd" && options_.compression != "lz4" &&
      !options_.compression.empty()) {
    throw std::invalid_argument("MCAP: no compression '" + options_.compression +
                                "' (zstd, lz4 or none)");
  }
  // Regular files and character devices (/dev/null) only: a FIFO blocks.
  struct stat info {};
  if (::stat(path.c_str(), &info) == 0 && !S_ISREG(info.st_mode) && !S_ISCHR(info.st_mode)) {
    throw std::runtime_error("cannot write the MCAP file '" + path + "': not a regular file");
  }
  file_ = std::fopen(path.c_str(), "wb");
  if (file_ == nullptr) {
    throw std::runtime_error("cannot write the MCAP file '" + path + "': " + std::strerror(errno));
  }
  std::string start(mcap::kMagic, sizeof(mcap::kMagic));
  Builder b(&start);
  const std::size_t header = b.BeginRecord(mcap::kHeader);
  b.String("").String("sandbox");  // no well-known profile; the library
  b.EndRecord(header);
  Put(start);
  thread_ = std::thread(&McapWriter::Run, this);
}

McapWriter::~McapWriter() { Close(); }

bool McapWriter::Write(const std::string& channel, const void* data, unsigned size,
                       std::int64_t utime) {
  return Queue({channel, std::string(static_cast<const char*>(data), size), utime, true, {}});
}

bool McapWriter::WriteInput(const std::string& channel, const void* data, unsigned size,
                            std::int64_t utime) {
  return Queue({channel, std::string(static_cast<const char*>(data), size), utime, false, {}});
}

bool McapWriter::WriteView(MakeView make, std::int64_t utime, std::size_t bytes) {
  if (!options_.foxglove_views) return true;
  return Queue({{}, {}, utime, false, std::move(make), bytes});
}

bool McapWriter::Queue(Event event) {
  const std::size_t bytes = event.data.size() + event.channel.size() + event.view_bytes;
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait(lock, [&] { return queued_bytes_ < kMaxQueuedBytes || closing_; });
  if (closing_ || !error_.empty()) return false;
  queue_.push_back(std::move(event));
  queued_bytes_ += bytes;
  ++events_;
  // The writer's thread looks every kWritePeriod: no wake-up (a system call)
  // a message unless much is waiting.
  if (queued_bytes_ >= kWakeBytes) changed_.notify_all();
  return true;
}

bool McapWriter::Close() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    closing_ = true;
    changed_.notify_all();
  }
  if (thread_.joinable()) thread_.join();
  if (file_ != nullptr) {
    errno = 0;
    if (std::fclose(file_) != 0) Fail(std::strerror(errno != 0 ? errno : EIO));
    file_ = nullptr;
  }
  return error().empty();
}

std::string McapWriter::error() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return error_;
}

std::int64_t McapWriter::events() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return events_;
}

void McapWriter::Run() {
  std::deque<Event> events;
  for (bool closing = false; !closing;) {
    {
      std::unique_lock<std::mutex> lock(mutex_);
      changed_.wait_for(lock, kWritePeriod,
                        [&] { return queued_bytes_ >= kWakeBytes || closing_; });
      closing = closing_;
      events.swap(queue_);  // everything waiting, at once
      queued_bytes_ = 0;
      changed_.notify_all();  // a Write() waiting for room
    }
    for (const Event& event : events) Add(event);
    events.clear();
  }
  Finish();
}

std::uint16_t McapWriter::SchemaId(const std::string& name, const std::string& encoding,
                                   const std::string& text) {
  const auto [it, added] = schema_ids_.emplace(name, std::uint16_t(schema_ids_.size() + 1));
  if (added) {
    for (std::string* out : {&chunk_, &schemas_}) {
      Builder b(out);
      const std::size_t record = b.BeginRecord(mcap::kSchema);
      b.U16(it->second).String(name).String(encoding).String(text);
      b.EndRecord(record);
    }
  }
  return it->second;
}

std::uint16_t McapWriter::ChannelId(const std::string& topic, std::uint16_t schema,
                                    const std::string& message_encoding) {
  const auto [it, added] =
      channel_ids_.emplace(ChannelKey{topic, schema}, std::uint16_t(channel_ids_.size() + 1));
  if (added) {
    for (std::string* out : {&chunk_, &channels_}) {
      Builder b(out);
      const std::size_t record = b.BeginRecord(mcap::kChannel);
      b.U16(it->second).U16(schema).String(topic).String(message_encoding).U32(0);  // no metadata
      b.EndRecord(record);
    }
  }
  return it->second;
}

void McapWriter::Add(const Event& event) {
  if (failed_) return;
  // Room for the message's channel and its views' (two more at most).
  if (channel_ids_.size() > 0xffff - 3 || schema_ids_.size() > 0xffff - 3) {
    return Fail("over 65532 channels or schemas");
  }
  const std::uint64_t time = std::uint64_t(event.utime) * 1000;  // nanoseconds
  if (event.make) {                                              // a view given as one
    const FoxgloveView view = event.make();
    const std::uint16_t schema = SchemaId(view.schema_name, "jsonschema", *view.schema);
    AddMessage(ChannelId(view.topic, schema, "json"), time, view.json);
    if (chunk_.size() >= options_.chunk_bytes) FinishChunk();
    return;
  }
  const auto* bytes = reinterpret_cast<const std::uint8_t*>(event.data.data());
  const LcmType* type = LcmTypeOf(bytes, event.data.size());
  const std::uint16_t schema = type ? SchemaId(type->full_name(), "lcm", type->schema) : 0;
  AddMessage(ChannelId(event.channel, schema, "lcm"), time, event.data);
  if (options_.foxglove_views && event.with_views) {
    for (const FoxgloveView& view : FoxgloveViewsOf(event.channel, bytes, event.data.size())) {
      const std::uint16_t view_schema = SchemaId(view.schema_name, "jsonschema", *view.schema);
      AddMessage(ChannelId(view.topic, view_schema, "json"), time, view.json);
    }
  }
  if (chunk_.size() >= options_.chunk_bytes) FinishChunk();
}

void McapWriter::AddMessage(std::uint16_t channel, std::uint64_t time, std::string_view data) {
  if (chunk_index_.empty()) chunk_start_ = chunk_end_ = time;  // the chunk's first message
  chunk_index_[channel].emplace_back(time, chunk_.size());
  Builder b(&chunk_);
  const std::size_t record = b.BeginRecord(mcap::kMessage);
  b.U16(channel).U32(sequence_[channel]++).U64(time).U64(time).Bytes(data);
  b.EndRecord(record);
  if (messages_ == 0 || time < first_time_) first_time_ = time;
  if (messages_ == 0 || time > last_time_) last_time_ = time;
  chunk_start_ = std::min(chunk_start_, time);
  chunk_end_ = std::max(chunk_end_, time);
  ++messages_;
  ++channel_counts_[channel];
}

void McapWriter::FinishChunk() {
  if (chunk_.empty()) return;
  std::string compressed;
  try {
    compressed = mcap::Compress(options_.compression, chunk_);
  } catch (const std::exception& e) {
    return Fail(e.what());
  }
  std::string out;
  Builder b(&out);
  const std::size_t record = b.BeginRecord(mcap::kChunk);
  b.U64(chunk_start_).U64(chunk_end_).U64(chunk_.size()).U32(mcap::Crc32(chunk_));
  b.String(options_.compression).U64(compressed.size()).Bytes(compressed);
  b.EndRecord(record);
  const std::uint64_t chunk_offset = offset_, chunk_length = out.size();
  std::map<std::uint16_t, std::uint64_t> index_offsets;
  for (const auto& [channel, entries] : chunk_index_) {
    index_offsets[channel] = chunk_offset + out.size();
    const std::size_t index = b.BeginRecord(mcap::kMessageIndex);
    b.U16(channel).U32(std::uint32_t(entries.size() * 16));
    for (const auto& [time, at] : entries) b.U64(time).U64(at);
    b.EndRecord(index);
  }
  Put(out);

  Builder s(&chunk_indexes_);
  const std::size_t chunk_index = s.BeginRecord(mcap::kChunkIndex);
  s.U64(chunk_start_).U64(chunk_end_).U64(chunk_offset).U64(chunk_length);
  s.U32(std::uint32_t(index_offsets.size() * 10));
  for (const auto& [channel, at] : index_offsets) s.U16(channel).U64(at);
  s.U64(out.size() - chunk_length).String(options_.compression);
  s.U64(compressed.size()).U64(chunk_.size());
  s.EndRecord(chunk_index);

  ++chunks_;
  chunk_.clear();
  chunk_index_.clear();
}

void McapWriter::Finish() {
  FinishChunk();
  std::string end;
  Builder e(&end);
  const std::size_t data_end = e.BeginRecord(mcap::kDataEnd);
  e.U32(data_crc_);
  e.EndRecord(data_end);
  Put(end);

  const std::uint64_t summary_start = offset_;
  std::string summary;
  std::vector<Group> groups;
  const auto group = [&](mcap::Opcode opcode, const std::string& records) {
    if (records.empty()) return;
    groups.push_back({opcode, summary.size(), records.size()});
    summary += records;
  };
  group(mcap::kSchema, schemas_);
  group(mcap::kChannel, channels_);
  std::string statistics;
  Builder st(&statistics);
  const std::size_t record = st.BeginRecord(mcap::kStatistics);
  st.U64(messages_).U16(std::uint16_t(schema_ids_.size())).U32(std::uint32_t(channel_ids_.size()));
  st.U32(0).U32(0).U32(chunks_);  // no attachments, no metadata
  st.U64(first_time_).U64(last_time_).U32(std::uint32_t(channel_counts_.size() * 10));
  for (const auto& [channel, count] : channel_counts_) st.U16(channel).U64(count);
  st.EndRecord(record);
  group(mcap::kStatistics, statistics);
  group(mcap::kChunkIndex, chunk_indexes_);

  const std::uint64_t offsets_start = summary_start + summary.size();
  Builder b(&summary);
  for (const Group& g : groups) {
    const std::size_t offset = b.BeginRecord(mcap::kSummaryOffset);
    b.U8(g.opcode).U64(summary_start + g.start).U64(g.length);
    b.EndRecord(offset);
  }
  b.U8(mcap::kFooter).U64(20).U64(summary_start).U64(offsets_start);
  b.U32(mcap::Crc32(summary));  // from the summary's start through the footer's offsets
  b.Bytes(std::string_view(mcap::kMagic, sizeof(mcap::kMagic)));
  Put(summary);
  errno = 0;
  if (file_ != nullptr && std::fflush(file_) != 0) Fail(std::strerror(errno != 0 ? errno : EIO));
}

void McapWriter::Put(const std::string& bytes) {
  if (file_ == nullptr || failed_) return;
  errno = 0;
  if (std::fwrite(bytes.data(), 1, bytes.size(), file_) != bytes.size()) {
    return Fail(std::strerror(errno != 0 ? errno : EIO));
  }
  data_crc_ = mcap::Crc32(bytes, data_crc_);
  offset_ += bytes.size();
}

void McapWriter::Fail(const std::string& why) {
  std::lock_guard<std::mutex> lock(mutex_);
  failed_ = true;
  if (error_.empty()) {
    error_ =
        "cannot write '" + path_ + "' after " + std::to_string(messages_) + " messages: " + why;
  }
  changed_.notify_all();
}

}  // namespace sandbox::bridge
