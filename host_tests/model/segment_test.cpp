// One segment: cables <-> joints (eqs. 2-5), the constant-curvature pose and
// its POE form (eqs. 6-12), and the spatial twists of its partial
// derivatives. References are evaluated in long double, from formulas or
// library code (Eigen's AngleAxis and matrix exponential) independent of the
// code under test, so the tolerances can sit close to the tested type's
// rounding error.

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <unsupported/Eigen/MatrixFunctions>

#include "cdcr/model/segment.hpp"

#include "../support/pose_distance.hpp"
#include "../support/scalar_types.hpp"

namespace cdcr::model {
namespace {

using test_support::kPi;
using test_support::Real;

// Segment shapes from slender (small r / L, where the cable differences are
// small and joints_from_cables amplifies rounding most) to the prototype.
const std::array<SegmentGeometry<double>, 4> kGeometries = {{
    {120.0, 67.0, 1.5707963267948966},
    {120.0, 70.0, 1.5707963267948966},
    {60.0, 15.0, 1.2},
    {200.0, 8.0, 0.4},
}};

Real wrap_angle(Real angle) { return std::remainder(angle, 2 * kPi); }

template <typename S>
class Segment : public test_support::RandomScalarTest<S, 7u> {
 protected:
  using test_support::RandomScalarTest<S, 7u>::uniform;

