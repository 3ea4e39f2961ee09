// Properties of the SE(3) exponential coordinates, in float and in double.
// References are computed in long double, independently of the code under
// test where possible (Eigen's matrix exponential, Eigen's AngleAxis), so a
// tolerance close to the rounding error of the tested type is meaningful.

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <type_traits>

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <unsupported/Eigen/MatrixFunctions>

#include "cdcr/model/se3.hpp"

#include "../support/pose_distance.hpp"
#include "../support/scalar_types.hpp"

namespace cdcr::model {
namespace {

using test_support::kPi;
using test_support::Real;

// Error bounds (test_support::RelativeTolerance) are relative to the size of
// the compared quantity (a rotation entry, or a translation divided by
// max(1 mm, its norm)). The worst observed errors are about ten roundings of
// the tested type (6e-7 in float, 1.3e-15 in double); the bounds leave a wide
// margin without letting an O(h) series or branch mistake through.
template <typename S> struct JacobianTolerance;
// The left Jacobian is compared against finite differences taken in long
// double, so only the float rounding of its ten-term series counts.
template <> struct JacobianTolerance<float> { static constexpr Real value = 2e-5L; };
// The left Jacobian truncates its series after ten terms; for rotations up
// to 0.3 rad the omitted term is about 0.3^10 / 11! = 1.5e-13 relative.
template <> struct JacobianTolerance<double> { static constexpr Real value = 2e-12L; };

template <typename S>
class Se3 : public test_support::RandomScalarTest<S, 20200417u> {
 protected:
  using test_support::RandomScalarTest<S, 20200417u>::rng;
  using test_support::RandomScalarTest<S, 20200417u>::uniform;

  Vec3<Real> random_unit_vector() {
    std::normal_distribution<double> normal;
    Vec3<Real> v;
    do {
      v = Vec3<Real>(normal(rng), normal(rng), normal(rng));
    } while (v.norm() < 1e-3L);
    return v.normalized();
  }

  // Twist with rotation angle uniform in [0, max_angle) and each translation
  // component uniform in [-max_translation, max_translation]. Sampled in long
  // double and rounded to S once, so the reference sees exactly the input
  // the code under test sees.
  Twist<S> random_twist(Real max_angle_rad, Real max_translation_mm) {
    Twist<Real> xi;
    xi.template head<3>() = Vec3<Real>(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1)) * max_translation_mm;
    xi.template tail<3>() = uniform(0, max_angle_rad) * random_unit_vector();
    return xi.template cast<S>();
  }

  Pose<S> random_pose() {
    Pose<Real> pose;
    pose.rotation = Eigen::AngleAxis<Real>(uniform(0, kPi), random_unit_vector()).toRotationMatrix();
    pose.position_mm = Vec3<Real>(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1)) * Real(300);
    return pose.template cast<S>();
  }
};

TYPED_TEST_SUITE(Se3, test_support::Scalars, test_support::ScalarNames);

using test_support::relative_distance;  // pose against its long-double reference

template <typename S>
Real relative_distance(const Pose<S>& actual, const Pose<S>& expected) {
  return relative_distance(actual, expected.template cast<Real>());
}

// Twist difference relative to max(1, |expected|) separately for the linear
// (mm) and angular (rad) parts.
template <typename S>
Real relative_distance(const Twist<S>& actual, const Twist<Real>& expected) {
  const Twist<Real> d = actual.template cast<Real>() - expected;
  return std::max(d.template head<3>().norm() / std::max(Real(1), expected.template head<3>().norm()),
                  d.template tail<3>().norm() / std::max(Real(1), expected.template tail<3>().norm()));
}

template <typename S>
Real relative_distance(const Twist<S>& actual, const Twist<S>& expected) {
  return relative_distance(actual, Twist<Real>(expected.template cast<Real>()));
}

Pose<Real> matrix_exponential(const Twist<Real>& xi) {
  const Mat4<Real> m = hat<Real>(xi);
  return Pose<Real>::from_matrix(m.exp());
}

