#pragma once
// The two ways a command can refuse its input. main() turns each into one
// line on stderr and its exit code, so scripts can tell a mistyped command
// line (fix the call) from well-formed values the model rejects (fix the data).

#include <stdexcept>

namespace cdcr::cli {

inline constexpr int kExitSuccess = 0;
inline constexpr int kExitInvalidInput = 1;
inline constexpr int kExitUsage = 2;

// The command line itself is malformed: unknown flag, missing target,
// unparsable number list. Exit code kExitUsage.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The command line parses but its values are unusable: wrong count, NaN,
// cables the model rejects, an unreachable target. Exit code kExitInvalidInput.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace cdcr::cli
