#pragma once
// The predictive variance that the image carries to the board (model/
// gp_uncertainty.hpp evaluates it there), fitted in double precision, and
// the dense references it is tested against.
//
// Kernel coordinates z = (x - input_mean) / (input_scale * length_scale)
// throughout, so that the kernel without its amplitude is exp(-|z - z'|^2 / 2).

#include <cstdint>

#include <Eigen/Core>

#include "trained_model/trained_model.hpp"
#include "training_set.hpp"

namespace cdcr::training {

// z for raw encoded inputs (rows).
Eigen::MatrixXd kernel_coordinates(const TrainedModel& model, const Eigen::MatrixXd& inputs);

// The factors for variance points `points` (R x D, kernel coordinates) from
// the rows the model is fitted on (raw encoded inputs): L_u = chol(R_uu +
// jitter I), L_c = chol(I + (s/n) L_u^-1 R_uf R_fu L_u^-T). Calibration
// values are left at 1 (no scaling, no variance threshold).
VarianceFactor fit_variance_factor(const TrainedModel& model, const Eigen::MatrixXd& fitted_inputs,
                                   const Eigen::MatrixXd& points);

// R variance points for the fitted rows: k-means centres in kernel coordinates.
Eigen::MatrixXd variance_points(const TrainedModel& model, const Eigen::MatrixXd& fitted_inputs, int rank,
                                std::uint64_t seed);

// share(z) = latent variance / signal variance at the rows of z, from the
// factor (what the board computes, in double).
Eigen::VectorXd latent_share(const VarianceFactor& factor, const Eigen::MatrixXd& z);

// The exact GP's share on the rows `fitted_inputs` (raw) at z, by the dense
// formula 1 - r^T (R + (n/s) I)^-1 r: the reference for the factor.
Eigen::VectorXd exact_latent_share(const TrainedModel& model, const Eigen::MatrixXd& fitted_inputs,
                                   const Eigen::MatrixXd& z);

// The factor's latent share at each of `rows` (raw inputs, rows the factor
// was fitted on) with that row left out of the factor (the same variance
// points): what the board computes at a new input like it. The factor is
// C = I + (s/n) A A^T; without row i it is C - (s/n) a_i a_i^T, and by
// Sherman-Morrison a_i^T (C - (s/n) a_i a_i^T)^-1 a_i = q_i / (1 - (s/n) q_i),
// q_i = |L_c^-1 a_i|^2.
Eigen::VectorXd held_out_latent_share(const TrainedModel& model, const Eigen::MatrixXd& rows);

// The share above which the board flags a query as extrapolating: twice
// the 99th percentile of the held-out shares of the fitted rows (at most
// max_rows of them, drawn at random), or halfway from it to the prior (1)
// if that is lower, so that inputs like those the data visited stay
// unflagged wherever they lie, and a query beyond the data, where the share
// grows with the distance in the kernel's metric, is flagged.
double extrapolation_threshold(const TrainedModel& model, const Eigen::MatrixXd& fitted_inputs, int max_rows = 4000,
                               std::uint64_t seed = 1);

// The scales that make the radii hold `coverage` of the rows: the exact
// GP's leave-one-out residuals of the error twist on `set` (at most
// max_rows of its rows, drawn at random), mapped to the tip as the board
// maps the variance, against the radii the board computes there with the
// row left out (from the model's variance factor, held_out_latent_share();
// without one, from the leave-one-out variances): split conformal
// calibration with every row held out once.
// The position radius needs it most: the motion-capture orientation noise
// enters v and omega together (v = p x omega), and the outputs' independent
// GPs cannot see that its effect on the tip cancels.
struct RadiusCalibration {
  double position_scale = 1.0;
  double orientation_scale = 1.0;
  int rows = 0;
};
RadiusCalibration calibrate_radii(const TrainedModel& model, const TrainingSet& set, double coverage = 0.95,
                                  int max_rows = 1000, std::uint64_t seed = 1);

}  // namespace cdcr::training
