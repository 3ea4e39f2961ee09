#include "segment_diagnostics.hpp"

#include <cmath>

#include <fmt/format.h>

#include "cli_errors.hpp"

namespace cdcr::cli {
namespace {

// The cable whose value is the first to break the rule, numbered from 1.
template <typename Predicate>
int first_cable(const model::SegmentCables<double>& cables_mm, Predicate predicate) {
  for (int j = 0; j < cables_mm.size(); ++j) {
    if (predicate(cables_mm[j])) return j + 1;
  }
  return 1;
}

std::string describe_difference(const model::SegmentCables<double>& cables_mm,
                                const model::SegmentGeometry<double>& geometry, double reach_mm) {
  if (geometry.cables != model::CableLayout<double>{}) {
    const model::CableDifferences<double> d = model::cable_differences(cables_mm, geometry);
    return fmt::format("the chord of the cables' fit, {:g} mm > {:g} mm", d.chord, reach_mm);
  }
  const double d31 = std::abs(cables_mm[2] - cables_mm[0]);
  const double d42 = std::abs(cables_mm[3] - cables_mm[1]);
  if (d31 > reach_mm) return fmt::format("|l3-l1| = {:g} mm > {:g} mm", d31, reach_mm);
  if (d42 > reach_mm) return fmt::format("|l4-l2| = {:g} mm > {:g} mm", d42, reach_mm);
  return fmt::format("hypot(l3-l1, l4-l2) = {:g} mm > {:g} mm", std::hypot(d31, d42), reach_mm);
}

std::string with_source(std::string_view source, const std::string& message) {
  return source.empty() ? message : fmt::format("{}: {}", source, message);
}

}  // namespace

std::string describe_segment_cables(model::Status status, int segment_number,
                                    const model::SegmentCables<double>& cables_mm,
                                    const model::SegmentGeometry<double>& geometry) {
  using model::Status;
  const double reach_mm = 4.0 * geometry.anchor_radius_mm;
  switch (status) {
    case Status::non_finite_input: {
      const int j = first_cable(cables_mm, [](double l) { return !std::isfinite(l); });
      return fmt::format("segment {}: cable length l{} is not finite ({})", segment_number, j, cables_mm[j - 1]);
    }
    case Status::cable_length_not_positive: {
      const int j = first_cable(cables_mm, [](double l) { return !(l > 0.0); });
      return fmt::format("segment {}: cable length must be positive (l{} = {:g} mm)", segment_number, j,
                         cables_mm[j - 1]);
    }
    case Status::cable_difference_out_of_range:
      return fmt::format("segment {}: cable length difference exceeds 4 x anchor radius ({})", segment_number,
                         describe_difference(cables_mm, geometry, reach_mm));
    case Status::theta_beyond_limit: {
      const double chord_mm = model::cable_differences(cables_mm, geometry).chord;
      const double theta_rad = 2.0 * std::asin(chord_mm / reach_mm);
      return fmt::format("segment {}: bending angle theta = {:.4f} rad exceeds theta_max = {:.6g} rad",
                         segment_number, theta_rad, geometry.theta_max_rad);
    }
    default:
      return fmt::format("segment {}: {}", segment_number, model::to_string(status));
  }
}

std::string describe_segment_joints(model::Status status, int segment_number,
                                    const model::SegmentJoints<double>& joints,
                                    const model::SegmentGeometry<double>& geometry) {
  using model::Status;
  switch (status) {
    case Status::non_finite_input:
      return fmt::format("segment {}: joint variables are not finite (alpha = {}, theta = {})", segment_number,
                         joints.alpha_rad, joints.theta_rad);
    case Status::theta_beyond_limit:
      return fmt::format("segment {}: bending angle theta = {:.6g} rad is outside [0, theta_max = {:.6g}] rad",
                         segment_number, joints.theta_rad, geometry.theta_max_rad);
    default:
      return fmt::format("segment {}: {}", segment_number, model::to_string(status));
  }
}

model::JointVector<double> joints_from_cables_checked(const model::CableVector<double>& cables_mm,
                                                      const model::RobotGeometry<double>& geometry) {
  model::JointVector<double> joints;
  const model::Status status = model::joints_from_cables(cables_mm, geometry, joints);
  if (status == model::Status::ok) return joints;
  if (status == model::Status::invalid_segment_count || cables_mm.size() != geometry.cable_count()) {
    throw InputError(fmt::format("{} cable lengths do not match {} segments of {} cables", cables_mm.size(),
                                 geometry.segment_count, geometry.cable_count()));
  }
  for (int i = 0; i < geometry.segment_count; ++i) {
    const model::SegmentCables<double> segment_cables =
        cables_mm.segment(geometry.first_cable(i), geometry.segments[i].cables.count);
    model::SegmentJoints<double> segment_joints;
    const model::Status segment_status = model::joints_from_cables(segment_cables, geometry.segments[i], segment_joints);
    if (segment_status != model::Status::ok) {
      throw InputError(describe_segment_cables(segment_status, i + 1, segment_cables, geometry.segments[i]));
    }
  }
  throw InputError(model::to_string(status));
}

void check_joints_or_throw(const model::JointVector<double>& joints, const model::RobotGeometry<double>& geometry,
                           std::string_view source) {
  const model::Status status = model::check_joints(joints, geometry);
  if (status == model::Status::ok) return;
  if (joints.size() != 2 * geometry.segment_count) {
    throw InputError(with_source(source, fmt::format("{} joint values do not match {} segments (alpha, theta each)",
                                                     joints.size(), geometry.segment_count)));
  }
  for (int i = 0; i < geometry.segment_count; ++i) {
    const model::SegmentJoints<double> q = model::segment_joints(joints, i);
    const model::Status segment_status = model::check_joints(q, geometry.segments[i]);
    if (segment_status != model::Status::ok) {
      throw InputError(with_source(source, describe_segment_joints(segment_status, i + 1, q, geometry.segments[i])));
    }
  }
  throw InputError(with_source(source, model::to_string(status)));
}

model::CableVector<double> cables_from_joints_checked(const model::JointVector<double>& joints,
                                                      const model::RobotGeometry<double>& geometry,
                                                      std::string_view source) {
  check_joints_or_throw(joints, geometry, source);
  model::CableVector<double> cables_mm;
  const model::Status status = model::cables_from_joints(joints, geometry, cables_mm);
  if (status == model::Status::ok) return cables_mm;
  for (int i = 0; i < geometry.segment_count; ++i) {
    model::SegmentCables<double> segment_cables =
        model::SegmentCables<double>::Zero(geometry.segments[i].cables.count);
    const model::Status segment_status =
        model::cables_from_joints(model::segment_joints(joints, i), geometry.segments[i], segment_cables);
    if (segment_status != model::Status::ok) {
      throw InputError(
          with_source(source, describe_segment_cables(segment_status, i + 1, segment_cables, geometry.segments[i])));
    }
  }
  throw InputError(with_source(source, model::to_string(status)));
}

}  // namespace cdcr::cli
