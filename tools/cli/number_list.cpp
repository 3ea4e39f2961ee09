#include "number_list.hpp"

#include <charconv>
#include <cmath>
#include <string>
#include <system_error>

#include <fmt/format.h>

#include "cli_errors.hpp"

namespace cdcr::cli {
namespace {

bool is_space(char c) { return c == ' ' || c == '\t'; }

std::string_view trim(std::string_view text) {
  while (!text.empty() && is_space(text.front())) text.remove_prefix(1);
  while (!text.empty() && is_space(text.back())) text.remove_suffix(1);
  return text;
}

double parse_value(std::string_view token, std::size_t position, std::string_view text,
                   std::string_view option_name) {
  if (token.empty()) {
    throw UsageError(fmt::format("{}: value {} is empty in '{}'", option_name, position, text));
  }
  // from_chars rejects a leading '+', which people do write for coordinates.
  std::string_view digits = token;
  if (digits.size() > 1 && digits.front() == '+' && digits[1] != '-') digits.remove_prefix(1);
  double value = 0.0;
  const char* const end = digits.data() + digits.size();
  const auto [stop, error] = std::from_chars(digits.data(), end, value);
  if (error == std::errc::result_out_of_range) {
    // Well-formed, so a bad value rather than a usage error, like nan and inf.
    throw InputError(fmt::format("{}: value {} ('{}') is out of the range of a double", option_name, position, token));
  }
  if (error != std::errc() || stop != end) {
    throw UsageError(fmt::format("{}: value {} ('{}') is not a number", option_name, position, token));
  }
  return value;
}

}  // namespace

std::vector<double> parse_number_list(std::string_view text, std::string_view option_name) {
  std::vector<double> values;
  if (trim(text).empty()) {
    throw UsageError(fmt::format("{}: expected a comma-separated list of numbers, got an empty string", option_name));
  }
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = text.find(',', start);
    const std::string_view token = trim(text.substr(start, comma == std::string_view::npos ? text.npos : comma - start));
    values.push_back(parse_value(token, values.size() + 1, text, option_name));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return values;
}

void require_finite(const std::vector<double>& values, std::string_view option_name) {
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i])) {
      throw InputError(fmt::format("{}: value {} is not finite ({})", option_name, i + 1, values[i]));
    }
  }
}

void require_count(const std::vector<double>& values, std::size_t count, std::string_view option_name,
                   std::string_view meaning) {
  if (values.size() != count) {
    throw InputError(
        fmt::format("{}: expected {} values ({}), got {}", option_name, count, meaning, values.size()));
  }
}

}  // namespace cdcr::cli
