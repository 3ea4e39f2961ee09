// The predictive variance against references that do not share its code:
// the factor with its points on every fitted row is the exact GP's
// variance, written out here as the dense formula with a general inverse;
// the 95 % radius against Monte Carlo samples; the board's float path
// (model::GpUncertainty on a written and parsed image) against the
// trainer's double evaluation; and what the parser refuses in the block.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <stdexcept>
#include <vector>

#include <Eigen/LU>
#include <gtest/gtest.h>

#include "cdcr/model/crc32.hpp"
#include "cdcr/model/flash_image.hpp"
#include "cdcr/model/gp_correction.hpp"
#include "cdcr/model/gp_uncertainty.hpp"
#include "export/image_writer.hpp"
#include "train/predictive_variance.hpp"

namespace cdcr::training {
namespace {

// A two-segment model on `rows` random inputs, with a shared kernel.
TrainedModel make_model(int rows, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-0.2, 0.2);
  TrainedModel m;
  m.geometry.segment_count = 2;
  for (int s = 0; s < 2; ++s) m.geometry.segments[s] = {120.0, 67.0, 1.5};
  m.inputs.resize(rows, 4);
  for (int i = 0; i < rows; ++i) {
    for (int d = 0; d < 4; ++d) m.inputs(i, d) = u(rng);
  }
  m.alpha = Eigen::MatrixXd::Constant(rows, 6, 0.1);
  m.input_mean = Eigen::Vector4d(0.01, -0.02, 0.0, 0.03);
  m.input_scale = Eigen::Vector4d(0.11, 0.12, 0.1, 0.13);
  m.length_scales = Eigen::Vector4d(0.8, 1.4, 2.1, 1.1);
  m.output_mean << 1.0, -2.0, 0.5, 0.01, -0.02, 0.0;
  m.output_scale << 3.0, 2.5, 1.0, 0.02, 0.03, 0.01;
  m.signal_variance.setConstant(1.3);
  m.noise_variance.setConstant(0.02);
  m.set_input_range(m.inputs);
  return m;
}

// 1 - r^T (R + (n/s) I)^-1 r with R built entry by entry from the raw
// inputs and the length scales, inverted by LU.
double dense_share(const TrainedModel& m, const Eigen::VectorXd& x_query) {
  const int n = m.training_points();
  const auto kernel = [&](const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
    double sum = 0.0;
    for (int d = 0; d < 4; ++d) {
      const double t = (a[d] - b[d]) / (m.input_scale[d] * m.length_scales[d]);
      sum += t * t;
    }
    return std::exp(-0.5 * sum);
  };
  Eigen::MatrixXd k(n, n);
  Eigen::VectorXd r(n);
  for (int i = 0; i < n; ++i) {
    r[i] = kernel(m.inputs.row(i).transpose(), x_query);
    for (int j = 0; j < n; ++j) k(i, j) = kernel(m.inputs.row(i).transpose(), m.inputs.row(j).transpose());
    k(i, i) += m.noise_variance[0] / m.signal_variance[0];
  }
  return 1.0 - r.dot(k.fullPivLu().solve(r));
}

Eigen::MatrixXd queries(int count, double spread, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-spread, spread);
  Eigen::MatrixXd q(count, 4);
  for (int i = 0; i < count; ++i) {
    for (int d = 0; d < 4; ++d) q(i, d) = u(rng);
  }
  return q;
}

TEST(PredictiveVariance, FactorWithPointsOnEveryRowIsTheExactGp) {
  const TrainedModel m = make_model(40, 3);
  const VarianceFactor f = fit_variance_factor(m, m.inputs, kernel_coordinates(m, m.inputs));
  // Inside the data, at its edge and far outside (share near 1).
  const Eigen::MatrixXd x = queries(30, 0.5, 4);
  const Eigen::VectorXd from_factor = latent_share(f, kernel_coordinates(m, x));
  const Eigen::VectorXd exact = exact_latent_share(m, m.inputs, kernel_coordinates(m, x));
  double smallest = 1.0;
  double largest = 0.0;
  for (int i = 0; i < x.rows(); ++i) {
    const double reference = dense_share(m, x.row(i).transpose());
    smallest = std::min(smallest, reference);
    largest = std::max(largest, reference);
    EXPECT_NEAR(from_factor[i], reference, 1e-6) << "query " << i;
    EXPECT_NEAR(exact[i], reference, 1e-9) << "query " << i;
  }
  // The queries span the range: near the data and far from it.
  EXPECT_LT(smallest, 0.3);
  EXPECT_GT(largest, 0.9);
}

