#pragma once
// cdcr eval: mean tip errors of a dataset before and after compensation by a
// flash image, computed by the firmware's own float32 path.

#include "command_output.hpp"

namespace CLI {
class App;
}

namespace cdcr::cli {

void register_eval_command(CLI::App& app, CommandOutput& output);

}  // namespace cdcr::cli
