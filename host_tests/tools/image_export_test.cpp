// The exporters in tools/export/, each checked by something that shares no
// code with it: Intel HEX is decoded by binutils' objcopy and its addresses
// read back by objdump; the C array is compiled by the host C and C++
// compilers, linked into a program that writes the bytes back out, and its
// section is read back by objdump.

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <ostream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cdcr/model/crc32.hpp"
#include "cdcr/model/flash_image.hpp"
#include "export/binary_file.hpp"
#include "export/c_source.hpp"
#include "export/image_writer.hpp"
#include "export/intel_hex.hpp"

#include "../support/synthetic_trained_model.hpp"
#include "test_work_dir.hpp"

namespace cdcr::exporting {
namespace {

namespace fs = std::filesystem;
using Bytes = std::vector<std::uint8_t>;

Bytes small_image() { return write_image(test_support::synthetic_trained_model()); }

// More than 64 KiB, so Intel HEX needs a second extended address record.
Bytes large_image() {
  test_support::SyntheticModelOptions options;
  options.training_points = 800;
  options.segments = 8;
  return write_image(test_support::synthetic_trained_model(options));
}

std::string read_text(const fs::path& path) {
  std::ifstream file(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>());
}

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  file << text;
}

struct CommandResult {
  int exit_code;
  std::string output;  // stdout and stderr together
};

CommandResult run(const std::string& command, const fs::path& log) {
  const int status = std::system((command + " > '" + log.string() + "' 2>&1").c_str());
  return {status, read_text(log)};
}

class ExportTest : public ::testing::Test {
 protected:
  void SetUp() override { dir = test_support::fresh_test_work_dir(); }
  fs::path dir;
};

// --- Intel HEX -------------------------------------------------------------------

struct HexRecord {
  int length;
  int address;
  int type;
  Bytes data;
};

// Only the framing; the decoding that matters is objcopy's.
std::vector<HexRecord> split_records(const std::string& text) {
  std::vector<HexRecord> records;
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line)) {
    EXPECT_EQ(line.front(), ':') << line;
    EXPECT_EQ(line.size() % 2, 1u) << line;
    Bytes raw;
    for (std::size_t i = 1; i + 1 < line.size(); i += 2) {
      raw.push_back(static_cast<std::uint8_t>(std::stoi(line.substr(i, 2), nullptr, 16)));
    }
    std::uint8_t sum = 0;
    for (std::uint8_t b : raw) sum = static_cast<std::uint8_t>(sum + b);
    EXPECT_EQ(sum, 0) << "checksum of " << line;
    EXPECT_EQ(raw.size(), raw[0] + 5u) << line;
    records.push_back({raw[0], raw[1] << 8 | raw[2], raw[3], Bytes(raw.begin() + 4, raw.end() - 1)});
  }
  return records;
}

struct HexCase {
  const char* name;
  std::uint32_t base_address;
  int bytes_per_record;
  bool large;
};

void PrintTo(const HexCase& c, std::ostream* os) { *os << c.name; }

class IntelHex : public ExportTest, public ::testing::WithParamInterface<HexCase> {};

