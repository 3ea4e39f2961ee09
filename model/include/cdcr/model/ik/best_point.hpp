#pragma once
// The best point of a solve (ik_solver.hpp): the point with the lowest
// compensated residual evaluated exactly, and the last such point with its
// correction and tip, where the next target may start with the correction
// known (a warm start).

#include <limits>

#include "cdcr/model/ik/problem.hpp"
#include "cdcr/model/se3.hpp"
#include "cdcr/model/types.hpp"

namespace cdcr::model::ik {

template <typename S, int Max>
struct BestPoint {
  using Joints = JointVector<S, Max>;

  Joints bend;
  S cost = std::numeric_limits<S>::infinity();
  S position_error = std::numeric_limits<S>::infinity();
  S orientation_error = std::numeric_limits<S>::infinity();
  Joints warm_bend;
  Twist<S> warm_eps = Twist<S>::Zero();
  Pose<S> warm_tip{};

  bool exists() const { return cost < std::numeric_limits<S>::infinity(); }

  void forget() {
    cost = std::numeric_limits<S>::infinity();
    position_error = orientation_error = std::numeric_limits<S>::infinity();
  }

  void keep(const Joints& point, const Twist<S>& eps, const Pose<S>& tip, S point_cost, S point_position_error,
            S point_orientation_error) {
    cost = point_cost;
    position_error = point_position_error;
    orientation_error = point_orientation_error;
    bend = warm_bend = point;
    warm_eps = eps;
    warm_tip = tip;
  }

  // A new target: the warm start's tip was kept, only its residual is new.
  void rescore_warm_start(const Problem<S, Max>& problem) {
    Eigen::Matrix<S, 6, 1> residual;
    problem.residual_of(warm_tip, residual, position_error, orientation_error);
    cost = residual.squaredNorm();
    bend = warm_bend;
  }
};

}  // namespace cdcr::model::ik
