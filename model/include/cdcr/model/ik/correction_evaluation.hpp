#pragma once
// The corrections an IK solve evaluates: sliced ones (GpCorrection) as they
// come, any other evaluated whole, as one unit (ik_solver.hpp).

#include <cstdint>
#include <type_traits>
#include <utility>

#include "cdcr/model/status.hpp"
#include "cdcr/model/types.hpp"

namespace cdcr::model {

// Corrections the solver can evaluate in slices. A correction type provides
//   using Evaluation = ...;   // the state of one evaluation in progress
//   Status begin_evaluation(const JointVector<S, Max>& bend, Evaluation&, bool with_gradient) const;
//   std::uint32_t continue_evaluation(Evaluation&, std::uint32_t max_units) const;  // units spent
//   bool evaluation_finished(const Evaluation&) const;
//   bool evaluation_has_gradient(const Evaluation&) const;
//   void evaluation_result(const Evaluation&, Twist<S>& eps, Jacobian<S, Max>& d_eps_d_bend) const;
// (GpCorrection does: a unit is a training point of the mean.) Any other
// correction callable as Status(bend, eps, d_eps_d_bend) (with a gradient),
// or offering Status value(bend, eps) (without), is evaluated whole, as one
// unit.
template <typename Correction, typename = void>
struct is_sliced_correction : std::false_type {};
template <typename Correction>
struct is_sliced_correction<Correction, std::void_t<typename Correction::Evaluation>> : std::true_type {};

// The identity correction: the nominal model.
struct NoCorrection {
  template <typename Bend, typename S>
  Status value(const Bend&, Twist<S>& eps) const {
    eps.setZero();
    return Status::ok;
  }
};

namespace detail {

template <typename Correction, typename Bend, typename TwistType, typename = void>
struct has_value_only : std::false_type {};
template <typename Correction, typename Bend, typename TwistType>
struct has_value_only<Correction, Bend, TwistType,
                      std::void_t<decltype(std::declval<const Correction&>().value(std::declval<const Bend&>(),
                                                                                   std::declval<TwistType&>()))>>
    : std::true_type {};

template <typename Correction, typename Bend, typename TwistType, typename DerivativeType, typename = void>
struct has_gradient : std::false_type {};
template <typename Correction, typename Bend, typename TwistType, typename DerivativeType>
struct has_gradient<Correction, Bend, TwistType, DerivativeType,
                    std::void_t<decltype(std::declval<const Correction&>()(std::declval<const Bend&>(),
                                                                           std::declval<TwistType&>(),
                                                                           std::declval<DerivativeType&>()))>>
    : std::true_type {};

// Adapts a correction that is evaluated in one call to the sliced interface.
template <typename S, int Max, typename Correction>
struct WholeEvaluation {
  static constexpr bool kHasGradient = has_gradient<Correction, JointVector<S, Max>, Twist<S>, Jacobian<S, Max>>::value;
  const Correction* correction = nullptr;

  struct Evaluation {
    JointVector<S, Max> bend;
    Twist<S> eps = Twist<S>::Zero();
    Jacobian<S, Max> d_eps;
    bool finished = false;
    bool with_gradient = false;
  };

  Status begin_evaluation(const JointVector<S, Max>& bend, Evaluation& evaluation, bool with_gradient) const {
    evaluation.bend = bend;
    evaluation.finished = false;
    evaluation.with_gradient = with_gradient && kHasGradient;
    return Status::ok;
  }
  Status finish(Evaluation& evaluation) const {
    evaluation.finished = true;
    evaluation.d_eps.setZero(6, evaluation.bend.size());
    if constexpr (kHasGradient) {
      if (evaluation.with_gradient || !has_value_only<Correction, JointVector<S, Max>, Twist<S>>::value) {
        const Status s = (*correction)(evaluation.bend, evaluation.eps, evaluation.d_eps);
        if (s == Status::ok && evaluation.d_eps.cols() != evaluation.bend.size()) return Status::correction_failed;
        return s;
      }
    }
    if constexpr (has_value_only<Correction, JointVector<S, Max>, Twist<S>>::value) {
      return correction->value(evaluation.bend, evaluation.eps);
    } else {
      return Status::correction_failed;
    }
  }
  bool evaluation_finished(const Evaluation& evaluation) const { return evaluation.finished; }
  bool evaluation_has_gradient(const Evaluation& evaluation) const { return evaluation.with_gradient; }
  void evaluation_result(const Evaluation& evaluation, Twist<S>& eps, Jacobian<S, Max>& d_eps) const {
    eps = evaluation.eps;
    d_eps = evaluation.d_eps;
  }
};

}  // namespace detail

namespace ik {

// The correction evaluation in progress and its point: a sliced correction
// evaluated as it comes, any other whole (detail::WholeEvaluation); none
// bound: the nominal model.
template <typename S, int Max, typename Correction>
class CorrectionEvaluation {
  static constexpr bool kSliced = is_sliced_correction<Correction>::value;
  using Evaluator = std::conditional_t<kSliced, Correction, detail::WholeEvaluation<S, Max, Correction>>;

 public:
  using Joints = JointVector<S, Max>;
  static constexpr bool kOffersGradient = kSliced || detail::WholeEvaluation<S, Max, Correction>::kHasGradient;

  void bind(const Correction* correction) {
    if (correction == nullptr) {
      evaluator_ = nullptr;
    } else if constexpr (kSliced) {
      evaluator_ = correction;
    } else {
      whole_.correction = correction;
      evaluator_ = &whole_;
    }
  }
  bool bound() const { return evaluator_ != nullptr; }

  Status begin(const Joints& bend, bool with_gradient) {
    point_ = bend;
    return evaluator_->begin_evaluation(point_, evaluation_, with_gradient);
  }
  // Goes on within max_units; returns the units spent. A whole evaluation
  // counts one unit, and reports its failure in `status`.
  std::uint32_t advance(std::uint32_t max_units, Status& status) {
    if constexpr (kSliced) {
      return evaluator_->continue_evaluation(evaluation_, max_units);
    } else {
      (void)max_units;
      status = whole_.finish(evaluation_);
      return 1;
    }
  }
  bool finished() const { return evaluator_->evaluation_finished(evaluation_); }
  bool has_gradient() const { return evaluator_->evaluation_has_gradient(evaluation_); }
  void result(Twist<S>& eps, Jacobian<S, Max>& gradient) const {
    evaluator_->evaluation_result(evaluation_, eps, gradient);
  }
  const Joints& point() const { return point_; }

 private:
  const Evaluator* evaluator_ = nullptr;
  detail::WholeEvaluation<S, Max, Correction> whole_{};
  typename Evaluator::Evaluation evaluation_{};
  Joints point_;
};

}  // namespace ik

}  // namespace cdcr::model
