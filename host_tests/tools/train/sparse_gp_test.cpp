// The sparse (VFE) GP against references that do not share its code paths:
// with the inducing inputs on the training inputs it is the exact GP (its
// bound the exact likelihood, its mean the exact mean); its bound against
// the dense formula written out with N x N matrices; its analytic gradient
// against central differences, for the hyperparameters and every
// coordinate of every inducing input.
#include <cmath>
#include <random>
#include <stdexcept>

#include <Eigen/LU>
#include <gtest/gtest.h>

#include "train/gaussian_process.hpp"
#include "train/hyperparameter_search.hpp"
#include "train/sparse_gp.hpp"

namespace cdcr::training {
namespace {

struct Problem {
  Eigen::MatrixXd x, y;
  KernelHyperparameters h;
};

// Smooth outputs of three inputs with a little noise, two output columns.
Problem make_problem(int n) {
  std::mt19937_64 rng(77);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  std::normal_distribution<double> noise(0.0, 0.05);
  Problem p;
  p.x.resize(n, 3);
  p.y.resize(n, 2);
  for (int i = 0; i < n; ++i) {
    for (int d = 0; d < 3; ++d) p.x(i, d) = u(rng);
    p.y(i, 0) = std::sin(p.x(i, 0)) + 0.3 * p.x(i, 1) * p.x(i, 2) + noise(rng);
    p.y(i, 1) = std::cos(0.5 * p.x(i, 1)) - 0.2 * p.x(i, 0) + noise(rng);
  }
  p.h.length_scales = Eigen::Vector3d(0.9, 1.7, 2.6);
  p.h.signal_variance = 1.3;
  p.h.noise_variance = 0.02;
  return p;
}

SparseParameters sparse_parameters(const Problem& p, int m, std::uint64_t seed) {
  SparseParameters s;
  s.hyperparameters = p.h;
  s.inducing.resize(m, p.x.cols());
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  for (int i = 0; i < m; ++i) {
    for (Eigen::Index d = 0; d < p.x.cols(); ++d) s.inducing(i, d) = u(rng);
  }
  return s;
}

double relative_difference(double a, double b) { return std::abs(a - b) / std::max(std::abs(b), 1e-300); }

TEST(SparseGp, InducingInputsOnTheDataGiveTheExactGp) {
  const Problem p = make_problem(30);
  SparseParameters s;
  s.hyperparameters = p.h;
  s.inducing = p.x;
  const double exact = log_marginal_likelihood(p.x, p.y, p.h, false).log_marginal_likelihood;
  const SparseBound bound = sparse_bound(p.x, p.y, s, false);
  // K_uu's jitter (1e-8 of the signal variance) is all that separates them.
  EXPECT_LT(relative_difference(bound.value, exact), 1e-6) << bound.value << " vs " << exact;

  Eigen::MatrixXd queries(5, 3);
  queries << 0.1, -0.4, 1.2, -1.5, 0.3, 0.0, 1.9, 1.9, -1.9, 0.0, 0.0, 0.0, -0.7, 1.1, 0.5;
  const Eigen::MatrixXd exact_mean = GaussianProcess::fit(p.x, p.y, p.h).predict(queries);
  const Eigen::MatrixXd sparse_mean = SparseGaussianProcess::fit(p.x, p.y, s).predict(queries);
  EXPECT_LT((sparse_mean - exact_mean).cwiseAbs().maxCoeff(), 1e-5 * exact_mean.cwiseAbs().maxCoeff())
      << sparse_mean << "\nvs\n" << exact_mean;
}

// F = sum over columns of log N(y | 0, Q + s2 I) - tr(K_ff - Q) / (2 s2),
// with every matrix N x N and the determinant from a full-pivoting LU.
double dense_bound(const Problem& p, const SparseParameters& s) {
  const Eigen::Index n = p.x.rows();
  const Eigen::Index m = s.inducing.rows();
  const auto k = [&](const Eigen::RowVectorXd& a, const Eigen::RowVectorXd& b) {
    double e = 0.0;
    for (Eigen::Index d = 0; d < a.size(); ++d) {
      const double t = (a[d] - b[d]) / s.hyperparameters.length_scales[d];
      e += t * t;
    }
    return s.hyperparameters.signal_variance * std::exp(-0.5 * e);
  };
  Eigen::MatrixXd k_uu(m, m), k_fu(n, m);
  for (Eigen::Index i = 0; i < m; ++i) {
    for (Eigen::Index j = 0; j < m; ++j) k_uu(i, j) = k(s.inducing.row(i), s.inducing.row(j));
  }
  k_uu.diagonal().array() += 1e-8 * s.hyperparameters.signal_variance;  // the implementation's jitter
  for (Eigen::Index i = 0; i < n; ++i) {
    for (Eigen::Index j = 0; j < m; ++j) k_fu(i, j) = k(p.x.row(i), s.inducing.row(j));
  }
  const Eigen::MatrixXd q = k_fu * k_uu.fullPivLu().solve(k_fu.transpose());
  Eigen::MatrixXd sigma = q;
  sigma.diagonal().array() += s.hyperparameters.noise_variance;
  const Eigen::FullPivLU<Eigen::MatrixXd> lu(sigma);
  double value = 0.0;
  for (Eigen::Index c = 0; c < p.y.cols(); ++c) {
    const Eigen::VectorXd y = p.y.col(c);
    value += -0.5 * y.dot(lu.solve(y)) - 0.5 * std::log(lu.determinant()) - 0.5 * double(n) * std::log(2.0 * M_PI);
    value -= (double(n) * s.hyperparameters.signal_variance - q.trace()) / (2.0 * s.hyperparameters.noise_variance);
  }
  return value;
}

TEST(SparseGp, BoundMatchesTheDenseFormulaAndLiesBelowTheExactLikelihood) {
  const Problem p = make_problem(40);
  const double exact = log_marginal_likelihood(p.x, p.y, p.h, false).log_marginal_likelihood;
  for (const int m : {3, 8, 15}) {
    const SparseParameters s = sparse_parameters(p, m, 100 + m);
    const double bound = sparse_bound(p.x, p.y, s, false).value;
    EXPECT_LT(relative_difference(bound, dense_bound(p, s)), 1e-8) << "M = " << m;
    EXPECT_LT(bound, exact) << "M = " << m;
  }
}

TEST(SparseGp, GradientMatchesCentralDifferences) {
  const Problem p = make_problem(40);
  const SparseParameters s = sparse_parameters(p, 7, 5);
  const Eigen::VectorXd v = s.to_vector();
  const SparseBound analytic = sparse_bound(p.x, p.y, s);
  ASSERT_EQ(analytic.gradient.size(), v.size());
  const auto value_at = [&](const Eigen::VectorXd& w) {
    return sparse_bound(p.x, p.y, SparseParameters::from_vector(w, 3), false).value;
  };
  const double step = 1e-5;
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    Eigen::VectorXd plus = v, minus = v;
    plus[i] += step;
    minus[i] -= step;
    const double numeric = (value_at(plus) - value_at(minus)) / (2.0 * step);
    EXPECT_NEAR(analytic.gradient[i], numeric, 1e-5 * std::max(1.0, std::abs(numeric))) << "parameter " << i;
  }
}

TEST(SparseGp, ParametersRoundTripThroughTheVector) {
  const Problem p = make_problem(10);
  const SparseParameters s = sparse_parameters(p, 4, 9);
  const SparseParameters back = SparseParameters::from_vector(s.to_vector(), 3);
  EXPECT_EQ(back.inducing, s.inducing);
  EXPECT_NEAR(back.hyperparameters.noise_variance, s.hyperparameters.noise_variance, 1e-15);
  EXPECT_LT((back.hyperparameters.length_scales - s.hyperparameters.length_scales).norm(), 1e-14);
}

TEST(SparseGp, InitialInducingInputsAreDistinctRowsOfTheData) {
  const Problem p = make_problem(50);
  const Eigen::MatrixXd z = initial_inducing_inputs(p.x, 12, 3);
  ASSERT_EQ(z.rows(), 12);
  for (Eigen::Index i = 0; i < z.rows(); ++i) {
    bool found = false;
    for (Eigen::Index r = 0; r < p.x.rows(); ++r) found = found || p.x.row(r) == z.row(i);
    EXPECT_TRUE(found) << "inducing input " << i;
    for (Eigen::Index j = 0; j < i; ++j) EXPECT_NE(z.row(i), z.row(j)) << i << " and " << j;
  }
  EXPECT_THROW(initial_inducing_inputs(p.x, 51, 3), std::invalid_argument);
}

// On a smooth function a few inducing inputs, optimised with the
// hyperparameters, predict what the exact GP with its own optimised
// hyperparameters predicts, and the bound comes close to its likelihood.
TEST(SparseGp, OptimisedInducingInputsApproachTheExactGp) {
  const Problem p = make_problem(200);
  const SearchResult exact = maximise_likelihood(p.x, p.y, default_initial_hyperparameters(3));
  SparseParameters start;
  start.hyperparameters = default_initial_hyperparameters(3);
  start.inducing = initial_inducing_inputs(p.x, 25, 1);
  const double start_bound = sparse_bound(p.x, p.y, start, false).value;
  const SparseSearchResult sparse = maximise_sparse_bound(p.x, p.y, start);
  EXPECT_GT(sparse.bound, start_bound);
  EXPECT_LT(sparse.bound, exact.log_marginal_likelihood);
  EXPECT_GT(sparse.bound, exact.log_marginal_likelihood - 0.02 * std::abs(exact.log_marginal_likelihood))
      << sparse.bound << " vs " << exact.log_marginal_likelihood;

  const Problem q = make_problem(300);  // other points of the same functions
  const Eigen::MatrixXd queries = q.x.bottomRows(100);
  const Eigen::MatrixXd exact_mean = GaussianProcess::fit(p.x, p.y, exact.hyperparameters).predict(queries);
  const Eigen::MatrixXd sparse_mean = SparseGaussianProcess::fit(p.x, p.y, sparse.parameters).predict(queries);
  const double rms_difference = std::sqrt((sparse_mean - exact_mean).squaredNorm() / double(exact_mean.size()));
  EXPECT_LT(rms_difference, 0.02) << "the noise is 0.05";
}

}  // namespace
}  // namespace cdcr::training