TEST(PredictiveVariance, FewerPointsGiveAVarianceBetweenTheExactAndThePrior) {
  const TrainedModel m = make_model(200, 5);
  const VarianceFactor f = fit_variance_factor(m, m.inputs, variance_points(m, m.inputs, 16, 1));
  ASSERT_EQ(f.rank(), 16);
  const Eigen::MatrixXd z = kernel_coordinates(m, queries(50, 0.3, 6));
  const Eigen::VectorXd sparse = latent_share(f, z);
  const Eigen::VectorXd exact = exact_latent_share(m, m.inputs, z);
  for (int i = 0; i < z.rows(); ++i) {
    EXPECT_GE(sparse[i], exact[i] - 1e-9) << "query " << i;
    EXPECT_LE(sparse[i], 1.0);
  }
}

// The fraction of N(0, S) samples within gaussian_radius_95(tr S, tr S^2).
double monte_carlo_coverage(const Eigen::Matrix3d& covariance, std::uint64_t seed) {
  const Eigen::LLT<Eigen::Matrix3d> llt(covariance + 1e-15 * Eigen::Matrix3d::Identity());
  const Eigen::Matrix3d l = llt.matrixL();
  const double radius =
      model::gaussian_radius_95(covariance.trace(), (covariance * covariance).trace());
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  constexpr int kSamples = 200000;
  int inside = 0;
  for (int i = 0; i < kSamples; ++i) {
    const Eigen::Vector3d x = l * Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
    if (x.norm() <= radius) ++inside;
  }
  return static_cast<double>(inside) / kSamples;
}

TEST(PredictiveVariance, TheRadiusHolds95PercentOfAnyGaussian) {
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1.0, -2.0, 0.5).normalized()).toRotationMatrix();
  const std::vector<Eigen::Vector3d> shapes = {
      {1.0, 1.0, 1.0}, {4.0, 1e-12, 1e-12}, {1.0, 1.0, 1e-12}, {9.0, 1.0, 0.1}, {2.0, 0.5, 0.5}};
  std::uint64_t seed = 11;
  for (const Eigen::Vector3d& shape : shapes) {
    const Eigen::Matrix3d covariance = rotation * shape.asDiagonal() * rotation.transpose();
    const double coverage = monte_carlo_coverage(covariance, seed++);
    EXPECT_NEAR(coverage, 0.95, 0.01) << "variances " << shape.transpose();
  }
  EXPECT_EQ(model::gaussian_radius_95(0.0, 0.0), 0.0);
}

std::vector<std::uint8_t> image_with_variance(const TrainedModel& m) { return exporting::write_image(m); }

