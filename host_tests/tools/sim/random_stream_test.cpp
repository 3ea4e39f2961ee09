// The reproducible random stream: a seed names a sequence, streams of one
// seed are independent, and the conversions have the right distributions.

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "sim/random_stream.hpp"

namespace cdcr::sim {
namespace {

TEST(RandomStream, SameSeedSameSequence) {
  RandomStream a(42, StreamId::noise);
  RandomStream b(42, StreamId::noise);
  for (int i = 0; i < 1000; ++i) {
    ASSERT_EQ(a.uniform(), b.uniform());
    ASSERT_EQ(a.normal(), b.normal());
  }
}

TEST(RandomStream, SeedsAndStreamsDiffer) {
  RandomStream robot(1, StreamId::robot);
  RandomStream workspace(1, StreamId::workspace);
  RandomStream noise(1, StreamId::noise);
  RandomStream payload(1, StreamId::payload);
  RandomStream other_seed(2, StreamId::robot);
  int equal_streams = 0;
  int equal_seeds = 0;
  for (int i = 0; i < 100; ++i) {
    const double r = robot.uniform();
    const double w = workspace.uniform();
    const double n = noise.uniform();
    const double p = payload.uniform();
    equal_streams += (r == w) + (r == n) + (r == p) + (w == n) + (w == p) + (n == p);
    equal_seeds += r == other_seed.uniform();
  }
  EXPECT_EQ(equal_streams, 0);
  EXPECT_EQ(equal_seeds, 0);
}

TEST(RandomStream, UniformIsInRangeWithTheRightMoments) {
  RandomStream random(7, StreamId::workspace);
  constexpr int n = 200000;
  double sum = 0.0, sum_sq = 0.0;
  for (int i = 0; i < n; ++i) {
    const double u = random.uniform();
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    sum += u;
    sum_sq += u * u;
  }
  const double mean = sum / n;
  EXPECT_NEAR(mean, 0.5, 0.005);
  EXPECT_NEAR(sum_sq / n - mean * mean, 1.0 / 12.0, 0.002);
}

TEST(RandomStream, NormalHasTheRightMoments) {
  RandomStream random(7, StreamId::noise);
  constexpr int n = 200000;
  double sum = 0.0, sum_sq = 0.0, sum_abs = 0.0;
  int beyond_two_sigma = 0;
  for (int i = 0; i < n; ++i) {
    const double x = random.normal(2.0);
    sum += x;
    sum_sq += x * x;
    sum_abs += std::abs(x);
    beyond_two_sigma += std::abs(x) > 4.0;
  }
  EXPECT_NEAR(sum / n, 0.0, 0.02);
  EXPECT_NEAR(std::sqrt(sum_sq / n), 2.0, 0.02);
  EXPECT_NEAR(sum_abs / n, 2.0 * std::sqrt(2.0 / 3.14159265358979323846), 0.02);
  EXPECT_NEAR(static_cast<double>(beyond_two_sigma) / n, 0.0455, 0.003);
}

}  // namespace
}  // namespace cdcr::sim
