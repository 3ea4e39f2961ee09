// The trainer's GP against scikit-learn's GaussianProcessRegressor on the same
// data and hyperparameters, and its likelihood gradient against finite
// differences.

#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include <Eigen/LU>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "train/gaussian_process.hpp"
#include "train/hyperparameter_search.hpp"
#include "train/json_rows.hpp"

namespace cdcr::training {
namespace {

struct Problem {
  Eigen::MatrixXd x, y, queries;
  KernelHyperparameters h;
};

// A fixed, smooth two-output problem in three inputs with a little noise.
Problem make_problem() {
  std::mt19937_64 rng(20200219);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  std::normal_distribution<double> noise(0.0, 0.05);
  Problem p;
  p.x.resize(40, 3);
  p.y.resize(40, 2);
  for (int i = 0; i < 40; ++i) {
    for (int d = 0; d < 3; ++d) p.x(i, d) = u(rng);
    p.y(i, 0) = std::sin(p.x(i, 0)) + 0.3 * p.x(i, 1) * p.x(i, 2) + noise(rng);
    p.y(i, 1) = std::cos(0.5 * p.x(i, 1)) - 0.2 * p.x(i, 0) + noise(rng);
  }
  p.queries.resize(7, 3);
  for (int i = 0; i < 7; ++i) {
    for (int d = 0; d < 3; ++d) p.queries(i, d) = u(rng);
  }
  p.h.length_scales = Eigen::Vector3d(0.9, 1.7, 2.6);
  p.h.signal_variance = 1.3;
  p.h.noise_variance = 0.01;
  return p;
}

nlohmann::json run_sklearn(const Problem& p) {
  nlohmann::json request;
  request["x"] = json_rows(p.x);
  request["y"] = json_rows(p.y);
  request["queries"] = json_rows(p.queries);
  request["length_scales"] = std::vector<double>(p.h.length_scales.data(), p.h.length_scales.data() + 3);
  request["signal_variance"] = p.h.signal_variance;
  request["noise_variance"] = p.h.noise_variance;
  const std::string input = testing::TempDir() + "sklearn_request.json";
  const std::string output = testing::TempDir() + "sklearn_reply.json";
  std::ofstream(input) << request.dump();
  const std::string command =
      std::string(CDCR_PYTHON) + " " + CDCR_SKLEARN_SCRIPT + " < " + input + " > " + output;
  if (std::system(command.c_str()) != 0) {
    ADD_FAILURE() << "scikit-learn reference failed: " << command;
    return {};
  }
  std::ifstream reply(output);
  return nlohmann::json::parse(reply);
}

double relative_difference(double a, double b) { return std::abs(a - b) / std::max(std::abs(b), 1e-300); }

TEST(GaussianProcess, MatchesScikitLearnAtFixedHyperparameters) {
  const Problem p = make_problem();
  const nlohmann::json reference = run_sklearn(p);
  ASSERT_FALSE(reference.is_null());

  const LikelihoodResult lml = log_marginal_likelihood(p.x, p.y, p.h);
  EXPECT_LT(relative_difference(lml.log_marginal_likelihood, reference["log_marginal_likelihood"].get<double>()), 1e-6)
      << lml.log_marginal_likelihood << " vs " << reference["log_marginal_likelihood"];
  EXPECT_EQ(lml.jitter, 0.0);

  const Eigen::MatrixXd mean = GaussianProcess::fit(p.x, p.y, p.h).predict(p.queries);
  for (Eigen::Index i = 0; i < mean.rows(); ++i) {
    for (Eigen::Index k = 0; k < mean.cols(); ++k) {
      const double expected = reference["mean"][i][k].get<double>();
      EXPECT_LT(relative_difference(mean(i, k), expected), 1e-6) << "query " << i << " output " << k;
    }
  }

  // scikit-learn orders theta as [log c, log l_1..l_D, log noise].
  const auto& g = reference["gradient"];
  EXPECT_LT(relative_difference(lml.gradient[3], g[0].get<double>()), 1e-6);
  for (int d = 0; d < 3; ++d) {
    EXPECT_LT(relative_difference(lml.gradient[d], g[d + 1].get<double>()), 1e-6) << "length scale " << d;
  }
  EXPECT_LT(relative_difference(lml.gradient[4], g[4].get<double>()), 1e-6);
}

// The log marginal likelihood written out as the textbook gives it (Rasmussen
// and Williams, eq. 2.30), summed over the output columns: the kernel built
// entry by entry here, its inverse and determinant from a full-pivoting LU
// rather than the trainer's Cholesky factor.
TEST(GaussianProcess, LikelihoodMatchesTheDenseFormula) {
  const Problem p = make_problem();
  const Eigen::Index n = p.x.rows();
  Eigen::MatrixXd k(n, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    for (Eigen::Index j = 0; j < n; ++j) {
      double exponent = 0.0;
      for (Eigen::Index d = 0; d < p.x.cols(); ++d) {
        const double scaled = (p.x(i, d) - p.x(j, d)) / p.h.length_scales[d];
        exponent += scaled * scaled;
      }
      k(i, j) = p.h.signal_variance * std::exp(-0.5 * exponent) + (i == j ? p.h.noise_variance : 0.0);
    }
  }
  const Eigen::FullPivLU<Eigen::MatrixXd> lu(k);
  const double log_determinant = std::log(lu.determinant());
  double expected = 0.0;
  for (Eigen::Index c = 0; c < p.y.cols(); ++c) {
    const Eigen::VectorXd y = p.y.col(c);
    expected += -0.5 * y.dot(lu.solve(y)) - 0.5 * log_determinant - 0.5 * double(n) * std::log(2.0 * M_PI);
  }
  const LikelihoodResult lml = log_marginal_likelihood(p.x, p.y, p.h, false);
  EXPECT_LT(relative_difference(lml.log_marginal_likelihood, expected), 1e-9)
      << lml.log_marginal_likelihood << " vs " << expected;
}

TEST(GaussianProcess, LikelihoodGradientMatchesCentralDifferences) {
  const Problem p = make_problem();
  const Eigen::VectorXd theta = p.h.to_log();
  const Eigen::VectorXd analytic = log_marginal_likelihood(p.x, p.y, p.h).gradient;
  for (Eigen::Index i = 0; i < theta.size(); ++i) {
    constexpr double step = 1e-5;
    Eigen::VectorXd plus = theta;
    Eigen::VectorXd minus = theta;
    plus[i] += step;
    minus[i] -= step;
    const double numeric =
        (log_marginal_likelihood(p.x, p.y, KernelHyperparameters::from_log(plus), false).log_marginal_likelihood -
         log_marginal_likelihood(p.x, p.y, KernelHyperparameters::from_log(minus), false).log_marginal_likelihood) /
        (2 * step);
    EXPECT_NEAR(analytic[i], numeric, 1e-6 * std::max(1.0, std::abs(numeric))) << "parameter " << i;
  }
}

TEST(GaussianProcess, SearchImprovesTheLikelihoodAndStaysInBounds) {
  const Problem p = make_problem();
  SearchOptions options;
  options.restarts = 2;
  const double start = log_marginal_likelihood(p.x, p.y, default_initial_hyperparameters(3), false).log_marginal_likelihood;
  const SearchResult r = maximise_likelihood(p.x, p.y, default_initial_hyperparameters(3), options);
  EXPECT_GT(r.log_marginal_likelihood, start);
  EXPECT_EQ(r.optimisations_completed, 3);
  EXPECT_GE(r.hyperparameters.noise_variance, options.bounds.noise_variance_min * (1 - 1e-12));
  // At the optimum the gradient vanishes except against an active bound.
  const LikelihoodResult at = log_marginal_likelihood(p.x, p.y, r.hyperparameters);
  for (Eigen::Index i = 0; i < at.gradient.size(); ++i) {
    const bool at_bound = i < 3 && (r.hyperparameters.length_scales[i] >= options.bounds.length_scale_max * 0.999);
    if (!at_bound) {
      EXPECT_LT(std::abs(at.gradient[i]), 1e-2) << "parameter " << i;
    }
  }
}

TEST(GaussianProcess, JitterRescuesASingularKernel) {
  // Duplicate inputs with noise at its floor make K singular in floating point.
  Eigen::MatrixXd x(4, 1);
  x << 0.0, 0.0, 1.0, 1.0;
  Eigen::MatrixXd y(4, 1);
  y << 0.5, 0.5, -0.5, -0.5;
  KernelHyperparameters h;
  h.length_scales = Eigen::VectorXd::Constant(1, 1.0);
  h.signal_variance = 1.0;
  h.noise_variance = 1e-300;
  const LikelihoodResult r = log_marginal_likelihood(x, y, h);
  EXPECT_GT(r.jitter, 0.0);
  EXPECT_TRUE(std::isfinite(r.log_marginal_likelihood));
}

}  // namespace
}  // namespace cdcr::training
