#pragma once
// A motion sequence made in the test, independent of the simulator: the
// robot walks at random from home along straight lines in cable space
// (steps from a fraction of a millimetre of cable, inside a reversal's dead
// band, to several millimetres); its cables pass through a known hysteresis
// model; the measured pose is the nominal pose of the effective lengths
// times a smooth error the GP can learn, plus small noise.
#include <cmath>
#include <random>
#include <vector>

#include "cdcr/model/chain.hpp"
#include "cdcr/model/compensation.hpp"
#include "cdcr/model/hysteresis.hpp"
#include "dataset/dataset.hpp"

namespace cdcr::training::test {

// Two segments of the prototype's size: eight cables keep the per-cable
// search short.
inline model::RobotGeometry<double> two_segment_geometry() {
  return model::RobotGeometry<double>::uniform(2, 120.0, 67.0);
}

// K = 1, weight 1: the operator of the robot, widths 0.3..0.7 mm.
inline model::HysteresisModel<double> known_hysteresis(const model::RobotGeometry<double>& geometry) {
  static constexpr double kWidthsMm[8] = {0.30, 0.70, 0.45, 0.60, 0.35, 0.55, 0.65, 0.40};
  model::HysteresisModel<double> m;
  m.cables = 4 * geometry.segment_count;
  m.operators = 1;
  for (int c = 0; c < m.cables; ++c) {
    m.widths_mm[c][0] = kWidthsMm[c % 8];
    m.weights[c][0] = 1.0;
  }
  model::CableVector<double> approach, home;
  model::homing_waypoints(geometry, approach, home);
  model::compute_homing_lags(m, approach, home);
  return m;
}

struct SyntheticSequence {
  dataset::Dataset data;
  Eigen::MatrixXd effective_mm;  // the true effective lengths
};

// `session_rows`: the rows of each session; every session starts at home.
// An empty hysteresis model records the commanded lengths' poses.
// last_move_effect_mm: friction that is no lag of a length, a tip offset
// along z of that size times the direction of cable 1's last move (+1
// longer, -1 shorter, 0 before it has moved in the session).
inline SyntheticSequence synthetic_sequence(const model::RobotGeometry<double>& geometry,
                                            const model::HysteresisModel<double>& hysteresis,
                                            const std::vector<int>& session_rows, unsigned seed,
                                            double position_noise_mm = 0.05, double last_move_effect_mm = 0.0) {
  const int n = geometry.segment_count;
  int rows = 0;
  for (const int r : session_rows) rows += r;
  SyntheticSequence s;
  dataset::Dataset& d = s.data;
  d.segment_count = n;
  d.has_poses = true;
  d.has_time = true;
  d.cables_mm.resize(rows, 4 * n);
  d.time_s.resize(rows);
  s.effective_mm.resize(rows, 4 * n);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  model::HysteresisState<double> state;
  int row = 0;
  for (const int count : session_rows) {
    d.session_starts.push_back(row);
    if (!hysteresis.empty()) model::start_at_home(state, hysteresis, geometry);
    Eigen::VectorXd bend = Eigen::VectorXd::Zero(2 * n);
    double last_move = 0.0;
    for (int i = 0; i < count; ++i, ++row) {
      // A step of log-uniform size between 0.002 and 0.25 rad of bend.
      const double size = 0.002 * std::pow(125.0, unit(rng));
      Eigen::VectorXd step(2 * n);
      for (int j = 0; j < 2 * n; ++j) step[j] = gauss(rng);
      bend += size * step / step.norm();
      for (int k = 0; k < n; ++k) {
        const double norm = bend.segment<2>(2 * k).norm();
        if (norm > 0.9) bend.segment<2>(2 * k) *= 0.9 / norm;
      }
      model::CableVector<double> cables;
      model::cables_from_joints(model::JointVector<double>(model::joints_from_bend(bend)), geometry, cables);
      d.cables_mm.row(row) = cables.transpose();
      if (i > 0 && cables[0] != d.cables_mm(row - 1, 0)) last_move = cables[0] > d.cables_mm(row - 1, 0) ? 1.0 : -1.0;
      d.time_s[row] = 0.5 * row;
      model::CableVector<double> effective = cables;
      if (!hysteresis.empty()) {
        model::update_hysteresis(state, hysteresis, cables);
        model::effective_lengths(state, hysteresis, effective);
      }
      s.effective_mm.row(row) = effective.transpose();
      model::JointVector<double> joints;
      model::joints_from_cables(effective, geometry, joints);
      const model::JointVector<double> b = model::bend_from_joints(joints);
      const model::Pose<double> nominal = model::forward_kinematics_bend(b, geometry);
      // A smooth error of a few millimetres: the GP's part.
      model::Twist<double> error;
      error << 3.0 * std::sin(2.0 * b[0]) + 1.5 * b[3], 2.0 * std::cos(1.5 * b[1]) - 2.0, 2.5 * b[0] * b[2],
          0.01 * std::sin(b[2]), 0.008 * b[1], 0.012 * std::cos(b[3]) - 0.012;
      model::Pose<double> measured = model::compensate(error, nominal);
      measured.position_mm.z() += last_move_effect_mm * last_move;
      for (int j = 0; j < 3; ++j) measured.position_mm[j] += position_noise_mm * gauss(rng);
      d.poses.push_back(measured);
    }
  }
  return s;
}

}  // namespace cdcr::training::test
