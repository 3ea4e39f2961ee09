#pragma once
// What the typed model tests share: every test runs in float and in double,
// named so in the test list, and compares against long-double references.

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

}  // namespace cdcr::test_support
