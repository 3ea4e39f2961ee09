// The GP correction's gradient against central differences of its own mean,
// and its fixed-size loops (4, 6 and 8 inputs) against the general one.
#include <random>

#include <gtest/gtest.h>

#include "cdcr/model/gp_correction.hpp"
#include "export/image_writer.hpp"
#include "train/trainer.hpp"

#include "../support/synthetic_trained_model.hpp"

namespace cdcr::model {
namespace {

using Bytes = std::vector<std::uint8_t>;

struct BoundModel {
  training::TrainedModel model;
  Bytes image;
  ImageView view{};
};

BoundModel make_model(int segments, InputEncoding encoding, int training_points) {
  test_support::SyntheticModelOptions options;
  options.segments = segments;
  options.encoding = encoding;
  options.training_points = training_points;
  BoundModel b;
  b.model = test_support::synthetic_trained_model(options);
  b.image = exporting::write_image(b.model);
  EXPECT_EQ(parse_image(b.image.data(), b.image.size(), b.view), ImageStatus::ok);
  return b;
}

JointVector<double> random_bend(int segments, std::mt19937& rng) {
  std::uniform_real_distribution<double> alpha_rad(-3.0, 3.0);
  std::uniform_real_distribution<double> theta_rad(0.05, 1.2);
  JointVector<double> bend(2 * segments);
  for (int s = 0; s < segments; ++s) {
    const double a = alpha_rad(rng);
    const double t = theta_rad(rng);
    bend[2 * s] = t * std::cos(a);
    bend[2 * s + 1] = t * std::sin(a);
  }
  return bend;
}

class GpCorrectionSizes : public ::testing::TestWithParam<std::tuple<int, InputEncoding>> {};

// 2 to 4 segments take the fixed-size loops, 5 the general one; 37 points
// leave a partial block and a partial chunk.
INSTANTIATE_TEST_SUITE_P(Segments, GpCorrectionSizes,
                         ::testing::Combine(::testing::Values(2, 3, 4, 5),
                                            ::testing::Values(InputEncoding::bend_vector,
                                                              InputEncoding::joint_angles)));

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
    constexpr double h = 1e-6;
    for (int d = 0; d < 2 * segments; ++d) {
      JointVector<double> plus = bend;
      JointVector<double> minus = bend;
      plus[d] += h;
      minus[d] -= h;
      const Twist<double> difference = (correction.predict(plus) - correction.predict(minus)) / (2 * h);
      for (int k = 0; k < 6; ++k) {
        EXPECT_NEAR(gradient(k, d), difference[k], 1e-6 * (1.0 + std::abs(difference[k])))
            << "output " << k << ", input " << d << ", trial " << trial;
      }
    }
  }
}

TEST_P(GpCorrectionSizes, FloatMeanAndGradientFollowDouble) {
  const auto [segments, encoding] = GetParam();
  const BoundModel b = make_model(segments, encoding, 37);
  GpCorrection<double, double> reference;
  GpCorrection<float, double> correction;
  ASSERT_EQ(reference.bind(b.view), Status::ok);
  ASSERT_EQ(correction.bind(b.view), Status::ok);
  const Eigen::MatrixXd expected_mean = [&] {
    std::mt19937 rng(5);
    Eigen::MatrixXd bends(30, 2 * segments);
    for (int q = 0; q < 30; ++q) bends.row(q) = random_bend(segments, rng).transpose();
    return training::predict_error_twists(b.model, bends);
  }();
  std::mt19937 rng(5);
  for (int q = 0; q < 30; ++q) {
    const JointVector<double> bend = random_bend(segments, rng);
    Twist<double> eps;
    Jacobian<double> gradient;
    ASSERT_EQ(reference(bend, eps, gradient), Status::ok);
    Twist<float> eps_float;
    Jacobian<float> gradient_float;
    ASSERT_EQ(correction(bend.cast<float>(), eps_float, gradient_float), Status::ok);
    for (int k = 0; k < 6; ++k) {
      // The trainer's own prediction, independent of the image code; the
      // image holds float32 values, hence float32-sized differences.
      const double scale = b.model.output_scale[k] * b.model.signal_variance[k] + std::abs(b.model.output_mean[k]);
      EXPECT_NEAR(eps[k], expected_mean(q, k), 2e-6 * scale);
      EXPECT_NEAR(eps_float[k], eps[k], 2e-6 * scale);
      const double gradient_scale = gradient.row(k).cwiseAbs().maxCoeff() + scale;
      for (int d = 0; d < 2 * segments; ++d) EXPECT_NEAR(gradient_float(k, d), gradient(k, d), 1e-4 * gradient_scale);
    }
  }
}

}  // namespace
}  // namespace cdcr::model
