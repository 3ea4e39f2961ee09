#pragma once
// An MCAP file writer (https://mcap.dev/spec): the part of the format that a
// recording of the view needs, and what Foxglove, Lichtblick, PlotJuggler and
// `ros2 bag` read. Schemas and channels, messages in uncompressed chunks
// (each followed by its message indexes), and the summary: the schemas and
// channels again, the statistics and the chunk indexes, with the summary
// offsets, so a reader seeks to any time without reading the whole file.
// Every CRC is written. No maintained C++ MCAP library is packaged for
// Debian 12, so this is the project's; host_tests/tools/view checks it with
// the reference reader (@mcap/core).
//
// The file is written as FILE.tmp and renamed to FILE by close(): a run that
// stops early leaves no half file under the recording's name.

#include <cstdint>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

namespace cdcr::view {

class McapWriter {
 public:
  // Opens path.tmp; throws std::runtime_error (one line) when it cannot.
  explicit McapWriter(const std::string& path, const std::string& profile = "");
  ~McapWriter();  // an unclosed writer removes its temporary file
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  // A schema (encoding "jsonschema" for JSON messages); returns its id (> 0).
  std::uint16_t add_schema(const std::string& name, const std::string& encoding, const std::string& data);
  // A channel on a schema; returns its id.
  std::uint16_t add_channel(std::uint16_t schema_id, const std::string& topic, const std::string& message_encoding);
  void write_message(std::uint16_t channel_id, std::uint64_t log_time_ns, const std::string& data);
  // Writes the last chunk, the summary and the footer, and renames the file
  // into place. Throws std::runtime_error when a write fails.
  void close();

  std::uint64_t message_count() const { return message_count_; }

 private:
  struct ChunkIndex {
    std::uint64_t start_time = 0, end_time = 0, offset = 0, length = 0, uncompressed_size = 0;
    std::map<std::uint16_t, std::uint64_t> message_index_offsets;
    std::uint64_t message_index_length = 0;
  };
  struct Channel {
    std::uint16_t schema_id;
    std::string topic, encoding;
  };
  struct Schema {
    std::string name, encoding, data;
  };

  void write(const std::string& bytes);
  void flush_chunk();
  void write_summary_and_footer();
  std::string schema_record(std::size_t index) const;
  std::string channel_record(std::size_t index) const;
  std::string statistics_record() const;
  static std::string chunk_index_record(const ChunkIndex& index);

  std::string path_, temporary_path_;
  std::FILE* file_ = nullptr;
  std::uint64_t offset_ = 0;
  std::uint32_t data_crc_ = 0;
  std::vector<Schema> schemas_;
  std::vector<Channel> channels_;
  // The chunk being filled: its records, and per channel (log time, offset
  // in the chunk's records) of each message.
  std::string chunk_;
  std::uint64_t chunk_start_ = 0, chunk_end_ = 0;
  std::map<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>> chunk_messages_;
  std::vector<ChunkIndex> chunk_indexes_;
  std::map<std::uint16_t, std::uint64_t> channel_message_counts_;
  std::map<std::uint16_t, std::uint32_t> channel_sequences_;
  std::uint64_t message_count_ = 0, first_time_ = 0, last_time_ = 0;
};

}  // namespace cdcr::view
