#pragma once
// cdcr deploy: a model image to the runtime over SocketCAN, into its
// inactive flash slot (firmware/model_update.hpp), with a progress bar;
// resumes an interrupted transfer, and --status / --rollback.

#include <string>

#include "command_output.hpp"

namespace CLI {
class App;
}

namespace cdcr::cli {

struct DeployCommandOptions {
  std::string can_interface;
  std::string image_path;
  std::string id_base;  // "": the protocol's default
  bool status = false;
  bool rollback = false;
  double timeout_s = 120.0;  // without progress
  bool quiet = false;        // no progress bar
};

void register_deploy_command(CLI::App& app, CommandOutput& output);

CommandOutput run_deploy(const DeployCommandOptions& options);

}  // namespace cdcr::cli
