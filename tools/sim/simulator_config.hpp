#pragma once
// What makes the simulated robot differ from the nominal model, source by
// source. Every magnitude is here, with its default, and every source can be
// switched off on its own; with all of them off the simulator reproduces the
// nominal forward kinematics exactly.
//
// Systematic sources (deterministic for a given seed, learnable):
//   1. geometric      per-segment backbone length, anchor radius and anchor
//                     angle errors; small rigid mounts between segments; the
//                     mount of the whole robot in the measurement's base
//                     frame; the mount of the marker frame on the end platform.
//   2. curvature      the backbone curvature varies linearly along each
//                     segment instead of being constant.
//   3. compliance     the cables stretch under the tension that holds the
//                     bend, so every segment bends less than commanded.
//   4. gravity        the weight of the distal segments, of the end platform
//                     and of the payload it carries bends every segment
//                     further towards the ground.
//   7. hysteresis     (off by default) friction between each cable and its
//                     sheath: the length that bends a segment lags the
//                     commanded one by an amount that depends on how the
//                     cable got there. Deterministic given the path, but the
//                     robot remembers the path: the state persists from one
//                     command to the next, and a session is recorded as a
//                     motion sequence (see HysteresisConfig).
// Per-sample noise (no model can learn it):
//   5. repeatability  friction and backlash: a random perturbation of the
//                     achieved bend of every segment. With source 7 on, the
//                     friction is modelled and this is only what is left
//                     (see HysteresisSessionDefaults).
//   6. mocap noise    the motion-capture system's error on the reported pose.
//
// Frames: the base frame is the measurement's base frame (built from the base
// markers, eq. 21); z points along the straight backbone. The default mount is
// horizontal: the robot sticks out sideways from the actuation bench with the
// base x axis pointing up, so gravity is -x. Units: mm, rad, kg, N.
//
// The defaults are tuned to the paper's prototype and protocol (4 segments,
// L = 120 mm, r = 67 mm, 750 random samples): the nominal model is off by
// about 50 mm and 10 deg on average (Table 2: 53.2 mm, 11.4 deg), most of it
// gravity sag, while the noise floor is about 2.2 mm and 0.54 deg
// (repeatability of a few millimetres, motion capture of ~0.5 mm).

#include <cstdint>

#include <Eigen/Core>

#include <cdcr/model/units.hpp>

