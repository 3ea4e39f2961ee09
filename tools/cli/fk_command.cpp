#include "fk_command.hpp"

#include <memory>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "cli_errors.hpp"
#include "json_output.hpp"
#include "number_list.hpp"
#include "segment_diagnostics.hpp"
#include "text_output.hpp"

namespace cdcr::cli {
namespace {

std::string segments(std::size_t count) { return fmt::format("{} segment{}", count, count == 1 ? "" : "s"); }

int segment_count_from_cables(std::size_t cable_count, const GeometryOptions& geometry) {
  constexpr std::size_t capacity = model::RobotGeometry<double>::kCapacity;
  const auto per_segment = static_cast<std::size_t>(cables_per_segment(geometry));
  if (cable_count % per_segment != 0) {
    throw InputError(fmt::format("--cables: {} values is not a multiple of {} ({} cables per segment)", cable_count,
                                 per_segment, per_segment));
  }
  if (cable_count / per_segment > capacity) {
    throw InputError(fmt::format("--cables: {} values make {}, more than the {} supported", cable_count,
                                 segments(cable_count / per_segment), capacity));
  }
  const int count = static_cast<int>(cable_count / per_segment);
  if (geometry.segment_count && *geometry.segment_count != count) {
    throw InputError(fmt::format("--cables: {} values make {}, but --segments is {}", cable_count,
                                 segments(cable_count / per_segment), *geometry.segment_count));
  }
  return count;
}

}  // namespace

void register_fk_command(CLI::App& app, CommandOutput& output) {
  auto options = std::make_shared<FkCommandOptions>();
  CLI::App* command = app.add_subcommand("fk", "Forward kinematics: cable lengths to joint variables and tip pose");
  command->add_option("--cables", options->cables_mm,
                      "Cable lengths in mm, l1,l2,l3,l4 of segment 1, then segment 2, ...")
      ->type_name("L1,L2,L3,L4,...")
      ->required();
  add_geometry_options(*command, options->geometry, "Number of segments (default: number of cable values / 4)");
  command->add_flag("--json", options->json, "Print one JSON object instead of tables");
  command->callback([options, &output] { output = run_fk(*options); });
}

CommandOutput run_fk(const FkCommandOptions& options) {
  const std::vector<double> values = parse_number_list(options.cables_mm, "--cables");
  const int segment_count = segment_count_from_cables(values.size(), options.geometry);
  require_finite(values, "--cables");
  const model::RobotGeometry<double> geometry = make_geometry(options.geometry, segment_count);

  const model::CableVector<double> cables_mm =
      Eigen::Map<const Eigen::VectorXd>(values.data(), static_cast<Eigen::Index>(values.size()));
  const model::JointVector<double> joints = joints_from_cables_checked(cables_mm, geometry);
  model::Pose<double> tip;
  if (const model::Status status = model::forward_kinematics(joints, geometry, tip); status != model::Status::ok) {
    throw InputError(fmt::format("forward kinematics failed: {}", model::to_string(status)));
  }

  CommandOutput output;
  if (options.json) {
    Json result;
    result["joints"] = joints_to_json(joints);
    result["pose"] = pose_to_json(tip);
    output.text = result.dump() + "\n";
  } else {
    output.text = format_joints_table(joints) + "\n" + format_pose(tip);
  }
  return output;
}

}  // namespace cdcr::cli
