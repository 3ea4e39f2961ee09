#pragma once
// Flags shared by the commands that train GPs (train, learning-curve):
// input encoding, kernel form and the hyperparameter search.

#include <string>

#include "train/trainer.hpp"

namespace CLI {
class App;
}

namespace cdcr::cli {

struct TrainingFlags {
  // auto: the bend vector, with the cables' residuals when the evidence
  // says so (train/cable_inputs.hpp).
  std::string encoding = "auto";
  std::string kernel = "ard";
  int restarts = 2;
  unsigned long long seed = 1;
};

// with_encoding: whether the command takes a single --encoding.
void add_training_flags(CLI::App& command, TrainingFlags& flags, bool with_encoding = true);

// "auto" reads as the bend vector, the choice's starting point.
model::InputEncoding parse_encoding(const std::string& name);

// Throws InputError for out-of-range values.
training::TrainingOptions make_training_options(const TrainingFlags& flags);

}  // namespace cdcr::cli
