#include "hyperparameter_search.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <optional>
#include <random>
#include <stdexcept>
#include <thread>
#include <vector>

#include "lapack.hpp"
#include "search_setup.hpp"

namespace cdcr::training {

KernelHyperparameters default_initial_hyperparameters(int input_dims) {
  KernelHyperparameters h;
  h.length_scales = Eigen::VectorXd::Ones(input_dims);
  h.signal_variance = 1.0;
  h.noise_variance = 0.1;
  return h;
}

namespace {

// The optimiser's parameter vector: ARD uses the full log-parameter vector;
// the isotropic kernel ties every length scale to its first entry.
struct ParameterMap {
  int input_dims;
  bool isotropic;

  int size() const { return isotropic ? 3 : input_dims + 2; }

  Eigen::VectorXd expand(const Eigen::VectorXd& p) const {
    if (!isotropic) return p;
    Eigen::VectorXd full(input_dims + 2);
    full.head(input_dims).setConstant(p[0]);
    full.tail<2>() = p.tail<2>();
    return full;
  }

  Eigen::VectorXd reduce_gradient(const Eigen::VectorXd& g) const {
    if (!isotropic) return g;
    Eigen::VectorXd r(3);
    r << g.head(input_dims).sum(), g.tail<2>();
    return r;
  }
};

struct NegativeLikelihood {
  const Eigen::MatrixXd& x;
  const Eigen::MatrixXd& y;
  ParameterMap map;
  int evaluations = 0;
  LikelihoodWorkspace workspace;

  double operator()(const Eigen::VectorXd& p, Eigen::VectorXd& gradient) {
    ++evaluations;
    const LikelihoodResult r =
        log_marginal_likelihood(x, y, KernelHyperparameters::from_log(map.expand(p)), true, workspace);
    gradient = -map.reduce_gradient(r.gradient);
    return -r.log_marginal_likelihood;
  }
};

}  // namespace

SearchResult maximise_likelihood(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y,
                                 const KernelHyperparameters& initial, const SearchOptions& options) {
  const ParameterMap map{static_cast<int>(x.cols()), options.isotropic};
  const int d = map.size() - 2;  // length-scale entries in the optimiser's vector
  Eigen::VectorXd lower(d + 2);
  Eigen::VectorXd upper(d + 2);
  detail::set_hyperparameter_box(options.bounds, d, lower, upper);
  // Each solver keeps a reference to its settings: they must outlive it.
  const LBFGSpp::LBFGSBParam<double> settings = detail::lbfgsb_parameters(options);

  // Restarts are drawn log-uniformly from a box of plausible values for
  // normalised data rather than from the whole search bounds, most of which
  // are degenerate (every point its own cluster, or one flat function).
  // All starting points are drawn up front, so they do not depend on how
  // the starts are spread over threads.
  std::mt19937_64 rng(options.seed);
  std::uniform_real_distribution<double> length_draw(std::log(0.1), std::log(10.0));
  std::uniform_real_distribution<double> signal_draw(std::log(0.1), std::log(10.0));
  std::uniform_real_distribution<double> noise_draw(std::log(1e-4), std::log(1.0));
  const int starts = options.restarts + 1;
  std::vector<Eigen::VectorXd> start_points(static_cast<std::size_t>(starts));
  for (int start = 0; start < starts; ++start) {
    Eigen::VectorXd p(d + 2);
    if (start == 0) {
      const Eigen::VectorXd full = initial.to_log();
      if (options.isotropic) {
        p << full.head(map.input_dims).mean(), full.tail<2>();
      } else {
        p = full;
      }
    } else {
      for (int i = 0; i < d; ++i) p[i] = length_draw(rng);
      p[d] = signal_draw(rng);
      p[d + 1] = noise_draw(rng);
    }
    start_points[static_cast<std::size_t>(start)] = p.cwiseMax(lower).cwiseMin(upper);
  }

  struct StartOutcome {
    Eigen::VectorXd p;
    double lml = 0.0;
    bool completed = false;
    int evaluations = 0;
  };
  std::vector<StartOutcome> outcomes(static_cast<std::size_t>(starts));
  auto run_start = [&](int start) {
    StartOutcome& outcome = outcomes[static_cast<std::size_t>(start)];
    NegativeLikelihood objective{x, y, map, 0, {}};
    LBFGSpp::LBFGSBSolver<double> solver(settings);
    outcome.p = start_points[static_cast<std::size_t>(start)];
    double negative_lml = 0.0;
    try {
      solver.minimize(objective, outcome.p, negative_lml, lower, upper);
    } catch (const std::exception&) {
      // A line search that cannot progress leaves p at its last accepted
      // point, which is still a valid candidate; a factorisation failure is
      // re-raised below by the evaluation.
    }
    outcome.evaluations = objective.evaluations;
    try {
      outcome.lml = log_marginal_likelihood(x, y, KernelHyperparameters::from_log(map.expand(outcome.p)), false,
                                            objective.workspace)
                        .log_marginal_likelihood;
      outcome.completed = true;
    } catch (const std::exception&) {
    }
  };

  // The BLAS runs each call on the calling thread (unless
  // OPENBLAS_NUM_THREADS asks otherwise): on a shared machine, waiting in
  // every call for a second BLAS thread that another process holds costs
  // far more than the thread gains (13x slower per evaluation, measured on
  // the 2-core development machine under load). The cores are used by
  // running the independent starts side by side, one per core.
  std::optional<blas_threads::SingleThreaded> single_threaded_blas;
  if (std::getenv("OPENBLAS_NUM_THREADS") == nullptr) single_threaded_blas.emplace();
  const int workers = std::min(starts, static_cast<int>(std::max(1u, std::thread::hardware_concurrency())));
  if (workers > 1) {
    std::atomic<int> next{0};
    std::vector<std::thread> threads;
    for (int w = 0; w < workers; ++w) {
      threads.emplace_back([&] {
        for (int start = next++; start < starts; start = next++) run_start(start);
      });
    }
    for (std::thread& t : threads) t.join();
  } else {
    run_start(0);
  }

  SearchResult best;
  best.log_marginal_likelihood = -std::numeric_limits<double>::infinity();
  for (const StartOutcome& outcome : outcomes) {
    best.likelihood_evaluations += outcome.evaluations;
    if (!outcome.completed) continue;
    ++best.optimisations_completed;
    if (outcome.lml > best.log_marginal_likelihood) {
      best.log_marginal_likelihood = outcome.lml;
      best.hyperparameters = KernelHyperparameters::from_log(map.expand(outcome.p));
    }
  }
  if (best.optimisations_completed == 0) {
    throw std::runtime_error("hyperparameter search failed from every start");
  }
  return best;
}

}  // namespace cdcr::training
