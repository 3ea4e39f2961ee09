#include "training_options.hpp"

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "cli_errors.hpp"

namespace cdcr::cli {

void add_training_flags(CLI::App& command, TrainingFlags& flags, bool with_encoding) {
  if (with_encoding) {
    command
        .add_option("--encoding", flags.encoding,
                    "GP input encoding; auto: the bend vector, and the cables' residuals beside it where the "
                    "evidence keeps them (bend-vector+cable-fit)")
        ->check(CLI::IsMember({"auto", "bend-vector", "bend-vector+cable-fit", "joint-angles"}))
        ->capture_default_str();
  }
  command.add_option("--kernel", flags.kernel, "Length scales: one per input (ard) or one for all (isotropic, the paper's)")
      ->check(CLI::IsMember({"ard", "isotropic"}))
      ->capture_default_str();
  command.add_option("--restarts", flags.restarts, "Random restarts of the hyperparameter search")->capture_default_str();
  command.add_option("--seed", flags.seed, "Seed of the restarts and of the held-out split")->capture_default_str();
}

model::InputEncoding parse_encoding(const std::string& name) {
  if (name == "joint-angles") return model::InputEncoding::joint_angles;
  if (name == "bend-vector+cable-fit") return model::InputEncoding::bend_vector_cable_fit;
  return model::InputEncoding::bend_vector;
}

training::TrainingOptions make_training_options(const TrainingFlags& flags) {
  if (flags.restarts < 0 || flags.restarts > 100) {
    throw InputError(fmt::format("--restarts must be between 0 and 100 (got {})", flags.restarts));
  }
  training::TrainingOptions options;
  options.encoding = parse_encoding(flags.encoding);
  options.search.isotropic = flags.kernel == "isotropic";
  options.search.restarts = flags.restarts;
  options.search.seed = flags.seed;
  return options;
}

}  // namespace cdcr::cli