TEST(PredictiveVariance, TheBoardsFloatPathMatchesTheTrainer) {
  TrainedModel m = make_model(120, 8);
  m.variance = fit_variance_factor(m, m.inputs, variance_points(m, m.inputs, 24, 2));
  m.variance.position_scale = 0.8;
  m.variance.orientation_scale = 1.2;
  m.variance.extrapolation_variance = 0.3;
  const std::vector<std::uint8_t> image = image_with_variance(m);
  model::ImageView view{};
  ASSERT_EQ(model::parse_image(image.data(), image.size(), view), model::ImageStatus::ok);
  EXPECT_EQ(view.version_minor, model::kImageVersionMinorHeldOutThreshold);
  ASSERT_EQ(view.variance_rank, 24u);
  model::GpCorrection<float, double> correction;
  model::GpUncertainty<float> board;
  ASSERT_EQ(correction.bind(view), model::Status::ok);
  ASSERT_EQ(board.bind(view), model::Status::ok);

  const Eigen::MatrixXd x = queries(40, 0.35, 9);
  const Eigen::MatrixXd z = kernel_coordinates(m, x);
  const Eigen::VectorXd share = latent_share(m.variance, z);
  int flagged_by_variance = 0;
  for (int i = 0; i < x.rows(); ++i) {
    model::JointVector<float, model::kMaxSegments> bend = x.row(i).transpose().cast<float>();
    float zf[model::GpCorrection<float>::kMaxInputs];
    correction.kernel_coordinates(bend, zf);
    for (int d = 0; d < 4; ++d) ASSERT_NEAR(zf[d], z(i, d), 1e-5);
    const Eigen::Vector3f tip(30.0f + i, -40.0f, 300.0f);
    const model::PoseUncertainty<float> u = board.evaluate(zf, tip);
    EXPECT_NEAR(u.latent_share, share[i], 2e-4) << "query " << i;

    // In slices of a few units, as the runtime spreads it over cycles: the
    // same steps, so the same bits.
    model::GpUncertainty<float>::Evaluation sliced;
    board.begin_evaluation(zf, tip, sliced);
    int slices = 0;
    while (!board.evaluation_finished(sliced)) {
      const std::uint32_t spent = board.continue_evaluation(sliced, 7);
      ASSERT_GT(spent, 0u);
      ASSERT_LE(spent, 7u);
      ++slices;
    }
    EXPECT_GT(slices, 10);
    const model::PoseUncertainty<float> from_slices = board.evaluation_result(sliced);
    EXPECT_EQ(from_slices.latent_share, u.latent_share);
    EXPECT_EQ(from_slices.r95_mm, u.r95_mm);

    double variances[6];
    for (int k = 0; k < 6; ++k) {
      variances[k] = m.output_scale[k] * m.output_scale[k] *
                     (m.signal_variance[0] * share[i] + m.noise_variance[0]);
    }
    double r_mm = 0.0;
    double r_deg = 0.0;
    model::gaussian_radii_95(variances, Eigen::Vector3d(tip.cast<double>()), r_mm, r_deg);
    EXPECT_NEAR(u.r95_mm, 0.8 * r_mm, 1e-3 * r_mm) << "query " << i;
    EXPECT_NEAR(u.r95_deg, 1.2 * r_deg, 1e-3 * r_deg) << "query " << i;

    bool outside = false;
    for (int d = 0; d < 4; ++d) outside = outside || x(i, d) < m.input_min[d] || x(i, d) > m.input_max[d];
    EXPECT_EQ(u.outside_range, outside) << "query " << i;
    // From 2.6 the share alone flags; the range is reported.
    EXPECT_EQ(u.extrapolating, u.latent_share > 0.3f) << "query " << i;
    if (!outside && u.latent_share > 0.3f) ++flagged_by_variance;
  }
  static_cast<void>(flagged_by_variance);
}

// The image with a header or payload word changed and its CRC made good
// again: only the check under test can object.
std::vector<std::uint8_t> resealed(std::vector<std::uint8_t> image, std::size_t offset, const void* value,
                                   std::size_t size) {
  std::memcpy(image.data() + offset, value, size);
  const std::uint32_t total = static_cast<std::uint32_t>(image.size());
  const std::uint32_t crc = model::crc32(image.data(), total - model::kImageTrailerSize);
  std::memcpy(image.data() + total - model::kImageTrailerSize, &crc, 4);
  return image;
}

model::ImageStatus parse(const std::vector<std::uint8_t>& image, const model::ImageCapacity& capacity = {}) {
  model::ImageView view{};
  return model::parse_image(image.data(), image.size(), view, capacity);
}

