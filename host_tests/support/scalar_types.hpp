#pragma once
// What the typed model tests share: every test runs in float and in double,
// named so in the test list, and compares against long-double references.

#include <random>
#include <string>
#include <type_traits>

#include <gtest/gtest.h>

namespace cdcr::test_support {

using Real = long double;
inline constexpr Real kPi = 3.141592653589793238462643383279502884L;

using Scalars = ::testing::Types<float, double>;

struct ScalarNames {
  template <typename S>
  static std::string GetName(int) {
    return std::is_same_v<S, float> ? "float" : "double";
  }
};

// Relative error bounds, a few tens of roundings of the tested type: the
// references (long double) are exact to that scale.
template <typename S> struct RelativeTolerance;
template <> struct RelativeTolerance<float> { static constexpr Real value = 1e-5L; };
template <> struct RelativeTolerance<double> { static constexpr Real value = 1e-12L; };

// The fixture of a typed test that draws its inputs: each test starts the
// generator from the same seed, so a failure repeats.
template <typename S, unsigned Seed>
class RandomScalarTest : public ::testing::Test {
 protected:
  static constexpr Real kTol = RelativeTolerance<S>::value;
  std::mt19937 rng{Seed};

  Real uniform(Real lo, Real hi) { return std::uniform_real_distribution<double>(double(lo), double(hi))(rng); }
};

}  // namespace cdcr::test_support
