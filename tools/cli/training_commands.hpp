#pragma once
// The commands on measured data, each registered with the CLI by main():
//   cdcr train           measured dataset -> trained GP -> flash image, with
//                        held-out accuracy and the float32 fidelity of the image
//   cdcr eval            mean tip errors of a dataset before and after
//                        compensation by a flash image, computed by the
//                        firmware's own float32 path
//   cdcr learning-curve  the paper's protocol (Table 3, Figs. 7-8) for one or
//                        both input encodings, as a table and two SVG plots

#include "command_output.hpp"

namespace CLI {
class App;
}

namespace cdcr::cli {

void register_train_command(CLI::App& app, CommandOutput& output);
void register_eval_command(CLI::App& app, CommandOutput& output);
void register_learning_curve_command(CLI::App& app, CommandOutput& output);

}  // namespace cdcr::cli
