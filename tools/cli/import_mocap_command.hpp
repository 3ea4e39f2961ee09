#pragma once
// cdcr import-mocap: commanded cable lengths + a QTM 6DOF capture of the base
// and end-platform rigid bodies -> dataset CSV with the measured end-platform
// pose in the base frame (eq. 21).

#include <string>

#include "command_output.hpp"

namespace CLI {
class App;
}

namespace cdcr::cli {

struct ImportMocapOptions {
  std::string cables_path;
  std::string mocap_path;
  std::string base_body;
  std::string end_body;
  std::string out_path;
  bool skip_lost = false;
};

void register_import_mocap_command(CLI::App& app, CommandOutput& output);

// Writes options.out_path; the returned text summarises what was imported.
CommandOutput run_import_mocap(const ImportMocapOptions& options);

}  // namespace cdcr::cli
