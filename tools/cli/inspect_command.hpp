#pragma once
// cdcr inspect: everything inside a flash image (model/flash-image-v2.md, or
// a v1 image) and every check of the shared parser with its outcome. A
// damaged image is still shown as far as it can be read; the command then
// exits 1 with one error line naming the parser's status.

#include <string>

#include "command_output.hpp"

namespace CLI {
class App;
}

namespace cdcr::cli {

struct InspectCommandOptions {
  std::string model_path;
  bool json = false;
};

void register_inspect_command(CLI::App& app, CommandOutput& output);

CommandOutput run_inspect(const InspectCommandOptions& options);

}  // namespace cdcr::cli
