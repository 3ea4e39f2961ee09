#pragma once
// cdcr train: measured dataset -> trained GP -> flash image, with held-out
// accuracy and the float32 fidelity of the exported image.

#include "command_output.hpp"

namespace CLI {
class App;
}

namespace cdcr::cli {

void register_train_command(CLI::App& app, CommandOutput& output);

}  // namespace cdcr::cli