TEST(PredictiveVariance, TheParserRefusesABlockItCannotTrust) {
  TrainedModel m = make_model(50, 12);
  m.variance = fit_variance_factor(m, m.inputs, variance_points(m, m.inputs, 8, 3));
  const std::vector<std::uint8_t> image = image_with_variance(m);
  ASSERT_EQ(parse(image), model::ImageStatus::ok);
  model::ImageView view{};
  ASSERT_EQ(model::parse_image(image.data(), image.size(), view), model::ImageStatus::ok);
  const std::size_t block = view.variance_calibration - reinterpret_cast<const float*>(image.data());
  const std::size_t block_bytes = 4 * block;

  // A v2.0 image has no variance block.
  const std::uint16_t minor_zero = 0;
  EXPECT_EQ(parse(resealed(image, model::image_field::version_minor.offset, &minor_zero, 2)),
            model::ImageStatus::bad_header);
  // More points than the build holds.
  EXPECT_EQ(parse(image, model::ImageCapacity{1024, 8, 4}), model::ImageStatus::over_capacity);
  // A non-positive calibration scale, a threshold above the prior, the
  // reserved word, a zero diagonal of either factor.
  const float zero = 0.0f;
  const float two = 2.0f;
  EXPECT_EQ(parse(resealed(image, block_bytes, &zero, 4)), model::ImageStatus::invalid_parameters);
  EXPECT_EQ(parse(resealed(image, block_bytes + 8, &two, 4)), model::ImageStatus::invalid_parameters);
  EXPECT_EQ(parse(resealed(image, block_bytes + 12, &two, 4)), model::ImageStatus::invalid_parameters);
  const std::size_t inducing = block_bytes + 4 * (model::image_variance_field::points + 8 * 4);
  EXPECT_EQ(parse(resealed(image, inducing + 4 * 2, &zero, 4)), model::ImageStatus::invalid_parameters);  // L_u(1,1)
  const std::size_t posterior = inducing + 4 * model::packed_triangle_floats(8);
  EXPECT_EQ(parse(resealed(image, posterior + 4 * 35, &zero, 4)), model::ImageStatus::invalid_parameters);  // L_c(7,7)
  const float nan = std::nanf("");
  EXPECT_EQ(parse(resealed(image, posterior + 4 * 3, &nan, 4)), model::ImageStatus::non_finite_payload);
  // Outputs with kernels of their own: the factor holds one signal / noise.
  const std::size_t signal = reinterpret_cast<const std::uint8_t*>(view.signal_variance + 2) - image.data();
  EXPECT_EQ(parse(resealed(image, signal, &two, 4)), model::ImageStatus::invalid_parameters);
  // The offset must be where the layout puts the block.
  const std::uint32_t moved = static_cast<std::uint32_t>(block_bytes + 8);
  EXPECT_EQ(parse(resealed(image, model::image_field::variance_offset.offset, &moved, 4)),
            model::ImageStatus::size_mismatch);
}

TEST(PredictiveVariance, ModelsWithOwnKernelsPerOutputGetNoFactor) {
  TrainedModel m = make_model(30, 13);
  m.noise_variance[4] = 0.05;
  EXPECT_THROW(fit_variance_factor(m, m.inputs, kernel_coordinates(m, m.inputs)), std::invalid_argument);
}

// The same image as a 2.5 image: the fitted rows' range flags as it did
// when that image was written, beside the share.
TEST(PredictiveVariance, ImagesBefore26FlagOutsideTheRangeToo) {
  TrainedModel m = make_model(120, 8);
  m.variance = fit_variance_factor(m, m.inputs, variance_points(m, m.inputs, 24, 2));
  const float threshold = 0.8f;
  m.variance.extrapolation_variance = threshold;
  const std::vector<std::uint8_t> image = image_with_variance(m);
  const std::uint16_t minor = model::kImageVersionMinorHeldOutThreshold - 1;
  const std::vector<std::uint8_t> older = resealed(image, 6, &minor, sizeof minor);
  model::ImageView view{};
  model::ImageView older_view{};
  ASSERT_EQ(model::parse_image(image.data(), image.size(), view), model::ImageStatus::ok);
  ASSERT_EQ(model::parse_image(older.data(), older.size(), older_view), model::ImageStatus::ok);
  model::GpUncertainty<float> board;
  model::GpUncertainty<float> older_board;
  ASSERT_EQ(board.bind(view), model::Status::ok);
  ASSERT_EQ(older_board.bind(older_view), model::Status::ok);
  EXPECT_FALSE(board.range_flags());
  EXPECT_TRUE(older_board.range_flags());

  const Eigen::MatrixXd z = kernel_coordinates(m, queries(60, 0.35, 9));
  int outside_within_share = 0;
  for (int i = 0; i < z.rows(); ++i) {
    float zf[4];
    for (int d = 0; d < 4; ++d) zf[d] = static_cast<float>(z(i, d));
    const Eigen::Vector3f tip(0.0f, 0.0f, 300.0f);
    const model::PoseUncertainty<float> u = board.evaluate(zf, tip);
    const model::PoseUncertainty<float> old = older_board.evaluate(zf, tip);
    EXPECT_EQ(old.latent_share, u.latent_share);
    EXPECT_EQ(old.outside_range, u.outside_range);
    EXPECT_EQ(old.extrapolating, u.outside_range || u.latent_share > threshold) << "query " << i;
    EXPECT_EQ(u.extrapolating, u.latent_share > threshold) << "query " << i;
    if (u.outside_range && !u.extrapolating) ++outside_within_share;
  }
  EXPECT_GT(outside_within_share, 0) << "no query tells the rules apart";
}

