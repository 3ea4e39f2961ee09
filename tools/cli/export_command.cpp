#include "export_command.hpp"

#include <cerrno>
#include <cstdlib>
#include <memory>
#include <stdexcept>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "cdcr/model/flash_image.hpp"
#include "cli_errors.hpp"
#include "export/binary_file.hpp"
#include "export/c_source.hpp"
#include "export/intel_hex.hpp"
#include "image_report.hpp"

namespace cdcr::cli {
namespace {

std::uint32_t parse_address(const std::string& text) {
  const bool hex = text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X');
  const std::string digits = hex ? text.substr(2) : text;
  const bool well_formed =
      !digits.empty() && digits.find_first_not_of(hex ? "0123456789abcdefABCDEF" : "0123456789") == std::string::npos;
  if (!well_formed) throw UsageError(fmt::format("--base-address: '{}' is not an address (decimal or 0x hex)", text));
  errno = 0;
  const unsigned long long value = std::strtoull(digits.c_str(), nullptr, hex ? 16 : 10);
  if (errno == ERANGE || value > 0xFFFFFFFFull) {
    throw InputError(fmt::format("--base-address: {} is beyond the 32-bit address space", text));
  }
  return static_cast<std::uint32_t>(value);
}

void require_format(bool given, const char* option, const char* format, const std::string& chosen) {
  if (given && chosen != format) {
    throw UsageError(fmt::format("{} applies to --format {}, not {}", option, format, chosen));
  }
}

}  // namespace

void register_export_command(CLI::App& app, CommandOutput& output) {
  auto options = std::make_shared<ExportCommandOptions>();
  CLI::App* command = app.add_subcommand(
      "export", "Validate a flash image and write it as a raw binary, Intel HEX, or a C array for the firmware");
  command->add_option("--model", options->model_path, "Flash image to export")->type_name("MODEL.img")->required();
  command->add_option("--format", options->format, "bin: the image as is; hex: Intel HEX; c: C source array")
      ->check(CLI::IsMember({"bin", "hex", "c"}))
      ->required();
  command->add_option("--out", options->out_path, "File to write")->type_name("FILE")->required();
  command->add_option("--base-address", options->base_address,
                      "hex: flash address of the image's first byte, e.g. 0x08040000 (default 0)")
      ->type_name("ADDRESS");
  command->add_option("--record-bytes", options->record_bytes, "hex: data bytes per record")
      ->check(CLI::IsMember({16, 32}))
      ->capture_default_str();
  command->add_option("--symbol", options->symbol, "c: name of the array (default cdcr_model_image)")
      ->type_name("NAME");
  command->add_option("--section", options->section,
                      "c: linker section of the array (default .cdcr_model); the linker script must place it")
      ->type_name("NAME");
  command->callback([options, &output] { output = run_export(*options); });
}

CommandOutput run_export(const ExportCommandOptions& options) {
  require_format(options.base_address.has_value(), "--base-address", "hex", options.format);
  require_format(options.symbol.has_value(), "--symbol", "c", options.format);
  require_format(options.section.has_value(), "--section", "c", options.format);
  exporting::IntelHexOptions hex;
  hex.base_address = options.base_address ? parse_address(*options.base_address) : 0;
  hex.bytes_per_record = options.record_bytes;
  exporting::CSourceOptions c;
  if (options.symbol) c.symbol = *options.symbol;
  if (options.section) c.section = *options.section;
  c.description = "Exported from " + options.model_path + " by cdcr export.";
  if (!exporting::is_c_identifier(c.symbol)) throw UsageError(fmt::format("--symbol: '{}' is not a C identifier", c.symbol));
  if (!exporting::is_section_name(c.section)) {
    throw UsageError(fmt::format("--section: '{}' is not a usable section name", c.section));
  }

  std::vector<std::uint8_t> bytes;
  try {
    bytes = exporting::read_binary_file(options.model_path);
  } catch (const std::runtime_error& error) {
    throw InputError(error.what());
  }
  model::ImageView view{};
  if (const model::ImageStatus status = model::parse_image(bytes.data(), bytes.size(), view);
      status != model::ImageStatus::ok) {
    throw InputError(fmt::format("{}: {} ({}); nothing written", options.model_path, model::to_string(status),
                                 image_status_name(status)));
  }
  // Bytes after total_size belong to whatever region the file was read from.
  const std::size_t image_size = view.total_size;

  std::string summary;
  try {
    if (options.format == "bin") {
      exporting::write_binary_file(options.out_path, bytes.data(), image_size);
      summary = fmt::format("raw binary, {} bytes", image_size);
    } else if (options.format == "hex") {
      const std::string text = exporting::format_intel_hex(bytes.data(), image_size, hex);
      exporting::write_binary_file(options.out_path, text.data(), text.size());
      summary = fmt::format("Intel HEX, {} bytes at 0x{:08x}..0x{:08x}, {} per record", image_size, hex.base_address,
                            hex.base_address + image_size - 1, hex.bytes_per_record);
    } else {
      const std::string text = exporting::format_c_source(bytes.data(), image_size, c);
      exporting::write_binary_file(options.out_path, text.data(), text.size());
      summary = fmt::format("C array {}[{}] in section {}", c.symbol, image_size, c.section);
    }
  } catch (const std::exception& error) {
    throw InputError(error.what());
  }

  CommandOutput output;
  output.text = fmt::format("wrote {}: {}\n", options.out_path, summary);
  return output;
}

}  // namespace cdcr::cli
