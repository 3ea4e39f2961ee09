#include "intel_hex.hpp"

#include <algorithm>
#include <stdexcept>

namespace cdcr::exporting {

namespace {

constexpr std::uint8_t kRecordData = 0x00;
constexpr std::uint8_t kRecordEndOfFile = 0x01;
constexpr std::uint8_t kRecordExtendedLinearAddress = 0x04;

void append_hex_byte(std::string& out, std::uint8_t value) {
  constexpr char kDigits[] = "0123456789ABCDEF";
  out += kDigits[value >> 4];
  out += kDigits[value & 0x0F];
}

// ":LLAAAATT<data>CC": the checksum makes the sum of all record bytes zero
// modulo 256.
void append_record(std::string& out, std::uint8_t type, std::uint16_t address, const std::uint8_t* data,
                   std::size_t length) {
  const auto address_high = static_cast<std::uint8_t>(address >> 8);
  const auto address_low = static_cast<std::uint8_t>(address & 0xFF);
  std::uint8_t sum = static_cast<std::uint8_t>(length) + address_high + address_low + type;
  out += ':';
  append_hex_byte(out, static_cast<std::uint8_t>(length));
  append_hex_byte(out, address_high);
  append_hex_byte(out, address_low);
  append_hex_byte(out, type);
  for (std::size_t i = 0; i < length; ++i) {
    append_hex_byte(out, data[i]);
    sum = static_cast<std::uint8_t>(sum + data[i]);
  }
  append_hex_byte(out, static_cast<std::uint8_t>(0x100 - sum));
  out += '\n';
}

}  // namespace

std::string format_intel_hex(const std::uint8_t* bytes, std::size_t size, const IntelHexOptions& options) {
  if (options.bytes_per_record != 16 && options.bytes_per_record != 32) {
    throw std::invalid_argument("Intel HEX records must hold 16 or 32 bytes, not " +
                                std::to_string(options.bytes_per_record));
  }
  if (static_cast<std::uint64_t>(options.base_address) + size > (std::uint64_t{1} << 32)) {
    throw std::invalid_argument("Intel HEX data runs past the 32-bit address space");
  }

  std::string out;
  // Each data record is 11 characters of framing plus two per byte.
  out.reserve(size / static_cast<std::size_t>(options.bytes_per_record) * (11 + 2 * options.bytes_per_record + 1) +
              64);
  std::uint64_t upper_emitted = ~std::uint64_t{0};  // none yet: the first record sets it
  std::size_t at = 0;
  while (at < size) {
    const std::uint64_t address = options.base_address + static_cast<std::uint64_t>(at);
    const std::uint64_t upper = address >> 16;
    if (upper != upper_emitted) {
      const std::uint8_t upper_bytes[2] = {static_cast<std::uint8_t>(upper >> 8), static_cast<std::uint8_t>(upper)};
      append_record(out, kRecordExtendedLinearAddress, 0, upper_bytes, 2);
      upper_emitted = upper;
    }
    // Records start on multiples of their size in the target's address
    // space, so a listing lines up with flash rows and, the size dividing
    // 64 KiB, no record crosses a segment boundary.
    const auto record_bytes = static_cast<std::uint64_t>(options.bytes_per_record);
    const std::uint64_t to_record_end = record_bytes - address % record_bytes;
    const std::size_t length = static_cast<std::size_t>(std::min<std::uint64_t>(to_record_end, size - at));
    append_record(out, kRecordData, static_cast<std::uint16_t>(address & 0xFFFF), bytes + at, length);
    at += length;
  }
  append_record(out, kRecordEndOfFile, 0, nullptr, 0);
  return out;
}

}  // namespace cdcr::exporting