namespace cdcr::sim {

// Drawn once per seed: a given seed is a given physical robot. Each value is
// a zero-mean normal with the sigma below (per axis for vectors).
struct GeometricErrorConfig {
  bool enabled = true;
  double backbone_length_sigma_mm = 1.0;
  double anchor_radius_sigma_mm = 0.5;
  // The cable pattern rotated about the segment's z axis: alpha reads off by
  // this angle.
  double anchor_angle_sigma_rad = 2.0 * model::kRadiansPerDegree;
  // Rigid transform between consecutive segments (assembly of the disks).
  double segment_twist_sigma_rad = 1.0 * model::kRadiansPerDegree;   // about z
  double segment_tilt_sigma_rad = 0.5 * model::kRadiansPerDegree;    // about x and y
  double segment_offset_sigma_mm = 0.5;
  // The robot's base in the measurement's base frame (base markers vs. the
  // actual first disk).
  double base_rotation_sigma_rad = 0.5 * model::kRadiansPerDegree;
  double base_offset_sigma_mm = 2.0;
  // The end-platform marker frame vs. the last disk's frame.
  double platform_rotation_sigma_rad = 1.5 * model::kRadiansPerDegree;
  double platform_offset_sigma_mm = 1.0;
};

// kappa(s) = kappa_mean (1 + c (2 s / L - 1)), s in [0, L]: the bend angle
// theta is unchanged, but the shape is no longer an arc. Friction in the disk
// holes lowers the cable tension towards the distal end, so the curvature is
// larger near the segment's base: c < 0. Per segment c is drawn once, normal
// with this mean and sigma; |c| must stay below 1 (the curvature would change
// sign within the segment).
struct CurvatureConfig {
  bool enabled = true;
  double gradient_mean = -0.3;
  double gradient_sigma = 0.1;
};

// Stiffnesses shared by compliance and gravity sag (a property of the
// structure, not a switchable error). A segment resists a bending moment with
//   K = EI / L + 2 k r^2   (N mm / rad)
// where EI is the backbone's bending stiffness and k the lumped axial
// stiffness of one cable's transmission (wire rope, sheaves, spool and drive)
// as seen at the segment. Four cables at 90 deg give sum(d d^T) = 2 I, hence
// the factor 2.
struct StructureConfig {
  double backbone_bending_stiffness_n_mm2 = 8.0e5;  // 0.8 N m^2: braided hydraulic hose, 19 mm
  // Far below what a 2 mm wire rope alone would give: the drive train and the
  // routing through the proximal segments dominate.
  double cable_stiffness_n_per_mm = 4.0;
};
// With the defaults and the prototype: K = 42,600 N mm / rad and a bend loss
// of 16 %; the straight horizontal robot sags 51 mm and 9 deg at the tip.

// The tension that holds a bend stretches the cables in proportion to the
// moment each one carries. Equilibrium of the backbone's restoring moment
// EI b / L and the cables' moment 2 k r^2 (b_cmd - b) gives
//   b = b_cmd * 2 k r^2 / K,
// a bend loss of (EI / L) / K: zero for a straight segment, growing with the
// bend. The cables are pretensioned, so none goes slack in the workspace.
struct ComplianceConfig {
  bool enabled = true;
};

// The moment M of the tip load and of every distal segment's weight (lumped at
// its arc midpoint) about the base of segment i bends that segment by M / K
// further, in the direction of gravity. The tip load, lumped at the end disk,
// is the end platform's own mass plus the payload of the sample (see
// PayloadConfig). The sag moves the masses, so the equilibrium is found by
// fixed-point iteration.
struct GravityConfig {
  bool enabled = true;
  Eigen::Vector3d direction{-1.0, 0.0, 0.0};  // in the base frame; normalised on use
  double acceleration_m_per_s2 = 9.81;
  double segment_mass_kg = 0.25;   // backbone, disks and passing cables
  double platform_mass_kg = 0.2;   // end platform and markers
};
// A tip force F bends segment i by F l_i / K, l_i the lever arm from its base
// to the tip, and the bends of the proximal segments swing the whole distal
// robot: with the defaults, the first kilogram of payload sags the tip of the
// straight horizontal prototype by 75 mm more and tilts it by 14 deg (63 to
// 81 mm over the paper's workspace), a little less for each further one as
// the sag shortens the lever arms.

// A payload carried by the end platform, known per sample (a dataset column):
// a tool, a gripped object. It is drawn per sample, uniform in
// [min_kg, max_kg], from a stream of its own, so the configurations and the
// noise are those of the same session without it. It loads the tip through
// gravity: with gravity off it weighs nothing. Off, every sample carries none
// and the dataset has no payload column.
struct PayloadConfig {
  bool enabled = false;
  double min_kg = 0.0;
  double max_kg = 0.0;
};

// Each component of each segment's achieved bend vector
// b = theta (cos alpha, sin alpha) moves by a zero-mean normal, independently
// per sample. The bend vector (unlike alpha) is well defined for a straight
// segment, so the perturbation is the same everywhere.
struct RepeatabilityConfig {
  bool enabled = true;
  double bend_sigma_rad = 0.003;
};

// Noise on the reported pose: a normal position error per axis and a rotation
// exp(hat(n)) with n normal per axis, applied in the base frame.
struct MocapNoiseConfig {
  bool enabled = true;
  double position_sigma_mm = 0.5;
  double rotation_sigma_rad = 0.2 * model::kRadiansPerDegree;
};

// Source 7. Per cable c, rate-independent friction between the commanded
// length x (what the drive sets) and the effective length e (what bends the
// segment): a Prandtl-Ishlinskii operator whose density of play widths is
// continuous on (0, R_c], discretised at the midpoints of kOperators equal
// bins, r_k = R_c (k + 1/2) / kOperators:
//
//   p_k <- clamp(p_k + dx, -r_k, r_k)      (dx: the change of x)
//   e    = x - sum_k w_k p_k,   w_k = W_c f_c(r_k / R_c) / sum_j f_c(r_j / R_c)
//   f_c(u) = 1 + s_c (2 u - 1)             (a linear density, slope s_c)
//
// The total weight W_c < 1, so right after a reversal e still moves with
// slope 1 - W_c and then bends smoothly back to slope 1 as ever wider
// plays saturate: a rounded loop, no dead band. After a long move in one
// direction every p_k = +-r_k: e trails x by the cable's maximum lag
//   L_c = sum_k w_k r_k,
// which is the loop's half-width. Per cable, drawn once per seed (its own
// stream, so the other sources keep their values): L_c uniform in
// [max_lag_min_mm, max_lag_max_mm], W_c uniform in [total_weight_min,
// total_weight_max], s_c uniform in [-density_slope_max, density_slope_max];
// R_c follows from L_c. With the defaults R_c < 1.9 mm, and every cable
// travels 4.7 mm (the prototype) on the last leg of the homing move, more
// than 2 R_c: after homing the state no longer depends on where it was.
//
// At power-up the state is unknown: each cable's plays are left by a random
// history (kPowerUpMoves moves uniform in [-2 R_c, 2 R_c]) drawn from the
// session seed, so every session of the same robot starts differently.
// Only the path of x matters, not its speed: a move along a straight line in
// cable space changes every cable monotonically and is one clamp per play.
struct HysteresisConfig {
  static constexpr int kOperators = 16;
  static constexpr int kPowerUpMoves = 5;