TEST_P(IntelHex, ObjcopyDecodesTheImageAtItsAddress) {
#ifndef CDCR_OBJCOPY
  FAIL() << "objcopy not found: install binutils (build-essential), which CMake finds as CDCR_OBJCOPY";
#else
  const HexCase c = GetParam();
  const Bytes image = c.large ? large_image() : small_image();
  IntelHexOptions options;
  options.base_address = c.base_address;
  options.bytes_per_record = c.bytes_per_record;
  const std::string hex = format_intel_hex(image.data(), image.size(), options);
  write_text(dir / "image.hex", hex);

  // Framing: record sizes, one extended address record per 64 KiB segment
  // touched, data records inside one segment, EOF last.
  const std::vector<HexRecord> records = split_records(hex);
  ASSERT_FALSE(records.empty());
  EXPECT_EQ(records.back().type, 1);
  EXPECT_EQ(records.back().length, 0);
  std::uint64_t upper = 0;
  std::uint64_t expected_address = c.base_address;
  int extended_records = 0;
  for (std::size_t i = 0; i + 1 < records.size(); ++i) {
    const HexRecord& r = records[i];
    if (r.type == 4) {
      ASSERT_EQ(r.length, 2);
      upper = static_cast<std::uint64_t>(r.data[0] << 8 | r.data[1]);
      EXPECT_EQ(upper, expected_address >> 16);
      ++extended_records;
      continue;
    }
    ASSERT_EQ(r.type, 0);
    EXPECT_GE(r.length, 1);
    EXPECT_LE(r.length, c.bytes_per_record);
    EXPECT_EQ((upper << 16) | static_cast<std::uint64_t>(r.address), expected_address);
    EXPECT_LE(static_cast<std::uint64_t>(r.address) + static_cast<std::uint64_t>(r.length), 0x10000u);
    expected_address += static_cast<std::uint64_t>(r.length);
  }
  EXPECT_EQ(expected_address, c.base_address + image.size());
  const std::uint64_t last_byte = c.base_address + image.size() - 1;
  EXPECT_EQ(extended_records, static_cast<int>((last_byte >> 16) - (c.base_address >> 16) + 1));

  const std::string objcopy = CDCR_OBJCOPY;
  const CommandResult decoded = run("'" + objcopy + "' -I ihex -O binary '" + (dir / "image.hex").string() + "' '" +
                                        (dir / "image.bin").string() + "'",
                                    dir / "objcopy.log");
  ASSERT_EQ(decoded.exit_code, 0) << decoded.output;
  EXPECT_EQ(read_binary_file((dir / "image.bin").string()), image);

#ifdef CDCR_OBJDUMP
  // objcopy -O binary drops the addresses; objdump lists them. BFD starts a
  // section at every extended address record, so: sections back to back from
  // the base address, covering the image.
  const std::string objdump = CDCR_OBJDUMP;
  const CommandResult sections = run("'" + objdump + "' -h '" + (dir / "image.hex").string() + "'", dir / "objdump.log");
  ASSERT_EQ(sections.exit_code, 0) << sections.output;
  const std::regex section_row(R"(\.sec[0-9]+ +([0-9a-f]+) +([0-9a-f]+) +([0-9a-f]+))");
  std::uint64_t next_address = c.base_address;
  int section_count = 0;
  for (auto it = std::sregex_iterator(sections.output.begin(), sections.output.end(), section_row);
       it != std::sregex_iterator(); ++it) {
    const std::uint64_t section_size = std::stoull((*it)[1].str(), nullptr, 16);
    const std::uint64_t vma = std::stoull((*it)[2].str(), nullptr, 16);
    EXPECT_EQ(vma, next_address) << sections.output;
    next_address = vma + section_size;
    ++section_count;
  }
  EXPECT_EQ(section_count, extended_records) << sections.output;
  EXPECT_EQ(next_address, c.base_address + image.size()) << sections.output;
#endif
#endif
}

INSTANTIATE_TEST_SUITE_P(
    Addresses, IntelHex,
    ::testing::Values(HexCase{"at_zero", 0, 16, false}, HexCase{"flash_bank", 0x08040000u, 16, false},
                      HexCase{"flash_bank_32_byte_records", 0x08040000u, 32, false},
                      HexCase{"large_across_a_segment", 0x08040000u, 16, true},
                      HexCase{"large_32_byte_records", 0x08040000u, 32, true},
                      HexCase{"unaligned_base_across_a_segment", 0x0804FFF3u, 16, false},
                      HexCase{"unaligned_base_32_byte_records", 0x0804FFE5u, 32, true},
                      HexCase{"top_of_address_space", 0xFFFFFFFFu - 600u, 32, false}),
    [](const ::testing::TestParamInfo<HexCase>& info) { return std::string(info.param.name); });

