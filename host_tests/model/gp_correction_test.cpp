// The GP correction's gradient against central differences of its own mean,
// and its fixed-size loops (4, 6 and 8 inputs) against the general one; with
// models of several chunks of the gradient pass, the mean against the dense
// sum written out here and the gradient against central differences.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>

#include <gtest/gtest.h>

#include "cdcr/model/gp_correction.hpp"
#include "export/image_writer.hpp"
#include "train/trainer.hpp"

#include "../support/synthetic_image.hpp"

namespace cdcr::model {
namespace {

using BoundModel = test_support::SyntheticImage;

BoundModel make_model(int segments, InputEncoding encoding, int training_points) {
  return test_support::synthetic_image(test_support::SyntheticModelOptions{training_points, segments, encoding});
}

// 2 to 4 segments take the fixed-size loops, 5 the general one; each in both
// input encodings.
auto segments_and_encodings() {
  return ::testing::Combine(::testing::Values(2, 3, 4, 5),
                            ::testing::Values(InputEncoding::bend_vector, InputEncoding::joint_angles));
}

JointVector<double> random_bend(int segments, std::mt19937& rng, double theta_min_rad = 0.05) {
  std::uniform_real_distribution<double> alpha_rad(-3.0, 3.0);
  std::uniform_real_distribution<double> theta_rad(theta_min_rad, 1.2);
  JointVector<double> bend(2 * segments);
  for (int s = 0; s < segments; ++s) {
    const double a = alpha_rad(rng);
    const double t = theta_rad(rng);
    bend[2 * s] = t * std::cos(a);
    bend[2 * s + 1] = t * std::sin(a);
  }
  return bend;
}

// `gradient`, the double correction's at `bend`, against central differences
// of its mean (steps of 1e-6) to 1e-6 relative.
template <typename Correction>
void expect_gradient_of_mean(Correction& correction, const JointVector<double>& bend,
                             const Jacobian<double>& gradient) {
  constexpr double h = 1e-6;
  for (int d = 0; d < bend.size(); ++d) {
    JointVector<double> plus = bend;
    JointVector<double> minus = bend;
    plus[d] += h;
    minus[d] -= h;
    const Twist<double> difference = (correction.predict(plus) - correction.predict(minus)) / (2 * h);
    for (int k = 0; k < 6; ++k) {
      EXPECT_NEAR(gradient(k, d), difference[k], 1e-6 * (1.0 + std::abs(difference[k])))
          << "output " << k << ", input " << d;
    }
  }
}

class GpCorrectionSizes : public ::testing::TestWithParam<std::tuple<int, InputEncoding>> {};

// 37 points leave a partial block and a partial chunk.
INSTANTIATE_TEST_SUITE_P(Segments, GpCorrectionSizes, segments_and_encodings());

TEST_P(GpCorrectionSizes, GradientMatchesCentralDifferences) {
  const auto [segments, encoding] = GetParam();
  const BoundModel b = make_model(segments, encoding, 37);
  GpCorrection<double, double> correction;
  ASSERT_EQ(correction.bind(b.view), Status::ok);
  std::mt19937 rng(11);
  for (int trial = 0; trial < 20; ++trial) {
    const JointVector<double> bend = random_bend(segments, rng);
    Twist<double> eps;
    Jacobian<double> gradient;
    ASSERT_EQ(correction(bend, eps, gradient), Status::ok);
    ASSERT_EQ(gradient.cols(), 2 * segments);
    const Twist<double> mean = correction.predict(bend);
    for (int k = 0; k < 6; ++k) EXPECT_EQ(eps[k], mean[k]);
    SCOPED_TRACE(testing::Message() << "trial " << trial);
    expect_gradient_of_mean(correction, bend, gradient);
  }
}

TEST_P(GpCorrectionSizes, FloatMeanAndGradientFollowDouble) {
  const auto [segments, encoding] = GetParam();
  const BoundModel b = make_model(segments, encoding, 37);
  GpCorrection<double, double> reference;
  GpCorrection<float, double> correction;
  ASSERT_EQ(reference.bind(b.view), Status::ok);
  ASSERT_EQ(correction.bind(b.view), Status::ok);
  std::mt19937 rng(5);
  Eigen::MatrixXd bends(30, 2 * segments);
  for (int q = 0; q < bends.rows(); ++q) bends.row(q) = random_bend(segments, rng).transpose();
  const Eigen::MatrixXd expected_mean = training::predict_error_twists(b.trained, bends);
  for (int q = 0; q < bends.rows(); ++q) {
    const JointVector<double> bend = bends.row(q).transpose();
    Twist<double> eps;
    Jacobian<double> gradient;
    ASSERT_EQ(reference(bend, eps, gradient), Status::ok);
    Twist<float> eps_float;
    Jacobian<float> gradient_float;
    ASSERT_EQ(correction(bend.cast<float>(), eps_float, gradient_float), Status::ok);
    for (int k = 0; k < 6; ++k) {
      // The trainer's own prediction, independent of the image code; the
      // image holds float32 values, hence float32-sized differences.
      const double scale = b.trained.output_scale[k] * b.trained.signal_variance[k] + std::abs(b.trained.output_mean[k]);
      EXPECT_NEAR(eps[k], expected_mean(q, k), 2e-6 * scale);
      EXPECT_NEAR(eps_float[k], eps[k], 2e-6 * scale);
      const double gradient_scale = gradient.row(k).cwiseAbs().maxCoeff() + scale;
      for (int d = 0; d < 2 * segments; ++d) EXPECT_NEAR(gradient_float(k, d), gradient(k, d), 1e-4 * gradient_scale);
    }
  }
}

// Models larger than one chunk of the gradient pass (kChunkPoints = 64): 203
// points are three full chunks and a ragged tail of 11 (one block of 8 and 3
// more), so a chunk that is skipped, summed twice or restarted shows up.
constexpr int kMultiChunkPoints = 203;
// Bends away from theta = 0, where the joint-angle encoding's derivatives
// grow as 1/theta and central differences lose their accuracy: what is
// tested here is the sum over chunks, not the encoding.
constexpr double kThetaMinRad = 0.3;

// The mean written out from the image, in long double:
//   eps_k = output_mean_k + output_scale_k signal_variance_k sum_i exp(-|z - z_i|^2 / 2) alpha_ik,
//   z_d = (x_d - input_mean_d) / (input_scale_d length_scale_d), x = encode(bend).
std::array<long double, 6> dense_mean(const ImageView& image, const JointVector<double>& bend) {
  Eigen::VectorXd x(bend.size());
  encode_inputs(image.encoding, bend, x);
  const int dims = image.input_dims;
  std::vector<long double> z(dims);
  for (int d = 0; d < dims; ++d) {
    z[d] = (x[d] - static_cast<long double>(image.input_mean[d])) /
           (static_cast<long double>(image.input_scale[d]) * image.length_scale[d]);
  }
  std::array<long double, 6> sums{};
  for (std::uint32_t i = 0; i < image.training_points; ++i) {
    long double distance_sq = 0;
    for (int d = 0; d < dims; ++d) {
      const long double difference = z[d] - image.inputs[i * dims + d];
      distance_sq += difference * difference;
    }
    const long double k = std::exp(-distance_sq / 2);
    for (int out = 0; out < 6; ++out) sums[out] += k * image.alpha[i * 6 + out];
  }
  std::array<long double, 6> eps{};
  for (int out = 0; out < 6; ++out) {
    eps[out] = image.output_mean[out] +
               static_cast<long double>(image.output_scale[out]) * image.signal_variance[out] * sums[out];
  }
  return eps;
}

// What an output's sum can lose to rounding: its mean plus the gain times
// the sum of |alpha| (every kernel value is at most 1).
std::array<double, 6> output_magnitudes(const ImageView& image) {
  std::array<double, 6> magnitude{};
  for (int out = 0; out < 6; ++out) {
    double alpha_sum = 0;
    for (std::uint32_t i = 0; i < image.training_points; ++i) alpha_sum += std::abs(image.alpha[i * 6 + out]);
    magnitude[out] = std::abs(image.output_mean[out]) + image.output_scale[out] * image.signal_variance[out] * alpha_sum;
  }
  return magnitude;
}

// 4, 6 and 8 inputs take the fixed-size loops, 10 (5 segments) the general one.
class GpCorrectionChunks : public ::testing::TestWithParam<std::tuple<int, InputEncoding>> {};

INSTANTIATE_TEST_SUITE_P(Segments, GpCorrectionChunks, segments_and_encodings());

// predict and predict_with_gradient against the dense sum, in double and
// in float with either accumulator the firmware uses.
TEST_P(GpCorrectionChunks, MeanMatchesDenseSum) {
  const auto [segments, encoding] = GetParam();
  const BoundModel b = make_model(segments, encoding, kMultiChunkPoints);
  GpCorrection<double, double> in_double;
  GpCorrection<float, double> in_float;
  GpCorrection<float, CompensatedFloat> in_compensated_float;
  ASSERT_EQ(in_double.bind(b.view), Status::ok);
  ASSERT_EQ(in_float.bind(b.view), Status::ok);
  ASSERT_EQ(in_compensated_float.bind(b.view), Status::ok);
  const std::array<double, 6> magnitude = output_magnitudes(b.view);
  std::mt19937 rng(23);
  for (int trial = 0; trial < 20; ++trial) {
    const JointVector<double> bend = random_bend(segments, rng, kThetaMinRad);
    const std::array<long double, 6> expected = dense_mean(b.view, bend);
    Twist<double> eps;
    Jacobian<double> gradient;
    in_double.predict_with_gradient(bend, eps, gradient);
    const Twist<double> mean = in_double.predict(bend);
    const JointVector<float> bend_float = bend.cast<float>();
    Twist<float> eps_float;
    Jacobian<float> gradient_float;
    in_float.predict_with_gradient(bend_float, eps_float, gradient_float);
    const Twist<float> mean_float = in_float.predict(bend_float);
    Twist<float> eps_compensated;
    in_compensated_float.predict_with_gradient(bend_float, eps_compensated, gradient_float);
    const Twist<float> mean_compensated = in_compensated_float.predict(bend_float);
    for (int k = 0; k < 6; ++k) {
      const double reference = static_cast<double>(expected[k]);
      EXPECT_NEAR(mean[k], reference, 1e-13 * magnitude[k]) << "double predict, output " << k << ", trial " << trial;
      EXPECT_NEAR(eps[k], reference, 1e-13 * magnitude[k]) << "double gradient pass, output " << k;
      // The float query alone moves the kernel values by a few float ulp.
      EXPECT_NEAR(mean_float[k], reference, 1e-6 * magnitude[k]) << "float predict, output " << k;
      EXPECT_NEAR(eps_float[k], reference, 1e-6 * magnitude[k]) << "float gradient pass, output " << k;
      EXPECT_NEAR(mean_compensated[k], reference, 1e-6 * magnitude[k]) << "compensated float predict, output " << k;
      EXPECT_NEAR(eps_compensated[k], reference, 1e-6 * magnitude[k]) << "compensated float gradient pass, output " << k;
    }
  }
}

// The largest |central difference - gradient| relative to the output's
// magnitude, over every output and input of `trials` random bends.
template <typename S, typename Accumulator>
double worst_gradient_error(const BoundModel& b, int segments, S step, int trials) {
  GpCorrection<S, Accumulator> correction;
  EXPECT_EQ(correction.bind(b.view), Status::ok);
  const std::array<double, 6> magnitude = output_magnitudes(b.view);
  std::mt19937 rng(29);
  double worst = 0;
  for (int trial = 0; trial < trials; ++trial) {
    const JointVector<S> bend = random_bend(segments, rng, kThetaMinRad).template cast<S>();
    Twist<S> eps;
    Jacobian<S> gradient;
    correction.predict_with_gradient(bend, eps, gradient);
    EXPECT_EQ(gradient.cols(), 2 * segments);
    for (int d = 0; d < 2 * segments; ++d) {
      JointVector<S> plus = bend;
      JointVector<S> minus = bend;
      plus[d] += step;
      minus[d] -= step;
      // The step actually taken, after rounding to S.
      const double taken = static_cast<double>(plus[d]) - static_cast<double>(minus[d]);
      const Twist<S> up = correction.predict(plus);
      const Twist<S> down = correction.predict(minus);
      for (int k = 0; k < 6; ++k) {
        const double difference = (static_cast<double>(up[k]) - static_cast<double>(down[k])) / taken;
        worst = std::max(worst, std::abs(static_cast<double>(gradient(k, d)) - difference) / magnitude[k]);
      }
    }
  }
  return worst;
}

TEST_P(GpCorrectionChunks, DoubleGradientMatchesCentralDifferences) {
  const auto [segments, encoding] = GetParam();
  const BoundModel b = make_model(segments, encoding, kMultiChunkPoints);
  const double worst = worst_gradient_error<double, double>(b, segments, 1e-5, 20);
  std::printf("double: worst gradient error %.3g of the output magnitude\n", worst);
  EXPECT_LT(worst, 1e-9);  // measured: at most 5e-11
}

// Central differences in float are noisy (the mean's own rounding over the
// step): a looser bound, still far below what a lost chunk costs.
TEST_P(GpCorrectionChunks, FloatGradientMatchesCentralDifferences) {
  const auto [segments, encoding] = GetParam();
  const BoundModel b = make_model(segments, encoding, kMultiChunkPoints);
  const double worst = worst_gradient_error<float, double>(b, segments, 1e-2f, 20);
  const double worst_compensated = worst_gradient_error<float, CompensatedFloat>(b, segments, 1e-2f, 20);
  std::printf("float: worst gradient error %.3g (double sums), %.3g (compensated float sums) of the output magnitude\n",
              worst, worst_compensated);
  EXPECT_LT(worst, 3e-4);  // measured: at most 5e-5
  EXPECT_LT(worst_compensated, 3e-4);
}

// A model with the payload input: the board's mean against the trainer's
// double prediction (its own code, not the image's) at the image's default
// payload and at payloads set afterwards, in double and float; the
// gradient is d(eps)/d(bend) alone, 6 x 2n, and matches central differences
// at the set payload.
class GpCorrectionPayload : public ::testing::TestWithParam<int> {};

INSTANTIATE_TEST_SUITE_P(Segments, GpCorrectionPayload, ::testing::Values(2, 3, 4));

TEST_P(GpCorrectionPayload, TheMeanFollowsThePayloadAsTheTrainerPredictsIt) {
  const int segments = GetParam();
  test_support::SyntheticModelOptions options;
  options.segments = segments;
  options.training_points = 37;
  options.payload_input = true;
  const BoundModel b = test_support::synthetic_image(options);
  ASSERT_EQ(b.view.extra_inputs, 1);
  ASSERT_EQ(b.view.input_dims, 2 * segments + 1);
  ASSERT_EQ(*b.view.extra_input_default, 0.375f);
  GpCorrection<double, double> reference;
  GpCorrection<float, double> correction;
  ASSERT_EQ(reference.bind(b.view), Status::ok);
  ASSERT_EQ(correction.bind(b.view), Status::ok);
  EXPECT_TRUE(correction.has_payload_input());
  EXPECT_EQ(correction.bend_dims(), 2 * segments);
  EXPECT_EQ(correction.payload_kg(), 0.375f);

  std::mt19937 rng(5);
  for (const double payload_kg : {-1.0, 0.0, 0.45, 1.0}) {  // -1: the default, none set
    if (payload_kg >= 0.0) {
      reference.set_payload_kg(payload_kg);
      correction.set_payload_kg(static_cast<float>(payload_kg));
    }
    const double used_kg = payload_kg >= 0.0 ? payload_kg : 0.375;
    Eigen::MatrixXd bends(12, 2 * segments);
    for (int q = 0; q < bends.rows(); ++q) bends.row(q) = random_bend(segments, rng).transpose();
    const Eigen::MatrixXd expected =
        training::predict_error_twists(b.trained, bends, Eigen::VectorXd::Constant(bends.rows(), used_kg));
    for (int q = 0; q < bends.rows(); ++q) {
      const JointVector<double> bend = bends.row(q).transpose();
      Twist<double> eps;
      Jacobian<double> gradient;
      ASSERT_EQ(reference(bend, eps, gradient), Status::ok);
      ASSERT_EQ(gradient.cols(), 2 * segments);
      const Twist<float> eps_float = correction.predict(bend.cast<float>());
      for (int k = 0; k < 6; ++k) {
        const double scale = b.trained.output_scale[k] * b.trained.signal_variance[k] + std::abs(b.trained.output_mean[k]);
        EXPECT_NEAR(eps[k], expected(q, k), 2e-6 * scale) << "payload " << used_kg << ", query " << q;
        EXPECT_NEAR(eps_float[k], eps[k], 2e-6 * scale) << "payload " << used_kg << ", query " << q;
      }
      expect_gradient_of_mean(reference, bend, gradient);
    }
  }
  // The payload is an input, not a constant: two payloads, two corrections.
  const JointVector<double> bend = random_bend(segments, rng);
  reference.set_payload_kg(0.1);
  const Twist<double> light = reference.predict(bend);
  reference.set_payload_kg(0.9);
  EXPECT_GT((reference.predict(bend) - light).norm(), 1e-3);
  // A bend vector with the payload's slot is not one.
  JointVector<double> too_long(2 * segments + 1);
  too_long.setZero();
  Twist<double> eps;
  EXPECT_EQ(reference.value(too_long, eps), Status::correction_failed);
}

// A model with everything held: the cable residuals, the history and the
// payload, in that order after the bend pairs (the trainer's model_inputs).
// The board's mean against the trainer's double prediction on the same
// rows, held values set as the runtime sets them; each held input moves the
// correction.
TEST(GpCorrectionHistory, TheHeldInputsAreTheTrainersInTheirOrder) {
  test_support::SyntheticModelOptions options;
  options.segments = 2;
  options.training_points = 29;
  options.cable_residuals = true;
  options.history = true;
  options.payload_input = true;
  options.hysteresis_operators = 1;
  const BoundModel b = test_support::synthetic_image(options);
  ASSERT_EQ(b.view.encoding, InputEncoding::bend_vector_cable_fit_history);
  ASSERT_EQ(b.view.input_dims, 4 + 4 + 8 + 1);
  GpCorrection<double, double> correction;
  ASSERT_EQ(correction.bind(b.view), Status::ok);
  EXPECT_TRUE(correction.takes_history());
  EXPECT_EQ(correction.history_dims(), 8);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  training::TrainingSet rows;
  rows.encoding = b.view.encoding;
  rows.bends.resize(6, 4);
  rows.cable_residuals.resize(6, 4);
  rows.history_inputs.resize(6, 8);
  rows.payload_kg.resize(6);
  for (int q = 0; q < 6; ++q) {
    rows.bends.row(q) = random_bend(2, rng).transpose();
    for (int e = 0; e < 4; ++e) rows.cable_residuals(q, e) = unit(rng);
    for (int e = 0; e < 8; ++e) rows.history_inputs(q, e) = unit(rng);
    rows.payload_kg[q] = 0.5 + 0.5 * unit(rng);
  }
  const Eigen::MatrixXd expected = training::predict_error_twists(b.trained, rows);
  for (int q = 0; q < 6; ++q) {
    const JointVector<double> bend = rows.bends.row(q).transpose();
    const CableResiduals<double> residuals = rows.cable_residuals.row(q).transpose();
    const Eigen::VectorXd history = rows.history_inputs.row(q).transpose();
    correction.set_history_inputs(history.data());
    correction.set_payload_kg(rows.payload_kg[q]);
    const Twist<double> eps = correction.predict(bend, residuals);
    for (int k = 0; k < 6; ++k) {
      const double scale =
          b.trained.output_scale[k] * b.trained.signal_variance[k] + std::abs(b.trained.output_mean[k]);
      EXPECT_NEAR(eps[k], expected(q, k), 2e-6 * scale) << "query " << q;
    }
    // The payload stayed where it was set, after the history.
    EXPECT_EQ(correction.payload_kg(), rows.payload_kg[q]);
  }
  const JointVector<double> bend = rows.bends.row(0).transpose();
  const CableResiduals<double> residuals = rows.cable_residuals.row(0).transpose();
  const Twist<double> before = correction.predict(bend, residuals);
  Eigen::VectorXd flipped = -rows.history_inputs.row(0).transpose();
  correction.set_history_inputs(flipped.data());
  EXPECT_GT((correction.predict(bend, residuals) - before).norm(), 1e-3);
}

}  // namespace
}  // namespace cdcr::model
