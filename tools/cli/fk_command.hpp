#pragma once
// cdcr fk: cable lengths -> joint variables and tip pose (eqs. 2-5, 13).

#include <string>

#include "command_output.hpp"
#include "geometry_options.hpp"

namespace CLI {
class App;
}

namespace cdcr::cli {

struct FkCommandOptions {
  GeometryOptions geometry;
  std::string cables_mm;  // comma-separated, four per segment
  bool json = false;
};

// Adds the `fk` subcommand; when it is selected, parsing stores its result in `output`.
void register_fk_command(CLI::App& app, CommandOutput& output);

CommandOutput run_fk(const FkCommandOptions& options);

}  // namespace cdcr::cli
