#pragma once
// The types Eigen's Levenberg-Marquardt solver asks of a residual functor
// with a size known only at run time; the trainer's identification steps
// (calibration, compliance) derive their residuals from it.

#include <Eigen/Dense>

namespace cdcr::training {

struct DynamicSizeResiduals {
  using Scalar = double;
  enum { InputsAtCompileTime = Eigen::Dynamic, ValuesAtCompileTime = Eigen::Dynamic };
  using InputType = Eigen::VectorXd;
  using ValueType = Eigen::VectorXd;
  using JacobianType = Eigen::MatrixXd;
};

}  // namespace cdcr::training