TYPED_TEST(Se3, HatAndVeeAreInverse) {
  using S = TypeParam;
  for (int trial = 0; trial < 100; ++trial) {
    const Twist<S> xi = this->random_twist(kPi, 100);
    const Mat4<S> m = hat<S>(xi);
    EXPECT_EQ(vee<S>(m), xi);
    EXPECT_EQ(hat<S>(vee<S>(m)), m);
    EXPECT_TRUE(m.row(3).isZero(0));

    const Vec3<S> w = xi.template tail<3>();
    const Vec3<S> u = xi.template head<3>();
    EXPECT_EQ(vee3<S>(hat3<S>(w)), w);
    EXPECT_EQ(Mat3<S>(hat3<S>(w).transpose()), Mat3<S>(-hat3<S>(w)));
    EXPECT_LE((hat3<S>(w) * u - w.cross(u)).norm(), TestFixture::kTol * (1 + w.norm() * u.norm()));
  }
}

TYPED_TEST(Se3, ZeroTwistIsIdentity) {
  using S = TypeParam;
  const Pose<S> pose = exp<S>(Twist<S>::Zero());
  EXPECT_EQ(pose.rotation, Mat3<S>::Identity());
  EXPECT_EQ(pose.position_mm, Vec3<S>::Zero());
  EXPECT_EQ(log<S>(Pose<S>::identity()), Twist<S>::Zero());
  EXPECT_EQ(log_so3<S>(Mat3<S>::Identity()), Vec3<S>::Zero());
}

TYPED_TEST(Se3, ExpMatchesMatrixExponential) {
  using S = TypeParam;
  for (int trial = 0; trial < 500; ++trial) {
    const Twist<S> xi = this->random_twist(kPi, 100);
    const Pose<Real> reference = matrix_exponential(xi.template cast<Real>());
    EXPECT_LE(relative_distance(exp<S>(xi), reference), TestFixture::kTol) << "xi = " << xi.transpose();
  }
}

TYPED_TEST(Se3, ExpIsARigidTransform) {
  using S = TypeParam;
  for (int trial = 0; trial < 200; ++trial) {
    const Pose<S> pose = exp<S>(this->random_twist(kPi, 100));
    EXPECT_LE((pose.rotation.transpose() * pose.rotation - Mat3<S>::Identity()).cwiseAbs().maxCoeff(),
              TestFixture::kTol);
    EXPECT_NEAR(pose.rotation.determinant(), S(1), TestFixture::kTol);
  }
}

TYPED_TEST(Se3, ExpOfLogIsIdentityOnPoses) {
  using S = TypeParam;
  for (int trial = 0; trial < 1000; ++trial) {
    const Pose<S> pose = this->random_pose();
    const Twist<S> xi = log<S>(pose);
    EXPECT_LE(xi.template tail<3>().norm(), S(kPi) * (1 + S(TestFixture::kTol)));
    EXPECT_LE(relative_distance(exp<S>(xi), pose), TestFixture::kTol) << "trial " << trial;
  }
}

TYPED_TEST(Se3, LogOfExpIsIdentityOnTwists) {
  using S = TypeParam;
  for (int trial = 0; trial < 1000; ++trial) {
    const Twist<S> xi = this->random_twist(kPi, 100);
    EXPECT_LE(relative_distance(log<S>(exp<S>(xi)), xi), TestFixture::kTol) << "xi = " << xi.transpose();
  }
}

// Axes along the coordinate axes (where single entries of R vanish) and off them.
template <typename S>
std::array<Vec3<S>, 6> test_axes() {
  return {Vec3<S>::UnitX(), Vec3<S>::UnitY(), Vec3<S>::UnitZ(), Vec3<S>(-1, 0, 0),
          Vec3<S>(1, 1, 1).normalized(), Vec3<S>(0.36, -0.48, 0.8)};
}

TYPED_TEST(Se3, LogRecoversSmallAngles) {
  using S = TypeParam;
  for (const Real angle : {Real(1e-8), Real(1e-4)}) {
    for (const Vec3<S>& axis : test_axes<S>()) {
      const Vec3<S> w = S(angle) * axis;
      const Mat3<S> rotation = exp_so3<S>(w);
      // exp_so3 against the long-double rotation of the same vector.
      const Mat3<Real> reference =
          Eigen::AngleAxis<Real>(w.template cast<Real>().norm(), w.template cast<Real>().normalized()).toRotationMatrix();
      EXPECT_LE((rotation.template cast<Real>() - reference).cwiseAbs().maxCoeff(), TestFixture::kTol);
      // Relative to the angle itself: a small rotation must not be lost in
      // the rounding of the unit diagonal.
      const Vec3<S> recovered = log_so3<S>(rotation);
      EXPECT_LE((recovered - w).norm(), TestFixture::kTol * angle) << "angle " << double(angle);
    }
  }
}

