#include "ik_command.hpp"

#include <algorithm>
#include <memory>
#include <optional>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <cdcr/firmware/ik_settings.hpp>
#include <cdcr/model/inverse_kinematics.hpp>
#include <cdcr/model/units.hpp>

#include "cli_errors.hpp"
#include "ik_target.hpp"
#include "json_output.hpp"
#include "number_list.hpp"
#include "segment_diagnostics.hpp"
#include "text_output.hpp"

namespace cdcr::cli {
namespace {

struct Target {
  model::Pose<double> pose;
  bool orientation_given = false;
};

Target read_target(const IkCommandOptions& options) {
  if (!options.position_mm && !options.pose) {
    throw UsageError("ik needs a target: --position X,Y,Z [--quaternion QW,QX,QY,QZ] or --pose with 12 or 16 values");
  }
  // Parse every list before judging any value, so a syntax error is always
  // reported as such.
  std::optional<std::vector<double>> position;
  std::optional<std::vector<double>> quaternion;
  std::optional<std::vector<double>> pose;
  if (options.position_mm) position = parse_number_list(*options.position_mm, "--position");
  if (options.quaternion) quaternion = parse_number_list(*options.quaternion, "--quaternion");
  if (options.pose) pose = parse_number_list(*options.pose, "--pose");

  Target target;
  if (pose) {
    target.pose = pose_from_row_major(*pose);
    target.orientation_given = true;
    return target;
  }
  target.pose.position_mm = position_from_values(*position);
  if (quaternion) {
    target.pose.rotation = rotation_from_quaternion(*quaternion);
    target.orientation_given = true;
  }
  return target;
}

model::JointVector<double> read_initial_joints(const std::optional<std::vector<double>>& values,
                                               const model::RobotGeometry<double>& geometry) {
  if (!values) return firmware::ik_straight_start(geometry);
  model::JointVector<double> joints(2 * geometry.segment_count);
  require_count(*values, static_cast<std::size_t>(2 * geometry.segment_count), "--initial",
                fmt::format("alpha,theta for each of {} segments", geometry.segment_count));
  require_finite(*values, "--initial");
  for (Eigen::Index k = 0; k < joints.size(); ++k) joints[k] = (*values)[static_cast<std::size_t>(k)];
  check_joints_or_throw(joints, geometry, "--initial");
  return joints;
}

std::string format_text(const model::IkResult<double>& result, double orientation_error_deg,
                        const model::RobotGeometry<double>& geometry) {
  std::string text = fmt::format(
      "converged: {}\niterations: {}\nposition error: {:.6g} mm\norientation error: {:.6g} deg\n\n",
      result.converged() ? "yes" : "no", result.iterations, result.position_error_mm, orientation_error_deg);
  text += format_joints_table(result.joints);
  text += "\n";
  text += format_cables_table(result.cables_mm, geometry);
  return text;
}

std::string format_json(const model::IkResult<double>& result, double orientation_error_deg,
                        const model::RobotGeometry<double>& geometry) {
  Json json;
  json["converged"] = result.converged();
  json["iterations"] = result.iterations;
  json["position_error_mm"] = result.position_error_mm;
  json["orientation_error_deg"] = orientation_error_deg;
  json["joints"] = joints_to_json(result.joints);
  json["cables"] = cables_to_json(result.cables_mm, geometry);
  return json.dump() + "\n";
}

std::string describe_miss(const model::IkResult<double>& result, bool orientation_given,
                          double orientation_error_deg) {
  if (orientation_given) {
    return fmt::format("target not reached: position error {:.6g} mm, orientation error {:.6g} deg after {} iterations",
                       result.position_error_mm, orientation_error_deg, result.iterations);
  }
  return fmt::format("target not reached: position error {:.6g} mm after {} iterations", result.position_error_mm,
                     result.iterations);
}

}  // namespace

void register_ik_command(CLI::App& app, CommandOutput& output) {
  auto options = std::make_shared<IkCommandOptions>();
  CLI::App* command =
      app.add_subcommand("ik", "Inverse kinematics: target tip position or pose to joint variables and cable lengths");
  CLI::Option* position = command->add_option("--position", options->position_mm, "Target tip position (mm)")
                                 ->type_name("X,Y,Z");
  command->add_option("--quaternion", options->quaternion,
                      "Target orientation as a unit quaternion (Hamilton, scalar first); requires --position")
      ->type_name("QW,QX,QY,QZ")
      ->needs(position);
  command->add_option("--pose", options->pose,
                      "Target pose: 16 (or 12) row-major values of [R p; 0 0 0 1], as printed by fk --json")
      ->type_name("R00,R01,R02,X,...")
      ->excludes(position);
  add_geometry_options(*command, options->geometry, fmt::format("Number of segments (default: {})",
                                                                kDefaultIkSegmentCount));
  command->add_option("--max-iterations", options->max_iterations,
                      fmt::format("Iteration budget of the solver (default: the runtime's, {})",
                                  firmware::kMaxIkIterations));
  command->add_option("--initial", options->initial_joints,
                      fmt::format("Initial joints in rad (default: the runtime's start, alpha 0, theta {} for every "
                                  "segment)",
                                  firmware::kIkStraightStartThetaRad))
      ->type_name("A1,T1,A2,T2,...");
  command->add_flag("--json", options->json, "Print one JSON object instead of tables");
  command->callback([options, &output] { output = run_ik(*options); });
}

CommandOutput run_ik(const IkCommandOptions& options) {
  std::optional<std::vector<double>> initial_values;
  if (options.initial_joints) initial_values = parse_number_list(*options.initial_joints, "--initial");
  const Target target = read_target(options);

  const int max_iterations = options.max_iterations.value_or(firmware::kMaxIkIterations);
  if (max_iterations < 0) {
    throw InputError(fmt::format("--max-iterations must not be negative (got {})", max_iterations));
  }
  const model::RobotGeometry<double> geometry =
      make_geometry(options.geometry, options.geometry.segment_count.value_or(kDefaultIkSegmentCount));
  const model::JointVector<double> initial_joints = read_initial_joints(initial_values, geometry);

  // The board's solver with the runtime's settings, then polished in
  // double: what a user tries here is what the board does.
  const model::IkResult<double> result = firmware::solve_ik_as_on_the_board(
      target.pose, target.orientation_given ? model::IkTargetKind::pose : model::IkTargetKind::position, geometry,
      initial_joints, max_iterations);
  if (result.status != model::Status::ok && result.status != model::Status::ik_not_converged) {
    // The solver stays within the joint limits, so the only way here is a
    // geometry whose cables cannot reach the solved bend; name the segment.
    cables_from_joints_checked(result.joints, geometry, "solution");
    throw InputError(fmt::format("inverse kinematics failed: {}", model::to_string(result.status)));
  }

  const double orientation_error_deg = result.orientation_error_rad * model::kDegreesPerRadian;
  CommandOutput output;
  output.text = options.json ? format_json(result, orientation_error_deg, geometry)
                              : format_text(result, orientation_error_deg, geometry);
  if (!result.converged()) output.failure = describe_miss(result, target.orientation_given, orientation_error_deg);
  return output;
}

}  // namespace cdcr::cli