// Against references outside the Sherman-Morrison update: with a point at
// every row, the factor is the exact GP and the share with a row left out
// is the dense formula on the other rows; with fewer points, it is the
// factor fitted again without the row.
TEST(PredictiveVariance, TheHeldOutShareIsTheFactorWithoutTheRow) {
  TrainedModel m = make_model(40, 21);
  const Eigen::MatrixXd z = kernel_coordinates(m, m.inputs);
  m.variance = fit_variance_factor(m, m.inputs, z);
  const Eigen::VectorXd held_out = held_out_latent_share(m, m.inputs);
  const Eigen::VectorXd in_sample = latent_share(m.variance, z);
  for (int i = 0; i < m.training_points(); ++i) {
    TrainedModel without = m;
    without.inputs.resize(m.training_points() - 1, 4);
    for (int j = 0, k = 0; j < m.training_points(); ++j) {
      if (j != i) without.inputs.row(k++) = m.inputs.row(j);
    }
    EXPECT_NEAR(held_out[i], dense_share(without, m.inputs.row(i).transpose()), 1e-6) << "row " << i;
    EXPECT_GT(held_out[i], in_sample[i]) << "row " << i;
  }

  TrainedModel sparse = make_model(60, 22);
  const Eigen::MatrixXd points = variance_points(sparse, sparse.inputs, 12, 3);
  sparse.variance = fit_variance_factor(sparse, sparse.inputs, points);
  const Eigen::VectorXd sparse_held_out = held_out_latent_share(sparse, sparse.inputs);
  for (int i = 0; i < sparse.training_points(); i += 7) {
    Eigen::MatrixXd rows(sparse.training_points() - 1, 4);
    for (int j = 0, k = 0; j < sparse.training_points(); ++j) {
      if (j != i) rows.row(k++) = sparse.inputs.row(j);
    }
    const VarianceFactor refitted = fit_variance_factor(sparse, rows, points);
    const Eigen::VectorXd share = latent_share(refitted, kernel_coordinates(sparse, sparse.inputs.row(i)));
    EXPECT_NEAR(sparse_held_out[i], share[0], 1e-8) << "row " << i;
  }
}

// Twice the 99th percentile of the held-out shares: above every fitted
// row's, below the prior far from the data; halfway to the prior where
// twice would reach it.
TEST(PredictiveVariance, TheThresholdSitsAboveTheHeldOutShares) {
  TrainedModel m = make_model(200, 23);
  m.length_scales *= 4.0;  // smooth: the data leave little unknown
  m.variance = fit_variance_factor(m, m.inputs, variance_points(m, m.inputs, 32, 4));
  const Eigen::VectorXd held_out = held_out_latent_share(m, m.inputs);
  const double threshold = extrapolation_threshold(m, m.inputs);
  std::vector<double> sorted(held_out.data(), held_out.data() + held_out.size());
  std::sort(sorted.begin(), sorted.end());
  const double p99 = sorted[static_cast<std::size_t>(0.99 * 199)];
  ASSERT_LT(p99, 0.2);
  EXPECT_DOUBLE_EQ(threshold, 2.0 * p99);
  const Eigen::MatrixXd far = Eigen::MatrixXd::Constant(1, 4, 3.0);
  EXPECT_GT(latent_share(m.variance, kernel_coordinates(m, far))[0], threshold);

  // Two variance points for rows spread over about two length scales: much
  // of the prior stays unknown at the rows.
  TrainedModel vague = make_model(200, 24);
  vague.length_scales *= 2.0;
  vague.variance = fit_variance_factor(vague, vague.inputs, variance_points(vague, vague.inputs, 2, 4));
  Eigen::VectorXd vague_share = held_out_latent_share(vague, vague.inputs);
  std::sort(vague_share.data(), vague_share.data() + vague_share.size());
  const double vague_p99 = vague_share[static_cast<Eigen::Index>(0.99 * 199)];
  ASSERT_GT(vague_p99, 1.0 / 3.0);
  ASSERT_LT(vague_p99, 0.9);
  EXPECT_DOUBLE_EQ(extrapolation_threshold(vague, vague.inputs), 0.5 * (1.0 + vague_p99));
}

}  // namespace
}  // namespace cdcr::training
