// The x86-64 vector loops (model/arch/x86_avx2) against GpCorrection's own
// scalar loops in the same arithmetic (arch::FusedScalar: polynomial_gaussian
// and fused multiply-adds): every bit of the mean and of the gradient, for
// the unrolled input counts (4, 6, 8), the run-time count of 5 segments and
// of payload models (5 and 9 inputs), ragged blocks and chunks, and
// evaluations sliced over cycles; and the mean against the dense double sum.
// Built when the build selects x86_avx2; the CPU must then have AVX2 and FMA,
// or the vector loops would never run here.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <tuple>

#include <gtest/gtest.h>

#include "cdcr/model/arch/x86_avx2.hpp"
#include "cdcr/model/gp_correction.hpp"
#include "export/image_writer.hpp"

#include "../support/synthetic_image.hpp"

namespace cdcr::model {
namespace {

using Vector = GpCorrection<float, double, kMaxSegments, arch::X86Avx2>;
using Reference = GpCorrection<float, double, kMaxSegments, arch::FusedScalar>;

using Model = test_support::SyntheticImage;

Model make_model(int segments, int points, bool payload) {
  test_support::SyntheticModelOptions options;
  options.segments = segments;
  options.training_points = points;
  options.payload_input = payload;
  options.seed = 7000u + std::uint32_t(segments * 10 + points);
  return test_support::synthetic_image(options);
}

// Bends over the synthetic models' range, and some far outside it: there the
// kernel's clamp and the smallest normal floats are reached.
JointVector<float> random_bend(int segments, std::mt19937& rng, double theta_max_rad) {
  std::uniform_real_distribution<double> alpha_rad(-3.0, 3.0);
  std::uniform_real_distribution<double> theta_rad(0.0, theta_max_rad);
  JointVector<float> bend(2 * segments);
  for (int s = 0; s < segments; ++s) {
    const double a = alpha_rad(rng);
    const double t = theta_rad(rng);
    bend[2 * s] = float(t * std::cos(a));
    bend[2 * s + 1] = float(t * std::sin(a));
  }
  return bend;
}

template <typename A, typename B>
bool same_bits(const A& a, const B& b) {
  static_assert(sizeof(a) == sizeof(b));
  return std::memcmp(&a, &b, sizeof(a)) == 0;
}

::testing::AssertionResult same_gradient(const Jacobian<float>& a, const Jacobian<float>& b) {
  if (a.rows() != b.rows() || a.cols() != b.cols()) return ::testing::AssertionFailure() << "shapes differ";
  for (int k = 0; k < a.rows(); ++k) {
    for (int d = 0; d < a.cols(); ++d) {
      if (!same_bits(a(k, d), b(k, d))) {
        return ::testing::AssertionFailure() << "d eps_" << k << " / d bend_" << d << ": " << a(k, d) << " vs "
                                             << b(k, d);
      }
    }
  }
  return ::testing::AssertionSuccess();
}

TEST(X86Avx2, TheVectorLoopsRunOnThisCpu) {
  ASSERT_TRUE(arch::X86Avx2::vector_loops_available())
      << "the build selected CDCR_MODEL_ARCH=x86_avx2, but this CPU lacks AVX2 or FMA";
}

// segments, training points, payload input
class X86Avx2Loops : public ::testing::TestWithParam<std::tuple<int, int, bool>> {};

// 2, 3 and 4 segments take the unrolled loops (4, 6, 8 inputs; 4 segments the
// transposed blocks), 5 segments and the payload models the run-time count.
// 37 points end in a ragged block and chunk; 203 are three chunks and 11.
INSTANTIATE_TEST_SUITE_P(Models, X86Avx2Loops,
                         ::testing::Values(std::make_tuple(2, 37, false), std::make_tuple(3, 37, false),
                                           std::make_tuple(4, 37, false), std::make_tuple(4, 203, false),
                                           std::make_tuple(4, 8, false), std::make_tuple(5, 203, false),
                                           std::make_tuple(2, 203, true), std::make_tuple(4, 203, true),
                                           std::make_tuple(4, 5, true)));

TEST_P(X86Avx2Loops, MeanAndGradientHaveTheScalarLoopsBits) {
  ASSERT_TRUE(arch::X86Avx2::vector_loops_available());
  const auto [segments, points, payload] = GetParam();
  const Model m = make_model(segments, points, payload);
  Vector vector;
  Reference reference;
  ASSERT_EQ(vector.bind(m.view), Status::ok);
  ASSERT_EQ(reference.bind(m.view), Status::ok);
  std::mt19937 rng(3);
  for (int trial = 0; trial < 40; ++trial) {
    const JointVector<float> bend = random_bend(segments, rng, trial < 30 ? 1.2 : 12.0);
    if (payload && trial % 2 == 1) {
      vector.set_payload_kg(0.1f * float(trial % 7));
      reference.set_payload_kg(0.1f * float(trial % 7));
    }
    const Twist<float> mean = vector.predict(bend);
    const Twist<float> expected_mean = reference.predict(bend);
    EXPECT_TRUE(same_bits(mean, expected_mean)) << "trial " << trial << ": " << mean.transpose() << " vs "
                                                << expected_mean.transpose();
    Twist<float> eps, expected_eps;
    Jacobian<float> gradient, expected_gradient;
    ASSERT_EQ(vector(bend, eps, gradient), Status::ok);
    ASSERT_EQ(reference(bend, expected_eps, expected_gradient), Status::ok);
    EXPECT_TRUE(same_bits(eps, expected_eps)) << "trial " << trial;
    EXPECT_TRUE(same_gradient(gradient, expected_gradient)) << "trial " << trial;
  }
}

// The resumable IK solver's slices: the same bits whatever the slice size.
TEST_P(X86Avx2Loops, SlicedEvaluationsHaveTheWholeOnesBits) {
  ASSERT_TRUE(arch::X86Avx2::vector_loops_available());
  const auto [segments, points, payload] = GetParam();
  const Model m = make_model(segments, points, payload);
  Vector vector;
  ASSERT_EQ(vector.bind(m.view), Status::ok);
  std::mt19937 rng(4);
  for (const bool with_gradient : {false, true}) {
    for (const std::uint32_t slice_units : {1u, 8u, 70u, 200u, 640u}) {
      const JointVector<float> bend = random_bend(segments, rng, 1.2);
      Twist<float> whole_eps;
      Jacobian<float> whole_gradient;
      vector.predict_with_gradient(bend, whole_eps, whole_gradient);
      Vector::Evaluation evaluation;
      ASSERT_EQ(vector.begin_evaluation(bend, evaluation, with_gradient), Status::ok);
      int slices = 0;
      while (!vector.evaluation_finished(evaluation)) {
        // A slice too small for one block or chunk advances nothing; give
        // it what the smallest slice needs.
        const std::uint32_t units = std::max(slice_units, vector.smallest_gradient_slice_units());
        ASSERT_GT(vector.continue_evaluation(evaluation, units), 0u);
        ASSERT_LT(++slices, 2000);
      }
      Twist<float> eps;
      Jacobian<float> gradient;
      vector.evaluation_result(evaluation, eps, gradient);
      EXPECT_TRUE(same_bits(eps, whole_eps)) << "slices of " << slice_units << " units";
      if (with_gradient) {
        EXPECT_TRUE(same_gradient(gradient, whole_gradient)) << "slices of " << slice_units;
      }
    }
  }
}

// The mean against the dense sum over the image's own float values, written
// out in double with std::exp: polynomial_gaussian's 1.5 ulp and the float
// block sums leave float-sized differences.
TEST_P(X86Avx2Loops, MeanFollowsTheDenseDoubleSum) {
  const auto [segments, points, payload] = GetParam();
  const Model m = make_model(segments, points, payload);
  Vector vector;
  ASSERT_EQ(vector.bind(m.view), Status::ok);
  const int dims = int(m.view.input_dims);
  std::mt19937 rng(5);
  for (int trial = 0; trial < 20; ++trial) {
    const JointVector<float> bend = random_bend(segments, rng, 1.2);
    float z[kMaxInputs];
    vector.kernel_coordinates(bend, z);
    double sums[kImageOutputs] = {};
    double magnitude[kImageOutputs] = {};
    for (std::uint32_t i = 0; i < m.view.training_points; ++i) {
      double distance_sq = 0;
      for (int d = 0; d < dims; ++d) {
        const double difference = double(z[d]) - double(m.view.inputs[std::size_t(i) * dims + d]);
        distance_sq += difference * difference;
      }
      const double r = std::exp(-0.5 * distance_sq);
      for (int k = 0; k < kImageOutputs; ++k) {
        sums[k] += r * double(m.view.alpha[std::size_t(i) * kImageOutputs + k]);
        magnitude[k] += std::abs(r * double(m.view.alpha[std::size_t(i) * kImageOutputs + k]));
      }
    }
    const Twist<float> mean = vector.predict(bend);
    for (int k = 0; k < kImageOutputs; ++k) {
      const double gain = double(float(m.view.output_scale[k]) * float(m.view.signal_variance[k]));
      const double expected = double(m.view.output_mean[k]) + gain * sums[k];
      EXPECT_NEAR(mean[k], expected, 1e-5 * (std::abs(gain) * magnitude[k] + std::abs(expected)))
          << "output " << k << ", trial " << trial;
    }
  }
}

}  // namespace
}  // namespace cdcr::model
