// cdcr: command-line front end of the kinematic model.
//
// Exit codes: 0 success, 1 invalid input (the model or a check refused the
// values, or an IK target was not reached), 2 usage error. Every failure is
// exactly one line on stderr, so scripts can show it verbatim.

#include <cstdio>
#include <exception>
#include <iostream>
#include <string>

#include <CLI/CLI.hpp>

#include "cli/bus_command.hpp"
#include "cli/cli_errors.hpp"
#include "cli/command_output.hpp"
#include "cli/fk_command.hpp"
#if CDCR_HAVE_DEPLOY
#include "cli/deploy_command.hpp"
#include "cli/view_command.hpp"
#endif
#include "cli/ik_command.hpp"
#include "cli/training_commands.hpp"
#include "cli/import_mocap_command.hpp"
#include "cli/inspect_command.hpp"
#include "cli/export_command.hpp"
#include "cli/simulate_command.hpp"

namespace {

// Library messages occasionally span lines; the one-line contract must hold
// whatever they contain.
std::string single_line(std::string message) {
  for (char& c : message) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  while (!message.empty() && message.back() == ' ') message.pop_back();
  return message;
}

int report(const char* prefix, const std::string& message, int exit_code) {
  std::cerr << prefix << single_line(message) << '\n';
  return exit_code;
}

std::string help_hint(const CLI::App& app) {
  const auto selected = app.get_subcommands();
  const std::string command = selected.empty() ? "cdcr" : "cdcr " + selected.front()->get_name();
  return " (see '" + command + " --help')";
}

std::string subcommand_names(const CLI::App& app) {
  std::string names;
  for (const CLI::App* command : app.get_subcommands({})) {
    if (!names.empty()) names += ", ";
    names += command->get_name();
  }
  return names;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace cdcr::cli;

  CLI::App app{"Kinematics of cable-driven continuum robots (Shen et al., IEEE Access 2020)", "cdcr"};
  app.set_version_flag("--version", "cdcr " CDCR_VERSION);
  // At most one; a missing subcommand is reported after parsing, so that an
  // unknown word is named as such instead of "subcommand required".
  app.require_subcommand(0, 1);

  CommandOutput output;
  register_fk_command(app, output);
  register_ik_command(app, output);
  register_train_command(app, output);
  register_eval_command(app, output);
  register_learning_curve_command(app, output);
  register_import_mocap_command(app, output);
  register_inspect_command(app, output);
  register_export_command(app, output);
  register_simulate_command(app, output);
  register_bus_command(app, output);
#if CDCR_HAVE_DEPLOY
  register_deploy_command(app, output);
  register_view_command(app, output);
#endif

  try {
    app.parse(argc, argv);
    if (app.get_subcommands().empty()) throw UsageError("a subcommand is required: " + subcommand_names(app));
  } catch (const CLI::ParseError& error) {
    // --help and --version arrive here too, with exit code 0.
    if (error.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(error);
    return report("cdcr: usage: ", error.what() + help_hint(app), kExitUsage);
  } catch (const UsageError& error) {
    return report("cdcr: usage: ", error.what() + help_hint(app), kExitUsage);
  } catch (const InputError& error) {
    return report("cdcr: error: ", error.what(), kExitInvalidInput);
  } catch (const std::exception& error) {
    return report("cdcr: error: ", error.what(), kExitInvalidInput);
  } catch (...) {
    return report("cdcr: error: ", "unexpected failure", kExitInvalidInput);
  }

  std::cout << output.text << std::flush;
  if (!output.failure.empty()) return report("cdcr: error: ", output.failure, kExitInvalidInput);
  return kExitSuccess;
}
