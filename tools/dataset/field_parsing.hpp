#pragma once
// Field-level helpers shared by the text formats the dataset tools read (the
// dataset CSV and motion-capture exports): strict number parsing and quoting
// of offending input inside one-line error messages.

#include <charconv>
#include <cmath>
#include <cstddef>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

namespace cdcr::dataset::detail {

inline std::string_view trim_blanks(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

// Spreadsheet and capture software often prefix UTF-8 text with this mark.
inline constexpr std::string_view kUtf8ByteOrderMark = "\xEF\xBB\xBF";

// The fields of one line between `delimiter`s, each trimmed of blanks.
inline std::vector<std::string_view> split_fields(std::string_view line, char delimiter) {
  std::vector<std::string_view> fields;
  std::size_t start = 0;
  for (;;) {
    const std::size_t end = line.find(delimiter, start);
    fields.push_back(trim_blanks(line.substr(start, end == std::string_view::npos ? std::string_view::npos : end - start)));
    if (end == std::string_view::npos) break;
    start = end + 1;
  }
  return fields;
}

// Splits a text into lines at '\n'; a '\r' before it belongs to the line and
// is left for trim_blanks, so CRLF files read like LF files.
class LineReader {
 public:
  explicit LineReader(std::string_view text) : text_(text) {}

  bool next(std::string_view& line) {
    if (position_ >= text_.size()) return false;
    std::size_t end = text_.find('\n', position_);
    if (end == std::string_view::npos) end = text_.size();
    line = text_.substr(position_, end - position_);
    position_ = end + 1;
    ++number_;
    return true;
  }
  int number() const { return number_; }

 private:
  std::string_view text_;
  std::size_t position_ = 0;
  int number_ = 0;
};

// The field as it appears in a message: quoted, control bytes escaped so the
// message stays on one line, and long fields shortened.
inline std::string quoted(std::string_view field) {
  constexpr std::size_t kMaxShown = 40;
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out = "'";
  for (std::size_t i = 0; i < field.size() && i < kMaxShown; ++i) {
    const auto c = static_cast<unsigned char>(field[i]);
    if (c < 0x20 || c == 0x7f) {
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 0xf];
    } else {
      out += static_cast<char>(c);
    }
  }
  if (field.size() > kMaxShown) out += "...";
  out += '\'';
  return out;
}

enum class NumberStatus { ok, empty, not_a_number, out_of_range, not_finite };

// The whole field must be one decimal number (an optional leading '+' is
// allowed, as spreadsheets write it). NaN and Inf parse, but are reported as
// not_finite with the value set, so a caller can give them a meaning.
inline NumberStatus parse_decimal(std::string_view field, double& value) {
  if (field.empty()) return NumberStatus::empty;
  const char* begin = field.data();
  const char* const end = field.data() + field.size();
  if (*begin == '+') {
    ++begin;
    if (begin == end || *begin == '-' || *begin == '+') return NumberStatus::not_a_number;
  }
  const auto [ptr, ec] = std::from_chars(begin, end, value, std::chars_format::general);
  if (ec == std::errc::result_out_of_range && ptr == end) return NumberStatus::out_of_range;
  if (ec != std::errc() || ptr != end) return NumberStatus::not_a_number;
  return std::isfinite(value) ? NumberStatus::ok : NumberStatus::not_finite;
}

}  // namespace cdcr::dataset::detail