TEST(IntelHexFormat, KnownRecords) {
  const std::uint8_t bytes[] = {0x00, 0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07,
                                0x08, 0x09, 0x0A, 0x0B, 0x0C, 0x0D, 0x0E, 0x0F, 0xFF};
  IntelHexOptions options;
  options.base_address = 0x08040000u;
  EXPECT_EQ(format_intel_hex(bytes, sizeof bytes, options),
            ":020000040804EE\n"
            ":10000000000102030405060708090A0B0C0D0E0F78\n"
            ":01001000FFF0\n"
            ":00000001FF\n");
}

TEST(IntelHexFormat, RefusesWhatItCannotEncode) {
  const Bytes image = small_image();
  IntelHexOptions options;
  options.bytes_per_record = 24;
  EXPECT_THROW(format_intel_hex(image.data(), image.size(), options), std::invalid_argument);
  options.bytes_per_record = 16;
  options.base_address = 0xFFFFFFFFu - 10u;
  EXPECT_THROW(format_intel_hex(image.data(), image.size(), options), std::invalid_argument);
}

// --- C array -----------------------------------------------------------------------

// Writes the array back out byte for byte and prints the size and the CRC-32
// of everything but the trailer, computed here independently.
constexpr const char* kDumpProgram = R"(#include <stdint.h>
#include <stdio.h>

extern const uint8_t SYMBOL[];
extern const uint32_t SYMBOL_size;

int main(int argc, char** argv) {
  FILE* out;
  uint32_t crc = 0xFFFFFFFFu;
  uint32_t i;
  int bit;
  if (argc != 2) return 2;
  out = fopen(argv[1], "wb");
  if (out == NULL || fwrite(SYMBOL, 1, SYMBOL_size, out) != SYMBOL_size || fclose(out) != 0) return 1;
  if (((uintptr_t)SYMBOL) % 8 != 0) return 3;
  for (i = 0; i + 4 < SYMBOL_size + 0u; ++i) {
    crc ^= SYMBOL[i];
    for (bit = 0; bit < 8; ++bit) crc = (crc >> 1) ^ ((crc & 1u) ? 0xEDB88320u : 0u);
  }
  printf("%lu %08lx\n", (unsigned long)SYMBOL_size, (unsigned long)~crc);
  return 0;
}
)";

std::string replace_all(std::string text, const std::string& from, const std::string& to) {
  for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size())) {
    text.replace(at, from.size(), to);
  }
  return text;
}

constexpr const char* kStrictC = " -std=c99 -Wall -Wextra -Wpedantic -Werror ";
constexpr const char* kStrictCxx = " -x c++ -std=c++17 -Wall -Wextra -Wpedantic -Werror ";