TYPED_TEST(Se3, LogNearPiRecoversAngleAndAxis) {
  using S = TypeParam;
  const Real angle = kPi - Real(1e-6);
  // atan2(sin, cos) stays well conditioned next to pi, where acos would lose
  // half the digits, so in double the angle comes back to 1e-12. In float,
  // pi - 1e-6 is only four ulps below pi: the rotation is checked tightly and
  // the angle to float resolution there.
  const Real angle_tolerance = std::is_same_v<S, double> ? Real(1e-12) : Real(1e-6);
  for (const Vec3<S>& axis : test_axes<S>()) {
    const Mat3<Real> reference = Eigen::AngleAxis<Real>(angle, axis.template cast<Real>()).toRotationMatrix();
    const Mat3<S> rotation = reference.template cast<S>();
    const Vec3<S> w = log_so3<S>(rotation);
    EXPECT_NEAR(Real(w.norm()), angle, angle_tolerance);
    EXPECT_LE((exp_so3<S>(w).template cast<Real>() - reference).cwiseAbs().maxCoeff(), TestFixture::kTol);
    if constexpr (std::is_same_v<S, double>) {
      EXPECT_LE((w.normalized() - axis).norm(), Real(1e-10)) << axis.transpose();
    }
  }
}

TYPED_TEST(Se3, LogAtExactlyPi) {
  using S = TypeParam;
  const S pi = S(kPi);
  for (const Vec3<S>& axis : test_axes<S>()) {
    // R = 2 a a^T - I is exactly symmetric: the skew part that carries the
    // axis everywhere else is zero, so the axis must come from R + R^T.
    const Mat3<S> rotation = S(2) * axis * axis.transpose() - Mat3<S>::Identity();
    for (const Mat3<S>& r : {rotation, exp_so3<S>(pi * axis)}) {
      const Vec3<S> w = log_so3<S>(r);
      EXPECT_NEAR(w.norm(), pi, 4 * std::numeric_limits<S>::epsilon() * pi) << axis.transpose();
      EXPECT_LE((exp_so3<S>(w) - r).cwiseAbs().maxCoeff(), TestFixture::kTol) << axis.transpose();
      // Either sign of the axis is a correct logarithm at pi.
      EXPECT_NEAR(std::abs(w.normalized().dot(axis)), S(1), TestFixture::kTol);
    }
    // The same for a full pose: the translation goes through V^-1 at pi.
    Pose<S> pose;
    pose.rotation = rotation;
    pose.position_mm = Vec3<S>(12.5, -40, 230);
    EXPECT_LE(relative_distance(exp<S>(log<S>(pose)), pose), TestFixture::kTol) << axis.transpose();
  }
}

TYPED_TEST(Se3, TinyTwists) {
  using S = TypeParam;
  for (int trial = 0; trial < 200; ++trial) {
    Twist<Real> raw;
    for (int k = 0; k < 6; ++k) raw[k] = this->uniform(-1, 1);
    const Twist<S> xi = (Real(1e-8) * raw).template cast<S>();
    const Real size = xi.template cast<Real>().norm();

    const Pose<Real> reference = matrix_exponential(xi.template cast<Real>());
    const Pose<S> pose = exp<S>(xi);
    // The off-diagonal entries are of the size of the twist and must keep
    // their own relative precision, not just the absolute precision of the
    // unit diagonal (whose deviation from 1, ~1e-16, is below resolution).
    const Mat3<Real> error = pose.rotation.template cast<Real>() - reference.rotation;
    EXPECT_LE(error.diagonal().cwiseAbs().maxCoeff(), Real(std::numeric_limits<S>::epsilon()));
    const Mat3<Real> off_diagonal = error - Mat3<Real>(error.diagonal().asDiagonal());
    EXPECT_LE(off_diagonal.cwiseAbs().maxCoeff(), TestFixture::kTol * size);
    EXPECT_LE((pose.position_mm.template cast<Real>() - reference.position_mm).norm(), TestFixture::kTol * size);
    EXPECT_LE((log<S>(pose) - xi).template cast<Real>().norm(), TestFixture::kTol * size) << xi.transpose();
  }
}

