#pragma once
// The correction between its evaluations (ik_solver.hpp): the last
// evaluated point, its correction eps_k, and the slope E learned from the
// evaluations, so that away from b_k the correction is extrapolated as
// eps_k + E (b - b_k).

#include <type_traits>

#include "cdcr/model/ik/options.hpp"
#include "cdcr/model/ik/solve_flow.hpp"
#include "cdcr/model/types.hpp"

namespace cdcr::model::ik {

template <typename S, int Max>
struct Linearisation {
  using Joints = JointVector<S, Max>;
  // Secant steps shorter than this (rad of bend) are not learned from.
  static constexpr S kMinSecantStep = std::is_same_v<S, float> ? S(1e-4) : S(1e-8);

  // The point whose correction is evaluated (the linearisation in use), its
  // correction and, when the evaluation brought it, its gradient.
  Joints point;
  Twist<S> eps = Twist<S>::Zero();
  Jacobian<S, Max> gradient;
  // The outer point before it, for the secant rule.
  Joints previous_point;
  Twist<S> previous_eps = Twist<S>::Zero();
  S previous_cost = S(0);
  Jacobian<S, Max> slope;

  // The linearised compensated model's correction: eps_k + E (b - b_k).
  Twist<S> eps_at(const Joints& bend, const SolveFlow& flow) const {
    Twist<S> result = eps;
    if (flow.slope_known()) result.noalias() += slope.lazyProduct(bend - point);
    return result;
  }

  // The slope at a new point: its gradient when the evaluation brought one,
  // else a secant update from the last outer point to this one.
  void learn_slope(const IkSolverOptions<S>& options, SolveFlow& flow) {
    if (flow.evaluated_with_gradient()) {
      slope = gradient;
      flow.on(slope.allFinite() ? Event::slope_set : Event::slope_lost);
    } else if (options.secant_updates && flow.has_previous()) {
      // Steps below the arithmetic's resolution carry only noise.
      const Joints step = point - previous_point;
      const S step_sq = step.squaredNorm();
      if (step_sq > kMinSecantStep * kMinSecantStep) {
        if (!flow.slope_known()) {
          slope.setZero(6, point.size());
          flow.on(Event::slope_set);
        }
        const Twist<S> predicted = previous_eps + slope.lazyProduct(step);
        slope.noalias() += ((eps - predicted) / step_sq).lazyProduct(step.transpose());
        if (!slope.allFinite()) flow.on(Event::slope_lost);
      }
    }
  }

  // This point becomes the last outer point.
  void remember(S cost) {
    previous_point = point;
    previous_eps = eps;
    previous_cost = cost;
  }
};

}  // namespace cdcr::model::ik
