#pragma once
// What the R5F test programs share: checks that name what failed on the
// UART, and the verdict main returns (PASS and 0, or the count of failed
// checks and 1), which run_r5f.cmake reads.

#include <cstdint>

#include <cdcr/zynqmp/console.hpp>

namespace cdcr::zynqmp_checks {

inline int failures = 0;

inline void check(bool condition, const char* what) {
  if (condition) return;
  failures += 1;
  zynqmp::console_write("FAIL: ");
  zynqmp::console_write(what);
  zynqmp::console_write("\n");
}

inline void check_equal(std::uint32_t actual, std::uint32_t expected, const char* what) {
  if (actual == expected) return;
  failures += 1;
  zynqmp::console_write("FAIL: ");
  zynqmp::console_write(what);
  zynqmp::console_write(": ");
  zynqmp::console_write_int(static_cast<std::int32_t>(actual));
  zynqmp::console_write(" instead of ");
  zynqmp::console_write_int(static_cast<std::int32_t>(expected));
  zynqmp::console_write("\n");
}

// One line of the report from text and integers, no printf:
// print("can0: ", dropped, " dropped\n").
inline void print_part(const char* text) { zynqmp::console_write(text); }
template <typename Integer>
void print_part(Integer value) {
  zynqmp::console_write_int(static_cast<std::int32_t>(value));
}
template <typename... Parts>
void print(const Parts&... parts) {
  (print_part(parts), ...);
}

inline int verdict() {
  if (failures != 0) {
    zynqmp::console_write_int(failures);
    zynqmp::console_write(" checks failed\n");
    return 1;
  }
  zynqmp::console_write("PASS\n");
  return 0;
}

}  // namespace cdcr::zynqmp_checks
