#pragma once
// cdcr export: a validated flash image in the form a board takes it: the raw
// bytes, Intel HEX at a flash address, or a C array to link into firmware.

#include <cstdint>
#include <optional>
#include <string>

#include "command_output.hpp"

namespace CLI {
class App;
}

namespace cdcr::cli {

struct ExportCommandOptions {
  std::string model_path;
  std::string format;  // bin, hex or c
  std::string out_path;
  std::optional<std::string> base_address;  // hex only; decimal or 0x-prefixed
  int record_bytes = 16;                    // hex only
  std::optional<std::string> symbol;        // c only
  std::optional<std::string> section;       // c only
};

void register_export_command(CLI::App& app, CommandOutput& output);

CommandOutput run_export(const ExportCommandOptions& options);

}  // namespace cdcr::cli
