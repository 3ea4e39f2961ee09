#pragma once
// cdcr learning-curve: the paper's protocol (Table 3, Figs. 7-8) for one or
// both input encodings, as a table and two SVG plots.

#include "command_output.hpp"

namespace CLI {
class App;
}

namespace cdcr::cli {

void register_learning_curve_command(CLI::App& app, CommandOutput& output);

}  // namespace cdcr::cli
