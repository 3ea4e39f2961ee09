#include "sparse_gp.hpp"

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include <Eigen/Cholesky>
#include "search_setup.hpp"

namespace cdcr::training {

namespace {

constexpr double kPi = 3.14159265358979323846;

// K_uu needs a little jitter whatever the hyperparameters: inducing inputs
// may come close to one another. It grows by decades until the Cholesky
// factorisation succeeds.
struct InducingFactor {
  Eigen::LLT<Eigen::MatrixXd> llt;
  double jitter = 0.0;
};

InducingFactor factorise_inducing(Eigen::MatrixXd k_uu, double signal_variance) {
  InducingFactor f;
  double jitter = 1e-8 * signal_variance;
  k_uu.diagonal().array() += jitter;
  f.llt.compute(k_uu);
  while (f.llt.info() != Eigen::Success) {
    if (jitter > 1e-2 * signal_variance) {
      throw std::runtime_error("inducing kernel matrix is not positive definite even with jitter");
    }
    k_uu.diagonal().array() += 9.0 * jitter;
    jitter *= 10.0;
    f.jitter = jitter - 1e-8 * signal_variance;
    f.llt.compute(k_uu);
  }
  return f;
}

}  // namespace

Eigen::VectorXd SparseParameters::to_vector() const {
  const Eigen::Index d = hyperparameters.length_scales.size();
  Eigen::VectorXd v(d + 2 + inducing.size());
  v.head(d + 2) = hyperparameters.to_log();
  for (Eigen::Index m = 0; m < inducing.rows(); ++m) v.segment(d + 2 + m * d, d) = inducing.row(m).transpose();
  return v;
}

SparseParameters SparseParameters::from_vector(const Eigen::VectorXd& vector, int input_dims) {
  const Eigen::Index d = input_dims;
  SparseParameters p;
  p.hyperparameters = KernelHyperparameters::from_log(vector.head(d + 2));
  const Eigen::Index m = (vector.size() - d - 2) / d;
  p.inducing.resize(m, d);
  for (Eigen::Index i = 0; i < m; ++i) p.inducing.row(i) = vector.segment(d + 2 + i * d, d).transpose();
  return p;
}

SparseBound sparse_bound(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y, const SparseParameters& p,
                         bool with_gradient) {
  const KernelHyperparameters& h = p.hyperparameters;
  const Eigen::MatrixXd& z = p.inducing;
  const Eigen::Index n = x.rows();
  const Eigen::Index d = x.cols();
  const Eigen::Index m = z.rows();
  const double outputs = static_cast<double>(y.cols());
  const double s2 = h.noise_variance;
  const double sigma = std::sqrt(s2);

  const Eigen::MatrixXd k_uu = gram_matrix(z, h);
  const Eigen::MatrixXd k_uf = kernel_matrix(z, x, h);
  const InducingFactor f = factorise_inducing(k_uu, h.signal_variance);
  const auto l = f.llt.matrixL();
  // A = L^-1 K_uf / sigma, B = I + A A^T: then s2 K_uu + K_uf K_fu = s2 L B L^T.
  Eigen::MatrixXd a = l.solve(k_uf) / sigma;
  Eigen::MatrixXd b = Eigen::MatrixXd::Identity(m, m);
  b.selfadjointView<Eigen::Lower>().rankUpdate(a);
  b = b.selfadjointView<Eigen::Lower>();
  const Eigen::LLT<Eigen::MatrixXd> b_llt(b);
  if (b_llt.info() != Eigen::Success) throw std::runtime_error("sparse GP: I + A A^T is not positive definite");
  const double log_det_b = 2.0 * b_llt.matrixLLT().diagonal().array().log().sum();
  const double trace_aat = a.squaredNorm();

  // alpha = (Q + s2 I)^-1 y = (y - A^T B^-1 A y) / s2 (Woodbury).
  const Eigen::MatrixXd ay = a * y;
  const Eigen::MatrixXd b_inv_ay = b_llt.solve(ay);
  const Eigen::MatrixXd alpha = (y - a.transpose() * b_inv_ay) / s2;

  SparseBound bound;
  bound.jitter = f.jitter;
  const double nn = static_cast<double>(n);
  bound.value = -0.5 * outputs * nn * std::log(2.0 * kPi) - 0.5 * outputs * log_det_b -
                0.5 * outputs * nn * std::log(s2) - 0.5 * (y.array() * alpha.array()).sum() -
                0.5 * outputs * nn * h.signal_variance / s2 + 0.5 * outputs * trace_aat;
  if (!with_gradient) return bound;

  // With W = (alpha alpha^T - m Sigma^-1 + m I / s2) / 2, the bound's
  // differential through the kernel is tr(W dQ) - m tr(dK_ff) / (2 s2), and
  //   tr(W dQ) = 2 tr(K_uu^-1 P dK_fu) - tr(K_uu^-1 P K_fu K_uu^-1 dK_uu),
  // P = K_uf W, which Woodbury keeps to M x N:
  //   K_uu^-1 P = L^-T R,  R = sigma/2 (A alpha) alpha^T - m/(2 sigma) B^-1 A + m/(2 sigma) A.
  const Eigen::MatrixXd b_inv_a = b_llt.solve(a);
  Eigen::MatrixXd r = (0.5 * sigma) * (a * alpha) * alpha.transpose();
  r.noalias() += (0.5 * outputs / sigma) * (a - b_inv_a);
  const Eigen::MatrixXd kuu_inv_p = l.transpose().solve(r);               // M x N
  const Eigen::MatrixXd g_uf = 2.0 * kuu_inv_p;                            // dF/dK_uf
  // dF/dK_uu = -K_uu^-1 P K_fu K_uu^-1 = -sigma L^-T (R A^T) L^-1.
  Eigen::MatrixXd g_uu = -sigma * l.transpose().solve(l.transpose().solve((r * a.transpose()).transpose()).transpose());
  g_uu = 0.5 * (g_uu + g_uu.transpose()).eval();

  const Eigen::Index hyper = d + 2;
  bound.gradient = Eigen::VectorXd::Zero(hyper + m * d);
  const Eigen::RowVectorXd inverse_sq = h.length_scales.array().square().inverse().matrix().transpose();
  const Eigen::MatrixXd w_uf = g_uf.cwiseProduct(k_uf);  // M x N
  const Eigen::MatrixXd w_uu = g_uu.cwiseProduct(k_uu);  // M x M
  // Length scales: dk/dlog l_d = k (a_d - b_d)^2 / l_d^2, summed as
  // sum_ij W_ij (u_id^2 + x_jd^2 - 2 u_id x_jd) without a loop over pairs.
  const Eigen::MatrixXd z2 = z.array().square();
  const Eigen::MatrixXd x2 = x.array().square();
  const Eigen::VectorXd uf_rows = w_uf.rowwise().sum(), uf_cols = w_uf.colwise().sum().transpose();
  const Eigen::VectorXd uu_rows = w_uu.rowwise().sum();
  for (Eigen::Index k = 0; k < d; ++k) {
    const double uf = z2.col(k).dot(uf_rows) + x2.col(k).dot(uf_cols) - 2.0 * z.col(k).dot(w_uf * x.col(k));
    const double uu = 2.0 * z2.col(k).dot(uu_rows) - 2.0 * z.col(k).dot(w_uu * z.col(k));
    bound.gradient[k] = (uf + uu) * inverse_sq[k];
  }
  // Signal variance: every kernel entry is proportional to it, and the
  // trace term's K_ff diagonal is N of it.
  bound.gradient[d] = w_uf.sum() + w_uu.sum() - 0.5 * outputs * nn * h.signal_variance / s2;
  // Noise: dF/ds2 = 1/2 alpha^T alpha - m/2 tr(Sigma^-1) + m tr(K_ff - Q) / (2 s2^2),
  // tr(Sigma^-1) = (N - tr(B^-1 A A^T)) / s2 and tr(Q) = s2 tr(A A^T).
  const double trace_b_inv_aat = (b_inv_a.array() * a.array()).sum();
  const double d_s2 = 0.5 * alpha.squaredNorm() - 0.5 * outputs * (nn - trace_b_inv_aat) / s2 +
                      0.5 * outputs * (nn * h.signal_variance - s2 * trace_aat) / (s2 * s2);
  bound.gradient[d + 1] = s2 * d_s2;
  // Inducing inputs: dk(u_j, x)/du_jd = k (x_d - u_jd) / l_d^2 for K_uf, and
  // K_uu has u_j in its row and its column (g_uu is symmetric).
  for (Eigen::Index k = 0; k < d; ++k) {
    const Eigen::VectorXd from_f = w_uf * x.col(k) - uf_rows.cwiseProduct(z.col(k));
    const Eigen::VectorXd from_u = 2.0 * (w_uu * z.col(k) - uu_rows.cwiseProduct(z.col(k)));
    for (Eigen::Index j = 0; j < m; ++j) {
      bound.gradient[hyper + j * d + k] = (from_f[j] + from_u[j]) * inverse_sq[k];
    }
  }
  return bound;
}

SparseGaussianProcess SparseGaussianProcess::fit(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y,
                                                 const SparseParameters& p) {
  const KernelHyperparameters& h = p.hyperparameters;
  const Eigen::MatrixXd k_uf = kernel_matrix(p.inducing, x, h);
  const InducingFactor f = factorise_inducing(gram_matrix(p.inducing, h), h.signal_variance);
  const auto l = f.llt.matrixL();
  const double sigma = std::sqrt(h.noise_variance);
  const Eigen::MatrixXd a = l.solve(k_uf) / sigma;
  Eigen::MatrixXd b = Eigen::MatrixXd::Identity(a.rows(), a.rows());
  b.noalias() += a * a.transpose();
  // beta = (s2 K_uu + K_uf K_fu)^-1 K_uf y = L^-T B^-1 A y / sigma.
  SparseGaussianProcess gp;
  gp.parameters = p;
  gp.beta = l.transpose().solve(b.llt().solve(a * y)) / sigma;
  return gp;
}

Eigen::MatrixXd SparseGaussianProcess::predict(const Eigen::MatrixXd& queries) const {
  return kernel_matrix(queries, parameters.inducing, parameters.hyperparameters) * beta;
}

Eigen::MatrixXd initial_inducing_inputs(const Eigen::MatrixXd& x, int m, std::uint64_t seed) {
  const Eigen::Index n = x.rows();
  if (m < 1 || m > n) throw std::invalid_argument("inducing inputs must number between 1 and the rows of data");
  std::mt19937_64 rng(seed);
  Eigen::MatrixXd z(m, x.cols());
  z.row(0) = x.row(std::uniform_int_distribution<Eigen::Index>(0, n - 1)(rng));
  Eigen::VectorXd nearest_sq = (x.rowwise() - z.row(0)).rowwise().squaredNorm();
  for (int k = 1; k < m; ++k) {
    const double total = nearest_sq.sum();
    Eigen::Index chosen = 0;
    if (total > 0.0) {
      double draw = std::uniform_real_distribution<double>(0.0, total)(rng);
      while (chosen < n - 1 && draw >= nearest_sq[chosen]) draw -= nearest_sq[chosen++];
    } else {
      chosen = std::uniform_int_distribution<Eigen::Index>(0, n - 1)(rng);  // every row already chosen
    }
    z.row(k) = x.row(chosen);
    nearest_sq = nearest_sq.cwiseMin((x.rowwise() - z.row(k)).rowwise().squaredNorm());
  }
  return z;
}

SparseSearchResult maximise_sparse_bound(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y,
                                         const SparseParameters& initial, const SearchOptions& options) {
  const int d = static_cast<int>(x.cols());
  Eigen::VectorXd v = initial.to_vector();
  // The inducing inputs may go beyond the data, but not without bound.
  const double reach = 10.0 * std::max(1.0, x.cwiseAbs().maxCoeff());
  Eigen::VectorXd lower = Eigen::VectorXd::Constant(v.size(), -reach);
  Eigen::VectorXd upper = Eigen::VectorXd::Constant(v.size(), reach);
  detail::set_hyperparameter_box(options.bounds, d, lower, upper);
  v = v.cwiseMax(lower).cwiseMin(upper);
  // The solver keeps a reference to its settings: they must outlive it.
  const LBFGSpp::LBFGSBParam<double> settings = detail::lbfgsb_parameters(options);
  LBFGSpp::LBFGSBSolver<double> solver(settings);
  SparseSearchResult result;
  const auto objective = [&](const Eigen::VectorXd& w, Eigen::VectorXd& gradient) {
    ++result.bound_evaluations;
    const SparseBound bound = sparse_bound(x, y, SparseParameters::from_vector(w, d));
    gradient = -bound.gradient;
    return -bound.value;
  };
  double negative_bound = 0.0;
  try {
    solver.minimize(objective, v, negative_bound, lower, upper);
  } catch (const std::exception&) {
    // A line search that cannot progress leaves v at its last accepted
    // point, still a valid candidate; a factorisation failure is re-raised
    // by the evaluation below.
  }
  result.parameters = SparseParameters::from_vector(v, d);
  result.bound = sparse_bound(x, y, result.parameters, false).value;
  return result;
}

}  // namespace cdcr::training