  // Random joints with theta uniform in [0, theta_max], plus the values where
  // the parametrisation is singular or wraps.
  std::vector<SegmentJoints<S>> sample_joints(S theta_max_rad, int random_count) {
    std::vector<SegmentJoints<S>> samples;
    const S pi = S(kPi);
    for (const S alpha : {S(0), S(1), S(-2), pi, -pi}) {
      samples.push_back({alpha, S(0)});
      samples.push_back({alpha, theta_max_rad});
    }
    for (const S theta : {S(1e-9), S(1e-6), S(1e-3), S(0.1)}) {
      if (theta > theta_max_rad) continue;
      samples.push_back({pi, theta});
      samples.push_back({-pi, theta});
      samples.push_back({S(uniform(-kPi, kPi)), theta});
    }
    for (int i = 0; i < random_count; ++i) {
      samples.push_back({S(uniform(-kPi, kPi)), S(uniform(0, theta_max_rad))});
    }
    return samples;
  }
};

TYPED_TEST_SUITE(Segment, test_support::Scalars, test_support::ScalarNames);

template <typename S>
SegmentGeometry<S> cast_geometry(const SegmentGeometry<double>& g) {
  return SegmentGeometry<S>{S(g.backbone_length_mm), S(g.anchor_radius_mm), S(g.theta_max_rad)};
}

using test_support::relative_distance;  // pose against its long-double reference

// The note's closed form of the arc, evaluated directly. 1 - cos(theta) is
// written 2 sin^2(theta/2): at theta = 1e-9 the literal form keeps only one
// digit even in long double.
Pose<Real> arc_reference(Real alpha, Real theta, Real length_mm) {
  Pose<Real> pose;
  const Vec3<Real> axis(-std::sin(alpha), std::cos(alpha), 0);
  pose.rotation = Eigen::AngleAxis<Real>(theta, axis).toRotationMatrix();
  if (theta == 0) {
    pose.position_mm = Vec3<Real>(0, 0, length_mm);
  } else {
    const Real k = length_mm / theta;
    const Real one_minus_cos = 2 * std::sin(theta / 2) * std::sin(theta / 2);
    pose.position_mm = k * Vec3<Real>(one_minus_cos * std::cos(alpha), one_minus_cos * std::sin(alpha), std::sin(theta));
  }
  return pose;
}

TYPED_TEST(Segment, JointsSurviveCableRoundTrip) {
  using S = TypeParam;
  for (const SegmentGeometry<double>& g : kGeometries) {
    const SegmentGeometry<S> geometry = cast_geometry<S>(g);
    // Cable differences are about r * theta; each cable carries a rounding
    // of L, so the bend comes back to about eps * L / r.
    const Real bend_tolerance = TestFixture::kTol * g.backbone_length_mm / g.anchor_radius_mm;
    for (const SegmentJoints<S>& q : this->sample_joints(geometry.theta_max_rad, 300)) {
      Vec4<S> cables;
      ASSERT_EQ(cables_from_joints(q, geometry, cables), Status::ok) << q.alpha_rad << ", " << q.theta_rad;
      SegmentJoints<S> back;
      ASSERT_EQ(joints_from_cables(cables, geometry, back), Status::ok)
          << "alpha " << q.alpha_rad << " theta " << q.theta_rad << " limit " << geometry.theta_max_rad;

      // alpha is meaningless on a straight segment: compare bend vectors.
      const Vec2<Real> b = bend_from_joints(q).template cast<Real>();
      const Vec2<Real> b_back = bend_from_joints(back).template cast<Real>();
      EXPECT_LE((b_back - b).norm(), bend_tolerance) << "alpha " << q.alpha_rad << " theta " << q.theta_rad;
      EXPECT_NEAR(Real(back.theta_rad), Real(q.theta_rad), bend_tolerance);
      EXPECT_GE(back.theta_rad, S(0));
      EXPECT_LE(std::abs(back.alpha_rad), S(kPi));
      if (q.theta_rad > S(1e-3)) {
        // +-pi are the same plane: compare modulo 2 pi.
        EXPECT_LE(std::abs(wrap_angle(Real(back.alpha_rad) - Real(q.alpha_rad))), bend_tolerance / q.theta_rad)
            << "alpha " << q.alpha_rad << " theta " << q.theta_rad;
      }
    }
  }
}

TYPED_TEST(Segment, StraightSegmentCablesAreBackboneLength) {
  using S = TypeParam;
  for (const SegmentGeometry<double>& g : kGeometries) {
    const SegmentGeometry<S> geometry = cast_geometry<S>(g);
    for (const S alpha : {S(0), S(0.7), S(-3), S(kPi)}) {
      Vec4<S> cables;
      ASSERT_EQ(cables_from_joints(SegmentJoints<S>{alpha, S(0)}, geometry, cables), Status::ok);
      EXPECT_EQ(cables, Vec4<S>::Constant(geometry.backbone_length_mm));
    }
    SegmentJoints<S> q{S(5), S(5)};
    ASSERT_EQ(joints_from_cables(Vec4<S>(Vec4<S>::Constant(geometry.backbone_length_mm)), geometry, q), Status::ok);
    EXPECT_EQ(q.theta_rad, S(0));
    EXPECT_EQ(q.alpha_rad, S(0));
  }
}

TYPED_TEST(Segment, AlphaPlusAndMinusPiAreTheSameBend) {
  using S = TypeParam;
  const SegmentGeometry<S> geometry = cast_geometry<S>(kGeometries[0]);
  for (const S theta : {S(1e-6), S(0.05), S(1.0), geometry.theta_max_rad}) {
    Vec4<S> plus;
    Vec4<S> minus;
    ASSERT_EQ(cables_from_joints(SegmentJoints<S>{S(kPi), theta}, geometry, plus), Status::ok);
    ASSERT_EQ(cables_from_joints(SegmentJoints<S>{-S(kPi), theta}, geometry, minus), Status::ok);
    EXPECT_LE((plus - minus).cwiseAbs().maxCoeff(), TestFixture::kTol * geometry.backbone_length_mm);
    // l3 < l1 (the plane points along -x), l2 = l4.
    EXPECT_LT(plus[2], plus[0]);
    EXPECT_NEAR(plus[1], plus[3], TestFixture::kTol * geometry.backbone_length_mm);

    const Pose<S> pose_plus = segment_pose<S>(bend_from_joints(SegmentJoints<S>{S(kPi), theta}), geometry.backbone_length_mm);
    const Pose<S> pose_minus = segment_pose<S>(bend_from_joints(SegmentJoints<S>{-S(kPi), theta}), geometry.backbone_length_mm);
    EXPECT_LE(relative_distance(pose_plus, pose_minus.template cast<Real>()), TestFixture::kTol);
  }
}

TYPED_TEST(Segment, CablesFollowEquationTwo) {
  using S = TypeParam;
  for (const SegmentGeometry<double>& g : kGeometries) {
    const SegmentGeometry<S> geometry = cast_geometry<S>(g);
    for (const SegmentJoints<S>& q : this->sample_joints(geometry.theta_max_rad, 100)) {
      if (q.theta_rad == S(0)) continue;  // (2) is 0/0 there; covered by StraightSegmentCablesAreBackboneLength
      Vec4<S> cables;
      ASSERT_EQ(cables_from_joints(q, geometry, cables), Status::ok);
      const Real theta = q.theta_rad;
      const Real alpha = q.alpha_rad;
      const Real half_sin = std::sin(theta / 2);
      for (int j = 0; j < 4; ++j) {
        const Real expected = 2 * (Real(geometry.backbone_length_mm) / theta) * half_sin -
                              2 * Real(geometry.anchor_radius_mm) * std::cos(alpha + j * kPi / 2) * half_sin;
        EXPECT_NEAR(Real(cables[j]), expected, TestFixture::kTol * geometry.backbone_length_mm)
            << "cable " << j + 1 << " alpha " << alpha << " theta " << theta;
      }
    }
  }
}

TYPED_TEST(Segment, StraightPoseIsExact) {
  using S = TypeParam;
  for (const SegmentGeometry<double>& g : kGeometries) {
    const S length = S(g.backbone_length_mm);
    for (const Vec2<S>& bend : {Vec2<S>(0, 0), Vec2<S>(-0.0, 0), Vec2<S>(0, -0.0)}) {
      const Pose<S> pose = segment_pose<S>(bend, length);
      EXPECT_EQ(pose.rotation, Mat3<S>::Identity());
      EXPECT_EQ(pose.position_mm, Vec3<S>(0, 0, length));
    }
    const Pose<S> initial = segment_initial_pose<S>(length);
    EXPECT_EQ(initial.rotation, Mat3<S>::Identity());
    EXPECT_EQ(initial.position_mm, Vec3<S>(0, 0, length));
  }
}

TYPED_TEST(Segment, PoseMatchesArcClosedForm) {
  using S = TypeParam;
  for (const SegmentGeometry<double>& g : kGeometries) {
    const S length = S(g.backbone_length_mm);
    for (const SegmentJoints<S>& q : this->sample_joints(S(g.theta_max_rad), 200)) {
      const Pose<S> pose = segment_pose<S>(bend_from_joints(q), length);
      const Pose<Real> reference = arc_reference(q.alpha_rad, q.theta_rad, length);
      EXPECT_LE(relative_distance(pose, reference), TestFixture::kTol)
          << "alpha " << q.alpha_rad << " theta " << q.theta_rad;
    }
  }
}

TYPED_TEST(Segment, PositionMatchesNoteFormulaAwayFromStraight) {
  using S = TypeParam;
  // p = (L/theta) ((1 - cos) cos alpha, (1 - cos) sin alpha, sin), written
  // out once more on its own, for theta where the quotient is well conditioned.
  const S length = S(120);
  for (int i = 0; i < 300; ++i) {
    const Real alpha = S(this->uniform(-kPi, kPi));
    const Real theta = S(this->uniform(1e-2, kPi / 2));
    const Vec3<Real> expected = (length / theta) * Vec3<Real>((1 - std::cos(theta)) * std::cos(alpha),
                                                              (1 - std::cos(theta)) * std::sin(alpha), std::sin(theta));
    const Vec3<S> p = segment_pose<S>(bend_from_joints(SegmentJoints<S>{S(alpha), S(theta)}), length).position_mm;
    EXPECT_LE((p.template cast<Real>() - expected).norm(), TestFixture::kTol * length);
  }
}

TYPED_TEST(Segment, PoseEqualsProductOfExponentials) {
  using S = TypeParam;
  // Eq. (6): T(alpha, theta) = exp(hat(xi) theta) T(0), checked both with the
  // library's exp and with Eigen's matrix exponential of the same screw.
  for (const SegmentGeometry<double>& g : kGeometries) {
    const S length = S(g.backbone_length_mm);
    for (const SegmentJoints<S>& q : this->sample_joints(S(g.theta_max_rad), 100)) {
      const Pose<S> pose = segment_pose<S>(bend_from_joints(q), length);
      const Twist<S> screw = segment_screw_axis<S>(q, length);
      EXPECT_TRUE(screw.allFinite());

      const Pose<S> poe = exp<S>(Twist<S>(screw * q.theta_rad)) * segment_initial_pose<S>(length);
      EXPECT_LE(relative_distance(poe, pose.template cast<Real>()), TestFixture::kTol)
          << "alpha " << q.alpha_rad << " theta " << q.theta_rad;

      const Twist<Real> screw_reference =
          segment_screw_axis<Real>(SegmentJoints<Real>{q.alpha_rad, q.theta_rad}, Real(length));
      const Mat4<Real> exponential = (hat<Real>(screw_reference) * Real(q.theta_rad)).exp();
      const Pose<Real> reference = Pose<Real>::from_matrix(exponential) * segment_initial_pose<Real>(length);
      EXPECT_LE(relative_distance(pose, reference), TestFixture::kTol)
          << "alpha " << q.alpha_rad << " theta " << q.theta_rad;
    }
  }
}

TYPED_TEST(Segment, ScrewAxisOfStraightSegment) {
  using S = TypeParam;
  // The axis stays finite at theta = 0: a pure rotation about the line
  // through (0, 0, L/2) along (-sin alpha, cos alpha, 0).
  const S length = S(120);
  for (const S alpha : {S(0), S(0.5), S(-2.5), S(kPi)}) {
    const Twist<S> screw = segment_screw_axis<S>(SegmentJoints<S>{alpha, S(0)}, length);
    Twist<S> expected;
    expected << -length * std::cos(alpha) / 2, -length * std::sin(alpha) / 2, S(0), -std::sin(alpha), std::cos(alpha), S(0);
    EXPECT_LE((screw - expected).cwiseAbs().maxCoeff(), TestFixture::kTol * length);
  }
}

// Central difference of the spatial twist of a pose-valued function of two
// coordinates, in long double:
//   D(h) = vee(log(T(q + h e_k) T(q - h e_k)^-1)) / (2h) = (dT/dq_k) T^-1 + O(h^2).
// The log of the quotient is odd in h, so its error has only even powers and
// one Richardson step, (4 D(h/2) - D(h)) / 3, removes the h^2 term. With
// h = 1e-4 the remaining truncation (h^4) and rounding (1e-19 * L / h) both
// stay well below the 1e-12 tolerance of the double tests.
template <typename PoseOf>
Eigen::Matrix<Real, 6, 2> spatial_finite_difference(const PoseOf& pose_of, const Vec2<Real>& q) {
  const auto central = [&](int k, Real h) -> Twist<Real> {
    const Vec2<Real> step = h * Vec2<Real>::Unit(k);
    return log<Real>(pose_of(Vec2<Real>(q + step)) * pose_of(Vec2<Real>(q - step)).inverse()) / (2 * h);
  };
  const Real h = 1e-4L;
  Eigen::Matrix<Real, 6, 2> result;
  for (int k = 0; k < 2; ++k) result.col(k) = (4 * central(k, h / 2) - central(k, h)) / 3;
  return result;
}

// Columns compared with linear parts relative to the backbone length and
// angular parts relative to 1 rad.
template <typename S>
Real relative_twist_error(const Eigen::Matrix<S, 6, 2>& actual, const Eigen::Matrix<Real, 6, 2>& expected, Real length_mm) {
  const Eigen::Matrix<Real, 6, 2> error = actual.template cast<Real>() - expected;
  return std::max(error.template topRows<3>().cwiseAbs().maxCoeff() / length_mm,
                  error.template bottomRows<3>().cwiseAbs().maxCoeff());
}

TYPED_TEST(Segment, BendTwistsMatchFiniteDifferences) {
  using S = TypeParam;
  for (const SegmentGeometry<double>& g : kGeometries) {
    const Real length = S(g.backbone_length_mm);
    const auto pose_of = [length](const Vec2<Real>& bend) { return segment_pose<Real>(bend, length); };
    // The bend vector is smooth through zero, so straight and nearly straight
    // segments are tested like any other.
    for (const SegmentJoints<S>& q : this->sample_joints(S(g.theta_max_rad), 100)) {
      const Vec2<S> bend = bend_from_joints(q);
      const Eigen::Matrix<S, 6, 2> twists = segment_bend_twists<S>(bend, S(length));
      const Eigen::Matrix<Real, 6, 2> reference = spatial_finite_difference(pose_of, bend.template cast<Real>());
      EXPECT_LE(relative_twist_error(twists, reference, length), TestFixture::kTol)
          << "alpha " << q.alpha_rad << " theta " << q.theta_rad;
    }
  }
}

TYPED_TEST(Segment, JointTwistsMatchFiniteDifferences) {
  using S = TypeParam;
  for (const SegmentGeometry<double>& g : kGeometries) {
    const Real length = S(g.backbone_length_mm);
    const auto pose_of = [length](const Vec2<Real>& alpha_theta) {
      return segment_pose<Real>(bend_from_joints(SegmentJoints<Real>{alpha_theta[0], alpha_theta[1]}), length);
    };
    for (const SegmentJoints<S>& q : this->sample_joints(S(g.theta_max_rad), 100)) {
      // The difference steps theta by 1e-4 either way, and the arc is only
      // smooth in (alpha, theta) for theta > 0; theta = 0 is tested below.
      if (q.theta_rad < S(1e-3)) continue;
      const Eigen::Matrix<S, 6, 2> twists = segment_joint_twists<S>(q, S(length));
      const Eigen::Matrix<Real, 6, 2> reference = spatial_finite_difference(pose_of, Vec2<Real>(q.alpha_rad, q.theta_rad));
      EXPECT_LE(relative_twist_error(twists, reference, length), TestFixture::kTol)
          << "alpha " << q.alpha_rad << " theta " << q.theta_rad;
    }
  }
}

TYPED_TEST(Segment, JointTwistsAreBendTwistsThroughChainRule) {
  using S = TypeParam;
  // d/dalpha = theta (-sin, cos) . d/db and d/dtheta = (cos, sin) . d/db,
  // including theta = 0, where the alpha column must vanish exactly.
  const S length = S(120);
  for (const SegmentJoints<S>& q : this->sample_joints(S(kPi / 2), 100)) {
    const Eigen::Matrix<S, 6, 2> joint = segment_joint_twists<S>(q, length);
    const Eigen::Matrix<S, 6, 2> bend = segment_bend_twists<S>(bend_from_joints(q), length);
    Eigen::Matrix<S, 2, 2> d_bend_d_joints;
    d_bend_d_joints << -q.theta_rad * std::sin(q.alpha_rad), std::cos(q.alpha_rad),
                        q.theta_rad * std::cos(q.alpha_rad), std::sin(q.alpha_rad);
    const Eigen::Matrix<S, 6, 2> chained = bend * d_bend_d_joints;
    EXPECT_LE(relative_twist_error(joint, chained.template cast<Real>(), length), TestFixture::kTol)
        << "alpha " << q.alpha_rad << " theta " << q.theta_rad;
    if (q.theta_rad == S(0)) {
      EXPECT_TRUE(joint.col(0).isZero(0)) << joint.col(0).transpose();
    }
  }
}

}  // namespace
}  // namespace cdcr::model
