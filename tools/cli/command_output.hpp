#pragma once

#include <string>

namespace cdcr::cli {

// What a command hands back to main(). A command that refuses its input
// throws instead, before anything reaches stdout; `failure` is for results
// that are worth printing but still mean the request was not met (an
// unreachable IK target), so main() prints `text`, then `failure` as the
// error line, and exits with kExitInvalidInput.
struct CommandOutput {
  std::string text;
  std::string failure;
};

}  // namespace cdcr::cli