TYPED_TEST(Se3, AdjointConjugatesTwists) {
  using S = TypeParam;
  for (int trial = 0; trial < 200; ++trial) {
    const Pose<S> pose = this->random_pose();
    const Twist<S> xi = this->random_twist(kPi, 100);
    const Mat6<S> adj = adjoint<S>(pose);
    const Twist<S> moved = adj * xi;

    const Mat4<Real> expected =
        pose.matrix().template cast<Real>() * hat<Real>(xi.template cast<Real>()) * pose.inverse().matrix().template cast<Real>();
    const Real scale = std::max(Real(1), expected.cwiseAbs().maxCoeff());
    EXPECT_LE((hat<S>(moved).template cast<Real>() - expected).cwiseAbs().maxCoeff(), TestFixture::kTol * scale);

    // exp(Ad_T xi) = T exp(xi) T^-1.
    EXPECT_LE(relative_distance(exp<S>(moved), Pose<S>(pose * exp<S>(xi) * pose.inverse())), 10 * TestFixture::kTol);

    // apply_adjoint is the same map, column by column.
    Eigen::Matrix<S, 6, 3> columns;
    columns << xi, this->random_twist(1, 10), Twist<S>::Zero();
    const Eigen::Matrix<S, 6, 3> by_matrix = adj * columns;
    apply_adjoint(pose, columns);
    EXPECT_LE((columns - by_matrix).cwiseAbs().maxCoeff(), TestFixture::kTol * scale);
  }
}

TYPED_TEST(Se3, LeftJacobianMatchesFiniteDifferences) {
  using S = TypeParam;
  // Central difference of the spatial velocity, in long double:
  //   D(h) = log(exp(xi + h e_k) exp(xi - h e_k)^-1) / (2h) = J_l(xi) e_k + O(h^2),
  // odd in h, so one Richardson step (4 D(h/2) - D(h)) / 3 leaves O(h^4).
  const Real h = 1e-4L;
  for (int trial = 0; trial < 100; ++trial) {
    const Twist<S> xi = this->random_twist(0.3L, 10);
    const Twist<Real> x = xi.template cast<Real>();
    const auto central = [&](int k, Real step_size) -> Twist<Real> {
      const Twist<Real> step = step_size * Twist<Real>::Unit(k);
      return log<Real>(exp<Real>(Twist<Real>(x + step)) * exp<Real>(Twist<Real>(x - step)).inverse()) / (2 * step_size);
    };
    Mat6<Real> finite_difference;
    for (int k = 0; k < 6; ++k) finite_difference.col(k) = (4 * central(k, h / 2) - central(k, h)) / 3;
    const Mat6<Real> jacobian = left_jacobian<S>(xi).template cast<Real>();
    const Real scale = std::max(Real(1), finite_difference.cwiseAbs().maxCoeff());
    EXPECT_LE((jacobian - finite_difference).cwiseAbs().maxCoeff(), JacobianTolerance<S>::value * scale)
        << "xi = " << xi.transpose();
  }
}

TYPED_TEST(Se3, LeftJacobianAtZeroIsIdentity) {
  using S = TypeParam;
  EXPECT_EQ(left_jacobian<S>(Twist<S>::Zero()), Mat6<S>::Identity());
}

TYPED_TEST(Se3, PoseInverseAndMatrix) {
  using S = TypeParam;
  for (int trial = 0; trial < 100; ++trial) {
    const Pose<S> pose = this->random_pose();
    const Pose<S> identity = pose * pose.inverse();
    EXPECT_LE((identity.rotation - Mat3<S>::Identity()).cwiseAbs().maxCoeff(), TestFixture::kTol);
    // The translation cancels to the rounding of |p|, not to absolute zero.
    EXPECT_LE(identity.position_mm.norm(), TestFixture::kTol * pose.position_mm.norm());
    const Pose<S> round_trip = Pose<S>::from_matrix(pose.matrix());
    EXPECT_EQ(round_trip.rotation, pose.rotation);
    EXPECT_EQ(round_trip.position_mm, pose.position_mm);
    const Pose<S> other = this->random_pose();
    const Mat4<Real> product = pose.matrix().template cast<Real>() * other.matrix().template cast<Real>();
    EXPECT_LE(relative_distance(Pose<S>(pose * other), Pose<Real>::from_matrix(product)), TestFixture::kTol);
  }
}

}  // namespace
}  // namespace cdcr::model
