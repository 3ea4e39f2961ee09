#pragma once
// A simulated cable-driven continuum robot: commanded cable lengths in, the
// end-platform pose out, as a motion-capture system would report it.
//
// The nominal model (cdcr::model) only supplies the robot's design geometry.
// The true pose comes from the simulator's own physics, which departs from
// the nominal model through the sources described in simulator_config.hpp.
// From the commanded cables to the pose, per segment i:
//   1. the cable differences give the bend through the segment's TRUE anchor
//      radius, and the cable pattern's angular offset rotates it (geometric);
//   2. cable stretch scales the bend down by 2 k r^2 / K (compliance);
//   3. gravity adds M_i / K, M_i the moment of everything distal to the
//      segment's base (the payload at the tip included), solved to
//      equilibrium (gravity);
//   4. the segment takes the shape of a linearly varying curvature over its
//      TRUE backbone length (curvature; an arc when off);
//   5. the segments are chained with the mounts between them, the base mount
//      in front and the marker frame of the end platform behind (geometric).
// measure() then perturbs the achieved bends (repeatability) and the reported
// pose (mocap noise).
//
// With the hysteresis on (source 7), the robot has a state: the friction of
// every cable (CableFriction) between the commanded lengths and the effective
// ones that enter step 1. move_cables() and measure() move the cables there
// along a straight line in cable space and update it; true_pose() stays a
// function of the lengths given (pass it effective lengths).
//
// A given seed is a given physical robot: its imperfections are drawn once,
// at construction. The per-sample noise has its own random stream, so
// true_pose() is a deterministic function of the cables and the payload.
//
// payload_kg is the mass the end platform carries beyond its own (see
// PayloadConfig): finite and not negative (std::invalid_argument otherwise).
// Zero is the robot without a payload, bit for bit.

#include <array>
#include <optional>

#include <cdcr/model/geometry.hpp>
#include <cdcr/model/se3.hpp>
#include <cdcr/model/types.hpp>

#include "sim/cable_friction.hpp"
#include "sim/random_stream.hpp"
#include "sim/robot_deviations.hpp"
#include "sim/simulator_config.hpp"

namespace cdcr::sim {

struct Measurement {
  model::Pose<double> true_pose;      // systematic errors only, what true_pose() returns
  model::Pose<double> measured_pose;  // plus repeatability and mocap noise
  model::CableVector<double> effective_cables_mm;  // the commanded ones minus the friction's lag (source 7)
};

class SimulatedRobot {
 public:
  // Throws std::invalid_argument if the geometry or the configuration is
  // invalid.
  SimulatedRobot(const model::RobotGeometry<double>& nominal, const SimulatorConfig& config);

  const model::RobotGeometry<double>& nominal_geometry() const { return nominal_; }
  const SimulatorConfig& config() const { return config_; }
  const RobotDeviations& deviations() const { return deviations_; }

  // Achieved bend vectors [u_1, w_1, u_2, ...] of each segment in its own
  // base frame, systematic sources only. The cables must number 4n, be finite
  // and positive (std::invalid_argument otherwise); cable differences beyond
  // what the true anchor radius allows saturate at a half-turn bend.
  model::JointVector<double> achieved_bends(const model::CableVector<double>& cables_mm, double payload_kg = 0.0) const;

  // Pose of the end-platform marker frame in the base frame for the given
  // achieved bends.
  model::Pose<double> pose_from_bends(const model::JointVector<double>& bends) const;

  model::Pose<double> true_pose(const model::CableVector<double>& cables_mm, double payload_kg = 0.0) const;

  // The friction of the cables, or nullptr with the hysteresis off.
  const CableFriction* friction() const { return friction_ ? &*friction_ : nullptr; }

  // The cables move to `commanded_mm` along a straight line in cable space
  // (the friction's first move only records where they are); returns the
  // effective lengths there: the commanded ones with the hysteresis off.
  // Throws std::invalid_argument as achieved_bends does, before moving.
  model::CableVector<double> move_cables(const model::CableVector<double>& commanded_mm);

  // One sample: moves the cables there (move_cables), then draws the
  // per-sample noise from the noise stream (whether or not the noise sources
  // are enabled, so each source's draws do not depend on the other's switch).
  Measurement measure(const model::CableVector<double>& cables_mm, double payload_kg = 0.0);

 private:
  struct Shape {
    std::array<model::Pose<double>, model::kMaxSegments> segment_bases;
    std::array<model::Vec3<double>, model::kMaxSegments> segment_midpoints_mm;
    model::Pose<double> end_disk;
  };

  model::Vec2<double> kinematic_bend(int segment, const model::SegmentCables<double>& cables_mm) const;
  model::Pose<double> segment_shape(int segment, const model::Vec2<double>& bend, double fraction) const;
  Shape shape(const model::JointVector<double>& bends) const;
  model::JointVector<double> gravity_equilibrium(const model::JointVector<double>& unloaded_bends,
                                                 double tip_mass_kg) const;

  model::RobotGeometry<double> nominal_;
  SimulatorConfig config_;
  RobotDeviations deviations_;
  // Per segment: true backbone length and anchor radius, bending stiffness K.
  std::array<double, model::kMaxSegments> length_mm_{};
  std::array<double, model::kMaxSegments> radius_mm_{};
  std::array<double, model::kMaxSegments> stiffness_n_mm_per_rad_{};
  std::array<double, model::kMaxSegments> bend_retained_{};  // 2 k r^2 / K
  RandomStream noise_;
  std::optional<CableFriction> friction_;
};

}  // namespace cdcr::sim
