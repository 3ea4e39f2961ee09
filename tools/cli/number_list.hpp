#pragma once
// Comma-separated number lists such as --cables 118,123,124,115.

#include <cstddef>
#include <string_view>
#include <vector>

namespace cdcr::cli {

// Parses "v1,v2,...". Spaces around a value are allowed; empty values
// ("1,,2", a trailing comma) and anything that is not a whole number token
// ("abc", "1.2.3") throw UsageError naming the option and the position.
// nan and inf are accepted here so that require_finite can report them as
// invalid values rather than as a syntax error; a number beyond the range of
// a double throws InputError for the same reason.
std::vector<double> parse_number_list(std::string_view text, std::string_view option_name);

// Throws InputError naming the first NaN or Inf value.
void require_finite(const std::vector<double>& values, std::string_view option_name);

// Throws InputError unless the list has exactly `count` values.
void require_count(const std::vector<double>& values, std::size_t count, std::string_view option_name,
                   std::string_view meaning);

}  // namespace cdcr::cli