// Links dump.c against model<suffix>.o into dump<suffix> and runs it, which
// writes dumped<suffix>.bin; `printed` is what it printed.
void link_and_run_dump(const fs::path& dir, const std::string& suffix, std::string& printed) {
  const auto quoted = [](const fs::path& p) { return "'" + p.string() + "'"; };
  const fs::path program = dir / ("dump" + suffix);
  CommandResult r = run(std::string(CDCR_C_COMPILER) + kStrictC + quoted(dir / "dump.c") + " " +
                            quoted(dir / ("model" + suffix + ".o")) + " -o " + quoted(program),
                        dir / ("link" + suffix + ".log"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = run(quoted(program) + " " + quoted(dir / ("dumped" + suffix + ".bin")), dir / ("dump" + suffix + ".log"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  printed = r.output;
}

void expect_c_array_round_trip(const fs::path& dir, const Bytes& image, const CSourceOptions& options) {
  const std::string source = format_c_source(image.data(), image.size(), options);
  write_text(dir / "model.c", source);
  write_text(dir / "dump.c", replace_all(kDumpProgram, "SYMBOL", options.symbol));
  const std::string c_compiler = CDCR_C_COMPILER;
  const std::string cxx_compiler = CDCR_CXX_COMPILER;
  const auto quoted = [](const fs::path& p) { return "'" + p.string() + "'"; };

  // As C, and as C++: both without a single warning.
  CommandResult r = run(c_compiler + kStrictC + "-c " + quoted(dir / "model.c") + " -o " + quoted(dir / "model.o"),
                        dir / "cc.log");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output, "");
  r = run(cxx_compiler + kStrictCxx + "-c " + quoted(dir / "model.c") + " -o " + quoted(dir / "model_cxx.o"),
          dir / "cxx.log");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output, "");

  std::string printed;
  ASSERT_NO_FATAL_FAILURE(link_and_run_dump(dir, "", printed));
  char expected[64];
  std::snprintf(expected, sizeof expected, "%zu %08x\n", image.size(),
                model::crc32(image.data(), image.size() - model::kImageTrailerSize));
  EXPECT_EQ(printed, expected);
  EXPECT_EQ(read_binary_file((dir / "dumped.bin").string()), image);

  // The object compiled as C++ defines the same C symbols.
  ASSERT_NO_FATAL_FAILURE(link_and_run_dump(dir, "_cxx", printed));
  EXPECT_EQ(read_binary_file((dir / "dumped_cxx.bin").string()), image);

#ifdef CDCR_OBJDUMP
  // The array sits in its own section, 8-byte aligned, holding exactly the image.
  const std::string objdump = CDCR_OBJDUMP;
  r = run("'" + objdump + "' -h " + quoted(dir / "model.o"), dir / "objdump.log");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  char section_row[160];
  std::snprintf(section_row, sizeof section_row, "%s +%08zx +[0-9a-f]+ +[0-9a-f]+ +[0-9a-f]+ +2\\*\\*3",
                replace_all(options.section, ".", "\\.").c_str(), image.size());
  EXPECT_TRUE(std::regex_search(r.output, std::regex(section_row))) << r.output;
#endif
}

TEST_F(ExportTest, CArrayCompilesAsCAndCxxAndReproducesTheImage) {
  expect_c_array_round_trip(dir, small_image(), CSourceOptions{});
}

TEST_F(ExportTest, CArrayWithChosenSymbolAndSection) {
  CSourceOptions options;
  options.symbol = "robot_arm_model";
  options.section = ".flash_model.bank2";
  options.description = "from a file called */ weird\n name";
  expect_c_array_round_trip(dir, large_image(), options);
}

TEST(CArrayFormat, DeclaresWhatTheFirmwareLinksAgainst) {
  const Bytes image = small_image();
  const std::string source = format_c_source(image.data(), image.size(), CSourceOptions{});
  EXPECT_NE(source.find("const uint8_t cdcr_model_image[" + std::to_string(image.size()) +
                        "] __attribute__((aligned(8), section(\".cdcr_model\"))) = {"),
            std::string::npos);
  EXPECT_NE(source.find("const uint32_t cdcr_model_image_size = " + std::to_string(image.size()) + "u;"),
            std::string::npos);
  EXPECT_NE(source.find("extern \"C\""), std::string::npos);
}

TEST(CArrayFormat, RefusesBadNames) {
  const Bytes image = small_image();
  for (const char* symbol : {"", "1model", "model-image", "model image", "name$"}) {
    CSourceOptions options;
    options.symbol = symbol;
    EXPECT_THROW(format_c_source(image.data(), image.size(), options), std::invalid_argument) << symbol;
  }
  for (const char* section : {"", ".model\"", ".mo del", ".model\\n"}) {
    CSourceOptions options;
    options.section = section;
    EXPECT_THROW(format_c_source(image.data(), image.size(), options), std::invalid_argument) << section;
  }
}

// --- raw binary ----------------------------------------------------------------------

TEST_F(ExportTest, BinaryFileRoundTripAndReplacement) {
  const Bytes image = small_image();
  const std::string path = (dir / "model.img").string();
  write_text(path, std::string(5000, 'x'));  // longer than the image: must not survive
  write_binary_file(path, image.data(), image.size());
  EXPECT_EQ(read_binary_file(path), image);
  EXPECT_FALSE(fs::exists(path + ".partial"));
  EXPECT_THROW(read_binary_file((dir / "missing.img").string()), std::runtime_error);
  EXPECT_THROW(write_binary_file((dir / "no_such_dir" / "x.img").string(), image.data(), image.size()),
               std::runtime_error);
}

}  // namespace
}  // namespace cdcr::exporting
