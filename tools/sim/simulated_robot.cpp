#include "sim/simulated_robot.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <cdcr/model/segment.hpp>
#include <cdcr/model/status.hpp>

#include "sim/curved_segment.hpp"

namespace cdcr::sim {
namespace {

using Vec2 = model::Vec2<double>;
using Vec3 = model::Vec3<double>;
using Pose = model::Pose<double>;

constexpr int kMaxGravityIterations = 200;
constexpr double kGravityToleranceRad = 1e-13;

void check_cables(const model::CableVector<double>& cables_mm, const model::RobotGeometry<double>& nominal) {
  if (cables_mm.size() != nominal.cable_count()) {
    throw std::invalid_argument("expected " + std::to_string(nominal.cable_count()) + " cable lengths, got " +
                                std::to_string(cables_mm.size()));
  }
  if (!cables_mm.allFinite()) throw std::invalid_argument("cable lengths must be finite");
  if (!(cables_mm.minCoeff() > 0.0)) throw std::invalid_argument("cable lengths must be positive");
}

}  // namespace

SimulatedRobot::SimulatedRobot(const model::RobotGeometry<double>& nominal, const SimulatorConfig& config)
    : nominal_(nominal), config_(config), noise_(config.session_seed(), StreamId::noise) {
  if (const model::Status status = nominal.validate(); status != model::Status::ok) {
    throw std::invalid_argument(std::string("invalid nominal geometry: ") + model::to_string(status));
  }
  config_.validate();
  deviations_ = draw_deviations(nominal.segment_count, config_);
  const double EI = config_.structure.backbone_bending_stiffness_n_mm2;
  const double k = config_.structure.cable_stiffness_n_per_mm;
  for (int i = 0; i < nominal.segment_count; ++i) {
    length_mm_[i] = nominal.segments[i].backbone_length_mm + deviations_.segments[i].backbone_length_error_mm;
    radius_mm_[i] = nominal.segments[i].anchor_radius_mm + deviations_.segments[i].anchor_radius_error_mm;
    if (!(length_mm_[i] > 0.0) || !(radius_mm_[i] > 0.0)) {
      throw std::invalid_argument("geometric errors make segment " + std::to_string(i + 1) +
                                  " degenerate: reduce the length or radius sigma");
    }
    const double cables = 2.0 * k * radius_mm_[i] * radius_mm_[i];
    stiffness_n_mm_per_rad_[i] = EI / length_mm_[i] + cables;
    bend_retained_[i] = cables / stiffness_n_mm_per_rad_[i];
  }
  if (config_.hysteresis.enabled) {
    friction_.emplace(nominal.cable_count(), config_.hysteresis, config_.seed, config_.session_seed());
  }
}

// Eqs. (4)-(5) (the layout's chord, segment.hpp) with the segment's true
// anchor radius, written exactly as the nominal model does so that a robot
// without errors reproduces it bit for bit.
Vec2 SimulatedRobot::kinematic_bend(int segment, const model::SegmentCables<double>& cables_mm) const {
  const model::CableLayout<double>& layout = nominal_.segments[segment].cables;
  const double d31 = model::layout_sum(layout.chord_x_weights, cables_mm, layout.count);
  const double d24 = model::layout_sum(layout.chord_y_weights, cables_mm, layout.count);
  const double reach = 4.0 * radius_mm_[segment];
  const double chord = std::hypot(d31, d24);
  const double theta = 2.0 * std::asin(std::min(chord / reach, 1.0));
  const double alpha = std::atan2(d24, d31) + deviations_.segments[segment].anchor_angle_offset_rad;
  return model::bend_from_joints(model::SegmentJoints<double>{alpha, theta});
}

Pose SimulatedRobot::segment_shape(int segment, const Vec2& bend, double fraction) const {
  const double gradient = deviations_.segments[segment].curvature_gradient;
  if (gradient == 0.0 && fraction == 1.0) return model::segment_pose<double>(bend, length_mm_[segment]);
  return curved_segment_pose(bend, length_mm_[segment], gradient, fraction);
}

SimulatedRobot::Shape SimulatedRobot::shape(const model::JointVector<double>& bends) const {
  Shape result;
  Pose frame = deviations_.base_mount;
  const int n = nominal_.segment_count;
  for (int i = 0; i < n; ++i) {
    const Vec2 bend = bends.segment<2>(2 * i);
    result.segment_bases[i] = frame;
    result.segment_midpoints_mm[i] = frame.rotation * segment_shape(i, bend, 0.5).position_mm + frame.position_mm;
    frame = frame * segment_shape(i, bend, 1.0);
    if (i + 1 < n) frame = frame * deviations_.segment_mounts[i];
  }
  result.end_disk = frame;
  return result;
}

// b_i = b_i,unloaded + M_i(b) / K_i. The sag moves the masses and so changes
// the moments; a fixed-point iteration converges as long as the structure is
// far from buckling (|dM/db| << K). The tip mass (end platform and payload)
// hangs at the end disk.
model::JointVector<double> SimulatedRobot::gravity_equilibrium(const model::JointVector<double>& unloaded,
                                                               double tip_mass_kg) const {
  const GravityConfig& g = config_.gravity;
  // Newtons per kg; the lever arms are in mm, so the moments come out in N mm.
  const Vec3 weight_per_kg = g.acceleration_m_per_s2 * g.direction.normalized();
  const double segment_mass = g.segment_mass_kg;
  const int n = nominal_.segment_count;

  model::JointVector<double> bends = unloaded;
  for (int iteration = 0; iteration < kMaxGravityIterations; ++iteration) {
    const Shape s = shape(bends);
    model::JointVector<double> next(2 * n);
    double change = 0.0;
    for (int i = 0; i < n; ++i) {
      const Vec3 pivot = s.segment_bases[i].position_mm;
      Vec3 moment = (tip_mass_kg * (s.end_disk.position_mm - pivot)).cross(weight_per_kg);
      for (int j = i; j < n; ++j) moment += (segment_mass * (s.segment_midpoints_mm[j] - pivot)).cross(weight_per_kg);
      const Vec3 local = s.segment_bases[i].rotation.transpose() * moment;
      // A rotation vector (kx, ky, 0) is the bend (u, w) = (ky, -kx).
      const Vec2 sag = Vec2(local.y(), -local.x()) / stiffness_n_mm_per_rad_[i];
      next.segment<2>(2 * i) = unloaded.segment<2>(2 * i) + sag;
      change = std::max(change, (next.segment<2>(2 * i) - bends.segment<2>(2 * i)).cwiseAbs().maxCoeff());
    }
    bends = next;
    if (change < kGravityToleranceRad) return bends;
  }
  throw std::runtime_error("gravity sag does not converge: the structure is too soft for its load");
}

model::JointVector<double> SimulatedRobot::achieved_bends(const model::CableVector<double>& cables_mm,
                                                          double payload_kg) const {
  const int n = nominal_.segment_count;
  check_cables(cables_mm, nominal_);
  if (!(std::isfinite(payload_kg) && payload_kg >= 0.0)) {
    throw std::invalid_argument("payload must be finite and not negative (got " + std::to_string(payload_kg) + " kg)");
  }

  model::JointVector<double> bends(2 * n);
  for (int i = 0; i < n; ++i) {
    Vec2 bend = kinematic_bend(i, cables_mm.segment(nominal_.first_cable(i), nominal_.segments[i].cables.count));
    if (config_.compliance.enabled) bend *= bend_retained_[i];
    bends.segment<2>(2 * i) = bend;
  }
  if (config_.gravity.enabled) bends = gravity_equilibrium(bends, config_.gravity.platform_mass_kg + payload_kg);
  return bends;
}

Pose SimulatedRobot::pose_from_bends(const model::JointVector<double>& bends) const {
  return shape(bends).end_disk * deviations_.platform_mount;
}

Pose SimulatedRobot::true_pose(const model::CableVector<double>& cables_mm, double payload_kg) const {
  return pose_from_bends(achieved_bends(cables_mm, payload_kg));
}

model::CableVector<double> SimulatedRobot::move_cables(const model::CableVector<double>& commanded_mm) {
  check_cables(commanded_mm, nominal_);
  if (!friction_) return commanded_mm;
  friction_->move_to(commanded_mm);
  return friction_->effective_mm();
}

Measurement SimulatedRobot::measure(const model::CableVector<double>& cables_mm, double payload_kg) {
  // The same checks, in the same order, as achieved_bends, before the friction moves.
  check_cables(cables_mm, nominal_);
  if (!(std::isfinite(payload_kg) && payload_kg >= 0.0)) {
    throw std::invalid_argument("payload must be finite and not negative (got " + std::to_string(payload_kg) + " kg)");
  }
  Measurement m;
  m.effective_cables_mm = move_cables(cables_mm);
  const model::JointVector<double> bends = achieved_bends(m.effective_cables_mm, payload_kg);
  m.true_pose = pose_from_bends(bends);

  const RepeatabilityConfig& repeatability = config_.repeatability;
  model::JointVector<double> perturbed = bends;
  for (Eigen::Index k = 0; k < perturbed.size(); ++k) {
    const double jitter = noise_.normal(repeatability.bend_sigma_rad);
    if (repeatability.enabled) perturbed[k] += jitter;
  }
  m.measured_pose = repeatability.enabled ? pose_from_bends(perturbed) : m.true_pose;

  const MocapNoiseConfig& mocap = config_.mocap_noise;
  Vec3 position_noise, rotation_noise;
  for (int k = 0; k < 3; ++k) position_noise[k] = noise_.normal(mocap.position_sigma_mm);
  for (int k = 0; k < 3; ++k) rotation_noise[k] = noise_.normal(mocap.rotation_sigma_rad);
  if (mocap.enabled) {
    m.measured_pose.rotation = model::exp_so3<double>(rotation_noise) * m.measured_pose.rotation;
    m.measured_pose.position_mm += position_noise;
  }
  return m;
}

}  // namespace cdcr::sim
