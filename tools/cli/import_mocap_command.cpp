#include "import_mocap_command.hpp"

#include <memory>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "cli_errors.hpp"
#include "dataset/csv_dataset.hpp"
#include "dataset/mocap_import.hpp"

namespace cdcr::cli {
namespace {

constexpr std::size_t kListedSkippedFrames = 10;

std::string frame_list(const std::vector<long>& frames) {
  std::string list;
  for (std::size_t i = 0; i < frames.size() && i < kListedSkippedFrames; ++i) {
    list += fmt::format("{}{}", i ? ", " : "", frames[i]);
  }
  if (frames.size() > kListedSkippedFrames) list += ", ...";
  return list;
}

}  // namespace

void register_import_mocap_command(CLI::App& app, CommandOutput& output) {
  auto options = std::make_shared<ImportMocapOptions>();
  CLI::App* command = app.add_subcommand(
      "import-mocap",
      "Build a dataset from commanded cable lengths and a Qualisys (QTM) 6DOF TSV export: row i of the cable "
      "file is paired with captured frame i, and the pose written is T_base^-1 * T_end (eq. 21)");
  command->add_option("--cables", options->cables_path, "Dataset CSV with the commanded cable lengths and, optionally, the time (t_s: a motion "
                      "sequence, carried into the output) or the payload (pose columns, if any, are ignored)")
      ->type_name("FILE")
      ->required();
  command->add_option("--mocap", options->mocap_path, "QTM 6DOF export (.tsv): X Y Z in mm, Rot[0..8] column-major")
      ->type_name("FILE")
      ->required();
  command->add_option("--base-body", options->base_body, "Rigid body on the robot base")->type_name("NAME")->required();
  command->add_option("--end-body", options->end_body, "Rigid body on the end platform")->type_name("NAME")->required();
  command->add_option("--out", options->out_path, "Dataset CSV to write")->type_name("FILE")->required();
  command->add_flag("--skip-lost", options->skip_lost,
                    "Drop frames (and their cable rows) where either body was not tracked, instead of failing (not in a "
                    "motion sequence: its rows cannot be dropped)");
  command->callback([options, &output] { output = run_import_mocap(*options); });
}

CommandOutput run_import_mocap(const ImportMocapOptions& options) {
  if (options.base_body == options.end_body) {
    throw UsageError(fmt::format("--base-body and --end-body are both '{}'", options.base_body));
  }
  dataset::Dataset commanded;
  dataset::MocapCapture capture;
  try {
    commanded = dataset::read_dataset_csv(options.cables_path);
    capture = dataset::read_qtm_6d_tsv(options.mocap_path);
  } catch (const dataset::DatasetError& e) {
    throw InputError(e.what());
  }

  dataset::MocapImportOptions import_options;
  import_options.base_body = options.base_body;
  import_options.end_body = options.end_body;
  import_options.lost_frames = options.skip_lost ? dataset::LostFrames::skip : dataset::LostFrames::reject;
  dataset::MocapImport imported;
  try {
    imported = dataset::import_mocap(commanded, capture, import_options);
  } catch (const dataset::LostTrackingError& e) {
    throw InputError(fmt::format("{} (--skip-lost drops such frames)", dataset::DatasetError(options.mocap_path, e).what()));
  } catch (const dataset::DatasetError& e) {
    throw InputError(dataset::DatasetError(options.mocap_path, e).what());
  }

  const std::string comment = fmt::format(
      "Imported by cdcr import-mocap: cables from {}, poses from {}\n"
      "pose = T_base^-1 * T_end (eq. 21), base body '{}', end body '{}'; frames skipped (a body not tracked): {}",
      options.cables_path, options.mocap_path, options.base_body, options.end_body, imported.skipped_frames.size());
  try {
    dataset::write_dataset_csv(options.out_path, imported.data, comment);
  } catch (const dataset::DatasetError& e) {
    throw InputError(e.what());
  }

  CommandOutput output;
  output.text = fmt::format("wrote {} samples ({} segments) to {}\n", imported.data.sample_count(),
                            imported.data.segment_count, options.out_path);
  if (options.skip_lost) {
    const std::size_t skipped = imported.skipped_frames.size();
    output.text += fmt::format("skipped {} frame{} where a body was not tracked{}{}\n", skipped, skipped == 1 ? "" : "s",
                               skipped == 0 ? "" : ": ", frame_list(imported.skipped_frames));
  }
  return output;
}

}  // namespace cdcr::cli
