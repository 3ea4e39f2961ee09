#include "c_source.hpp"

#include <cstring>
#include <stdexcept>

#include "cdcr/model/crc32.hpp"
#include "cdcr/model/flash_image.hpp"

namespace cdcr::exporting {

namespace {

constexpr std::size_t kBytesPerLine = 12;

bool is_identifier_start(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; }
bool is_identifier_char(char c) { return is_identifier_start(c) || (c >= '0' && c <= '9'); }

// Comment text: printable ASCII only, and nothing that ends the comment early.
std::string comment_safe(const std::string& text) {
  std::string out;
  for (char c : text) {
    const bool printable = c >= 0x20 && c < 0x7F;
    out += printable ? c : '?';
    if (out.size() >= 2 && out.compare(out.size() - 2, 2, "*/") == 0) out.back() = '_';
  }
  return out;
}

std::string hex_u32(std::uint32_t value) {
  constexpr char kDigits[] = "0123456789abcdef";
  std::string out = "0x";
  for (int shift = 28; shift >= 0; shift -= 4) out += kDigits[(value >> shift) & 0xF];
  return out;
}

}  // namespace

bool is_c_identifier(const std::string& name) {
  if (name.empty() || !is_identifier_start(name.front())) return false;
  for (char c : name) {
    if (!is_identifier_char(c)) return false;
  }
  return true;
}

bool is_section_name(const std::string& name) {
  if (name.empty()) return false;
  for (char c : name) {
    if (c <= 0x20 || c >= 0x7F || c == '"' || c == '\\') return false;
  }
  return true;
}

std::string format_c_source(const std::uint8_t* bytes, std::size_t size, const CSourceOptions& options) {
  if (!is_c_identifier(options.symbol)) {
    throw std::invalid_argument("symbol '" + options.symbol + "' is not a C identifier");
  }
  if (!is_section_name(options.section)) {
    throw std::invalid_argument("section '" + options.section +
                                "' must be non-empty printable ASCII without spaces, quotes or backslashes");
  }
  if (size == 0 || size > 0xFFFFFFFFu) throw std::invalid_argument("image size does not fit a uint32_t size symbol");

  const std::string& name = options.symbol;
  const std::string count = std::to_string(size);
  std::string out;
  out.reserve(size * 6 + 1024);
  // The bytes are exported as they are, so the comment names their version.
  std::uint16_t version_major = 0;
  if (size >= model::image_field::version_major.offset + 2) {
    std::memcpy(&version_major, bytes + model::image_field::version_major.offset, 2);
  }
  const std::string version = std::to_string(version_major);
  out += "/* Trained CDCR compensation model, flash image v" + version + " (model/flash-image-v" + version + ".md).\n";
  if (!options.description.empty()) out += " * " + comment_safe(options.description) + "\n";
  if (size >= 4) {
    out += " * " + count + " bytes, CRC-32 " + hex_u32(model::crc32(bytes, size - 4)) + " (of all but the trailer).\n";
  }
  out += " *\n";
  out += " * Generated file. The array lives in section \"" + options.section + "\": the firmware's\n";
  out += " * linker script must place that section (KEEP() it if --gc-sections is used).\n";
  out += " */\n";
  out += "#include <stdint.h>\n\n";
  out += "#ifdef __cplusplus\nextern \"C\" {\n#endif\n";
  out += "extern const uint8_t " + name + "[];\n";
  out += "extern const uint32_t " + name + "_size;\n";
  out += "#ifdef __cplusplus\n}\n#endif\n\n";
  out += "const uint8_t " + name + "[" + count + "] __attribute__((aligned(8), section(\"" + options.section +
         "\"))) = {\n";
  constexpr char kDigits[] = "0123456789abcdef";
  for (std::size_t i = 0; i < size; ++i) {
    if (i % kBytesPerLine == 0) out += "   ";
    out += " 0x";
    out += kDigits[bytes[i] >> 4];
    out += kDigits[bytes[i] & 0xF];
    if (i + 1 < size) out += ',';
    if (i % kBytesPerLine == kBytesPerLine - 1 || i + 1 == size) out += '\n';
  }
  out += "};\n";
  out += "const uint32_t " + name + "_size = " + count + "u;\n";
  return out;
}

}  // namespace cdcr::exporting