  bool enabled = false;
  double max_lag_min_mm = 0.4;
  double max_lag_max_mm = 0.7;
  double total_weight_min = 0.85;
  double total_weight_max = 0.95;
  double density_slope_max = 0.4;
};

// A session with hysteresis is recorded as a motion sequence: the homing
// move, then row to row along straight lines in cable space. Every cable
// moves at most at cable_speed, all arrive together (a move lasts the
// largest cable change / speed), and the robot settles for settle_s before
// each row is measured (and at each stop of the homing move). t = 0 is the
// end of the homing move: the robot at home, settled (as the independent
// robot of tools/bench records its sessions).
struct MotionSequenceConfig {
  double cable_speed_mm_per_s = 10.0;
  double settle_s = 0.5;
};

// The per-sample noise of a session with hysteresis (cdcr simulate
// --hysteresis): the friction the repeatability source stood for is now
// modelled (source 7), so what remains is a small residual, and the motion
// capture is a good optical system. The noise floor is then about 0.67 mm and
// 0.16 deg on the prototype (700 rows, seed 1), against 2.2 mm and 0.54 deg
// with the default noise.
struct HysteresisSessionDefaults {
  static constexpr double kRepeatabilitySigmaRad = 0.00095;
  static constexpr double kMocapPositionSigmaMm = 0.1;
  static constexpr double kMocapRotationSigmaRad = 0.05 * model::kRadiansPerDegree;
};

struct SimulatorConfig {
  std::uint64_t seed = 1;
  // A data-collection session on the same robot: the robot's imperfections
  // come from `seed` alone, the sampled configurations and the noise from
  // (seed, session). Session 0 is the default data set; another session gives
  // an independent test set of the same physical robot.
  std::uint64_t session = 0;

  // The seed of the workspace and noise streams.
  std::uint64_t session_seed() const { return session == 0 ? seed : seed ^ (session * 0x9E3779B97F4A7C15ull); }
  // Upper limit of theta for the workspace sampler (alpha is uniform in
  // [-pi, pi], theta uniform in [0, this]). The design limit pi/2 is a
  // mechanical bound, not what the experiment sampled: the only
  // configurations the paper lists (Table 1) bend by 0.06-0.19 rad, which
  // a stiff braided-hose backbone makes plausible. 0.2 rad covers them.
  double workspace_theta_max_rad = 0.2;

  StructureConfig structure;
  GeometricErrorConfig geometric;
  CurvatureConfig curvature;
  ComplianceConfig compliance;
  GravityConfig gravity;
  PayloadConfig payload;
  RepeatabilityConfig repeatability;
  MocapNoiseConfig mocap_noise;
  HysteresisConfig hysteresis;
  MotionSequenceConfig motion;

  // Every source off: the simulator is the nominal model.
  static SimulatorConfig nominal_only();

  // Turns the hysteresis on with the noise of HysteresisSessionDefaults.
  void use_hysteresis_session();

  // Throws std::invalid_argument with a one-line message naming the field.
  void validate() const;
};

}  // namespace cdcr::sim
