// The Cortex-M float exp of the GP loop against the C library's exp in double.
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

TEST(PolynomialExp, WithinTwoUlpOverTheWholeRange) {
  double worst = 0.0;
  float worst_at = 0.0f;
  // Every 61st float in [-86.5, 0]: about 17 million arguments.
  for (float x = 0.0f; x >= -86.5f;) {
    const double error = ulps(polynomial_exp(x), std::exp(static_cast<double>(x)));
    if (error > worst) {
      worst = error;
      worst_at = x;
    }
    std::int32_t bits;
    std::memcpy(&bits, &x, sizeof(bits));
    bits = x == 0.0f ? static_cast<std::int32_t>(0x80000001) : bits + 61;
    std::memcpy(&x, &bits, sizeof(x));
  }
  EXPECT_LE(worst, 2.0) << "at x = " << worst_at;
  std::cout << "[          ] worst error " << worst << " ulp at x = " << worst_at << "\n";
}

TEST(PolynomialExp, ExactWhereExpIsExact) {
  EXPECT_EQ(polynomial_exp(0.0f), 1.0f);
  EXPECT_EQ(polynomial_exp(-0.0f), 1.0f);
}

TEST(PolynomialExp, VanishesBelowTheNormalRange) {
  for (float x : {-86.6f, -100.0f, -1e30f, -std::numeric_limits<float>::infinity()}) {
    EXPECT_LE(polynomial_exp(x), 2.8e-38f) << x;
    EXPECT_GE(polynomial_exp(x), 0.0f) << x;
  }
}

TEST(KernelExp, IsTheLibraryExpOffTheBoards) {
  for (double x : {0.0, -1e-9, -0.5, -10.0, -700.0}) EXPECT_EQ(kernel_exp(x), std::exp(x));
#if !(defined(__arm__) && defined(__ARM_FP))
  // Not a Cortex-M: the float path uses the C library too.
  for (float x : {0.0f, -1e-9f, -0.5f, -10.0f, -80.0f}) EXPECT_EQ(kernel_exp(x), std::exp(x));
#endif
}

}  // namespace
}  // namespace cdcr::model
