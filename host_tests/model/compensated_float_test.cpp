// CompensatedFloat's TwoSum against Neumaier's ordered Fast2Sum (both give
// the exact error of each addition, so the same bits), and its value against
// the same sum in double.
#include <cmath>
#include <cstring>
#include <random>

#include <gtest/gtest.h>

#include "cdcr/model/compensated_float.hpp"

namespace cdcr::model {
namespace {

// Neumaier's variant, written out here as the reference.
struct OrderedCompensatedSum {
  float sum = 0.0f;
  float compensation = 0.0f;
  void add(float term) {
    const float t = sum + term;
    if (std::abs(sum) >= std::abs(term)) {
      compensation += (sum - t) + term;
    } else {
      compensation += (term - t) + sum;
    }
    sum = t;
  }
};

std::uint32_t bits_of(float value) {
  std::uint32_t bits;
  std::memcpy(&bits, &value, sizeof(bits));
  return bits;
}

TEST(CompensatedFloat, SameBitsAsTheOrderedVariant) {
  std::mt19937 rng(7);
  std::normal_distribution<float> magnitude(0.0f, 6.0f);
  std::uniform_int_distribution<int> sign(0, 1);
  for (int run = 0; run < 200; ++run) {
    CompensatedFloat two_sum;
    OrderedCompensatedSum ordered;
    for (int i = 0; i < 500; ++i) {
      // Terms over many binades, alternating in sign: the sums the GP mean's
      // blocks add up (k_i alpha_i with large alphas of both signs).
      const float term = (sign(rng) ? 1.0f : -1.0f) * std::exp2(magnitude(rng));
      two_sum += term;
      ordered.add(term);
      ASSERT_EQ(bits_of(two_sum.sum), bits_of(ordered.sum)) << "run " << run << " term " << i;
      ASSERT_EQ(bits_of(two_sum.compensation), bits_of(ordered.compensation)) << "run " << run << " term " << i;
    }
  }
}

TEST(CompensatedFloat, RecoversWhatAPlainFloatSumLoses) {
  // 1 + 1e-8 added 10,000 times: a float sum stays at 1 (each 1e-8 is below
  // half an ulp of 1), the compensated sum finds the 1e-4.
  CompensatedFloat compensated;
  float plain = 0.0f;
  double reference = 0.0;
  compensated += 1.0f;
  plain += 1.0f;
  reference += 1.0;
  for (int i = 0; i < 10000; ++i) {
    compensated += 1e-8f;
    plain += 1e-8f;
    reference += double(1e-8f);
  }
  EXPECT_EQ(plain, 1.0f);
  EXPECT_NEAR(compensated.value(), reference, 1e-7);
}

TEST(CompensatedFloat, CancellingTermsLeaveTheSmallOnes) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> small(-1e-3f, 1e-3f);
  CompensatedFloat compensated;
  double reference = 0.0;
  for (int i = 0; i < 1000; ++i) {
    const float big = 1e4f * float(i % 7 + 1);
    const float s = small(rng);
    for (const float term : {big, s, -big}) {
      compensated += term;
      reference += double(term);
    }
  }
  EXPECT_NEAR(compensated.value(), reference, 1e-6 * 1e4);
  EXPECT_NEAR(compensated.value(), reference, 2e-7 * std::abs(reference) + 1e-6);
}

}  // namespace
}  // namespace cdcr::model
