#include "view/mcap_writer.hpp"

#include <cerrno>
#include <cstring>
#include <stdexcept>

#include <cdcr/model/crc32.hpp>

namespace cdcr::view {

namespace {

constexpr char kMagic[] = "\x89MCAP0\r\n";
constexpr std::size_t kMagicSize = 8;
// A chunk closes at this many bytes of records: a reader seeking to a time
// reads at most about this much before the message it wants.
constexpr std::size_t kChunkBytes = 1 << 20;

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

// The format's fields, little-endian.
void put(std::string& out, std::uint64_t value, int bytes) {
  for (int i = 0; i < bytes; ++i) out.push_back(static_cast<char>((value >> (8 * i)) & 0xFFu));
}
void put8(std::string& out, std::uint8_t v) { put(out, v, 1); }
void put16(std::string& out, std::uint16_t v) { put(out, v, 2); }
void put32(std::string& out, std::uint32_t v) { put(out, v, 4); }
void put64(std::string& out, std::uint64_t v) { put(out, v, 8); }
void put_string(std::string& out, const std::string& s) {
  put32(out, static_cast<std::uint32_t>(s.size()));
  out += s;
}

std::string record(Opcode opcode, const std::string& content) {
  std::string out;
  put8(out, opcode);
  put64(out, content.size());
  return out + content;
}

std::uint32_t crc(const std::string& bytes, std::uint32_t previous = 0) {
  return model::crc32(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size(), previous);
}

}  // namespace

McapWriter::McapWriter(const std::string& path, const std::string& profile)
    : path_(path), temporary_path_(path + ".tmp") {
  file_ = std::fopen(temporary_path_.c_str(), "wb");
  if (file_ == nullptr) throw std::runtime_error("cannot write " + temporary_path_ + ": " + std::strerror(errno));
  write(std::string(kMagic, kMagicSize));
  std::string header;
  put_string(header, profile);
  put_string(header, "cdcr");
  write(record(kHeader, header));
}

McapWriter::~McapWriter() {
  if (file_ != nullptr) {
    std::fclose(file_);
    std::remove(temporary_path_.c_str());
  }
}

void McapWriter::write(const std::string& bytes) {
  if (bytes.empty()) return;
  if (std::fwrite(bytes.data(), 1, bytes.size(), file_) != bytes.size()) {
    throw std::runtime_error("cannot write " + temporary_path_ + ": " + std::strerror(errno));
  }
  offset_ += bytes.size();
  data_crc_ = crc(bytes, data_crc_);
}

std::uint16_t McapWriter::add_schema(const std::string& name, const std::string& encoding, const std::string& data) {
  schemas_.push_back({name, encoding, data});
  write(schema_record(schemas_.size() - 1));
  return static_cast<std::uint16_t>(schemas_.size());
}

std::uint16_t McapWriter::add_channel(std::uint16_t schema_id, const std::string& topic,
                                      const std::string& message_encoding) {
  if (schema_id == 0 || schema_id > schemas_.size()) throw std::invalid_argument("MCAP channel on an unknown schema");
  channels_.push_back({schema_id, topic, message_encoding});
  write(channel_record(channels_.size() - 1));
  return static_cast<std::uint16_t>(channels_.size());
}

void McapWriter::write_message(std::uint16_t channel_id, std::uint64_t log_time_ns, const std::string& data) {
  if (channel_id == 0 || channel_id > channels_.size()) throw std::invalid_argument("MCAP message on an unknown channel");
  std::string content;
  put16(content, channel_id);
  put32(content, channel_sequences_[channel_id]++);
  put64(content, log_time_ns);
  put64(content, log_time_ns);  // published when logged: the view stamps what it saw
  content += data;
  if (chunk_.empty()) chunk_start_ = chunk_end_ = log_time_ns;
  chunk_start_ = std::min(chunk_start_, log_time_ns);
  chunk_end_ = std::max(chunk_end_, log_time_ns);
  chunk_messages_[channel_id].emplace_back(log_time_ns, chunk_.size());
  chunk_ += record(kMessage, content);
  if (message_count_ == 0) first_time_ = last_time_ = log_time_ns;
  first_time_ = std::min(first_time_, log_time_ns);
  last_time_ = std::max(last_time_, log_time_ns);
  ++message_count_;
  ++channel_message_counts_[channel_id];
  if (chunk_.size() >= kChunkBytes) flush_chunk();
}

void McapWriter::flush_chunk() {
  if (chunk_.empty()) return;
  ChunkIndex index;
  index.start_time = chunk_start_;
  index.end_time = chunk_end_;
  index.offset = offset_;
  index.uncompressed_size = chunk_.size();
  std::string content;
  put64(content, chunk_start_);
  put64(content, chunk_end_);
  put64(content, chunk_.size());
  put32(content, crc(chunk_));
  put_string(content, "");  // uncompressed: any reader reads it without a codec
  put64(content, chunk_.size());
  content += chunk_;
  const std::string chunk_record = record(kChunk, content);
  index.length = chunk_record.size();
  write(chunk_record);
  const std::uint64_t indexes_start = offset_;
  for (const auto& [channel, entries] : chunk_messages_) {
    index.message_index_offsets[channel] = offset_;
    std::string message_index;
    put16(message_index, channel);
    put32(message_index, static_cast<std::uint32_t>(entries.size() * 16));
    for (const auto& [time, offset] : entries) {
      put64(message_index, time);
      put64(message_index, offset);
    }
    write(record(kMessageIndex, message_index));
  }
  index.message_index_length = offset_ - indexes_start;
  chunk_indexes_.push_back(index);
  chunk_.clear();
  chunk_messages_.clear();
}

void McapWriter::close() {
  if (file_ == nullptr) return;
  flush_chunk();
  std::string data_end;
  put32(data_end, data_crc_);  // every byte before the Data End record
  write(record(kDataEnd, data_end));

  write_summary_and_footer();

  std::FILE* file = file_;
  file_ = nullptr;
  if (std::fclose(file) != 0) {
    std::remove(temporary_path_.c_str());
    throw std::runtime_error("cannot write " + temporary_path_ + ": " + std::strerror(errno));
  }
  if (std::rename(temporary_path_.c_str(), path_.c_str()) != 0) {
    std::remove(temporary_path_.c_str());
    throw std::runtime_error("cannot rename " + temporary_path_ + " to " + path_ + ": " + std::strerror(errno));
  }
}

// The records of the summary (and, for schemas and channels, of the data
// section too), as the specification lays them out.
std::string McapWriter::schema_record(std::size_t index) const {
  std::string content;
  put16(content, static_cast<std::uint16_t>(index + 1));
  put_string(content, schemas_[index].name);
  put_string(content, schemas_[index].encoding);
  put_string(content, schemas_[index].data);
  return record(kSchema, content);
}

std::string McapWriter::channel_record(std::size_t index) const {
  std::string content;
  put16(content, static_cast<std::uint16_t>(index + 1));
  put16(content, channels_[index].schema_id);
  put_string(content, channels_[index].topic);
  put_string(content, channels_[index].encoding);
  put32(content, 0);  // no metadata
  return record(kChannel, content);
}

std::string McapWriter::statistics_record() const {
  std::string content;
  put64(content, message_count_);
  put16(content, static_cast<std::uint16_t>(schemas_.size()));
  put32(content, static_cast<std::uint32_t>(channels_.size()));
  put32(content, 0);  // attachments
  put32(content, 0);  // metadata
  put32(content, static_cast<std::uint32_t>(chunk_indexes_.size()));
  put64(content, first_time_);
  put64(content, last_time_);
  put32(content, static_cast<std::uint32_t>(channel_message_counts_.size() * 10));
  for (const auto& [channel, count] : channel_message_counts_) {
    put16(content, channel);
    put64(content, count);
  }
  return record(kStatistics, content);
}

std::string McapWriter::chunk_index_record(const ChunkIndex& index) {
  std::string content;
  put64(content, index.start_time);
  put64(content, index.end_time);
  put64(content, index.offset);
  put64(content, index.length);
  put32(content, static_cast<std::uint32_t>(index.message_index_offsets.size() * 10));
  for (const auto& [channel, offset] : index.message_index_offsets) {
    put16(content, channel);
    put64(content, offset);
  }
  put64(content, index.message_index_length);
  put_string(content, "");
  put64(content, index.uncompressed_size);  // compressed size: stored as is
  put64(content, index.uncompressed_size);
  return record(kChunkIndex, content);
}

// The summary: one group per record kind, each found by its offset record,
// then the footer (its CRC over the summary and itself) and the magic.
void McapWriter::write_summary_and_footer() {
  const std::uint64_t summary_start = offset_;
  std::uint32_t summary_crc = 0;
  const auto write_summary = [&](const std::string& r) {
    write(r);
    summary_crc = crc(r, summary_crc);
  };
  std::vector<std::string> offsets;
  const auto write_group = [&](Opcode opcode, std::size_t count, const auto& record_at) {
    if (count == 0) return;
    const std::uint64_t start = offset_;
    for (std::size_t i = 0; i < count; ++i) write_summary(record_at(i));
    std::string content;
    put8(content, opcode);
    put64(content, start);
    put64(content, offset_ - start);
    offsets.push_back(record(kSummaryOffset, content));
  };
  write_group(kSchema, schemas_.size(), [this](std::size_t i) { return schema_record(i); });
  write_group(kChannel, channels_.size(), [this](std::size_t i) { return channel_record(i); });
  write_group(kStatistics, 1, [this](std::size_t) { return statistics_record(); });
  write_group(kChunkIndex, chunk_indexes_.size(), [this](std::size_t i) { return chunk_index_record(chunk_indexes_[i]); });
  const std::uint64_t summary_offset_start = offset_;
  for (const std::string& r : offsets) write_summary(r);
  std::string footer;
  put8(footer, kFooter);
  put64(footer, 8 + 8 + 4);
  put64(footer, summary_start);
  put64(footer, summary_offset_start);
  summary_crc = crc(footer, summary_crc);
  put32(footer, summary_crc);
  write(footer);
  write(std::string(kMagic, kMagicSize));
}

}  // namespace cdcr::view
