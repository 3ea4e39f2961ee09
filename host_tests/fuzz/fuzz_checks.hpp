#pragma once
// Checks shared by the fuzz targets. A failed check aborts, which libFuzzer
// reports as a crash with the input that caused it.

#include <cstdlib>
#include <string>

namespace cdcr::fuzz {

inline void require(bool condition) {
  if (!condition) std::abort();
}

// A rejection (dataset::DatasetError) is one line, and names the input line
// where it has one.
template <typename LineError>
void check_rejection(const LineError& e) {
  const std::string what = e.what();
  require(e.line() >= 0);
  require(what.find_first_of("\r\n") == std::string::npos);
  if (e.line() > 0) require(what.rfind("line " + std::to_string(e.line()) + ": ", 0) == 0);
}

}  // namespace cdcr::fuzz
