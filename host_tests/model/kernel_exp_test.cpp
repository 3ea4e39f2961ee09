// The Cortex-M float Gaussian exp(-y/2) of the GP loop against the C
// library's exp in double.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include <gtest/gtest.h>

#include "cdcr/model/kernel_exp.hpp"

namespace cdcr::model {
namespace {

// Distance in float ulps between a float result and the exact value.
double ulps(float result, double exact) {
  const float nearest = static_cast<float>(exact);
  const double ulp = std::nextafter(nearest, std::numeric_limits<float>::infinity()) - nearest;
  return std::abs(static_cast<double>(result) - exact) / ulp;
}

TEST(PolynomialGaussian, WithinOneAndAHalfUlpWhereTermsCount) {
  // y <= 40: kernel values down to 2e-9 of the largest.
  double worst = 0.0;
  double worst_far = 0.0;
  float worst_at = 0.0f;
  // Every 31st float in [0, 173]: about 35 million arguments.
  for (float y = 0.0f; y <= 173.0f;) {
    const double error = ulps(polynomial_gaussian(y), std::exp(-0.5 * static_cast<double>(y)));
    if (y > 40.0f) {
      worst_far = std::max(worst_far, error);
    } else if (error > worst) {
      worst = error;
      worst_at = y;
    }
    std::int32_t bits;
    std::memcpy(&bits, &y, sizeof(bits));
    bits += 31;
    std::memcpy(&y, &bits, sizeof(y));
  }
  EXPECT_LE(worst, 1.5) << "at y = " << worst_at;
  EXPECT_LE(worst_far, 5.0);
  std::cout << "[          ] worst error " << worst << " ulp at y = " << worst_at << ", beyond y = 40: " << worst_far
            << " ulp\n";
}

TEST(PolynomialGaussian, ExactAtZero) { EXPECT_EQ(polynomial_gaussian(0.0f), 1.0f); }

TEST(PolynomialGaussian, ClampsBeyondTheNormalRange) {
  const float floor_value = polynomial_gaussian(173.0f);
  EXPECT_GT(floor_value, 0.0f);
  EXPECT_LE(floor_value, 3e-38f);
  for (float y : {173.5f, 1000.0f, 1e30f, std::numeric_limits<float>::infinity(),
                  std::numeric_limits<float>::quiet_NaN()}) {
    EXPECT_EQ(polynomial_gaussian(y), floor_value) << y;
  }
}

TEST(Gaussian, IsTheLibraryExpOffTheBoards) {
  for (double y : {0.0, 1e-9, 1.0, 20.0, 1400.0}) EXPECT_EQ(gaussian(y), std::exp(-0.5 * y));
#if !(defined(__arm__) && defined(__ARM_FP))
  // Not a Cortex-M: the float path uses the C library too.
  for (float y : {0.0f, 1e-9f, 1.0f, 20.0f, 160.0f}) EXPECT_EQ(gaussian(y), std::exp(-0.5f * y));
  // ... with the polynomial's clamp, which keeps expf off its underflow path
  // and maps NaN as the boards' VMINNM does.
  const float floor_value = std::exp(-0.5f * 173.0f);
  EXPECT_GT(floor_value, 0.0f);
  for (float y : {173.0f, 200.0f, 1e6f, std::numeric_limits<float>::infinity(),
                  std::numeric_limits<float>::quiet_NaN()}) {
    EXPECT_EQ(gaussian(y), floor_value) << y;
  }
#endif
}

}  // namespace
}  // namespace cdcr::model
