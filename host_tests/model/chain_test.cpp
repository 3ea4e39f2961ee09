// The robot as a chain of segments (eq. 13): forward kinematics, the spatial
// tip Jacobians, and the compensation identities of eqs. (18)-(19), for
// 1 to kMaxSegments segments chosen at run time with different geometry per
// segment.

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <type_traits>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "cdcr/model/kinematics.hpp"

#include "../support/scalar_types.hpp"

namespace cdcr::model {
namespace {

using test_support::kPi;
using test_support::Real;

// Forward kinematics and the Jacobians are a few dozen operations per
// segment, so the observed error is a few tens of roundings of the tested
// type: test_support::RelativeTolerance.
template <typename S>
class Chain : public test_support::RandomScalarTest<S, 13u> {
 protected:
  using test_support::RandomScalarTest<S, 13u>::uniform;

  // Each segment different: slender to stubby, small to full bending range.
  RobotGeometry<S> random_geometry(int segment_count) {
    RobotGeometry<S> geometry;
    geometry.segment_count = segment_count;
    for (int i = 0; i < segment_count; ++i) {
      geometry.segments[i] = SegmentGeometry<S>{S(uniform(40, 200)), S(uniform(5, 80)), S(uniform(0.3, kPi / 2))};
    }
    return geometry;
  }

  // theta uniform in [theta_min, theta_max] of each segment; with
  // straight_probability, a segment is set exactly straight instead.
  JointVector<S> random_joints(const RobotGeometry<S>& geometry, S theta_min = S(0), Real straight_probability = 0) {
    JointVector<S> joints(2 * geometry.segment_count);
    for (int i = 0; i < geometry.segment_count; ++i) {
      joints[2 * i] = S(uniform(-kPi, kPi));
      joints[2 * i + 1] = S(uniform(theta_min, geometry.segments[i].theta_max_rad));
      if (uniform(0, 1) < straight_probability) joints[2 * i + 1] = S(0);
    }
    return joints;
  }
};

TYPED_TEST_SUITE(Chain, test_support::Scalars, test_support::ScalarNames);

template <typename S>
Real total_length(const RobotGeometry<S>& geometry) {
  Real length = 0;
  for (int i = 0; i < geometry.segment_count; ++i) length += geometry.segments[i].backbone_length_mm;
  return length;
}

// The chain written out as the explicit product T_01 T_12 ... of segment
// poses, in long double, from bend vectors (no limit check, so finite
// differences may step past theta_max or through zero).
Pose<Real> product_of_segment_poses(const JointVector<Real>& bend, const RobotGeometry<Real>& geometry) {
  Mat4<Real> tip = Mat4<Real>::Identity();
  for (int i = 0; i < geometry.segment_count; ++i) {
    tip = tip * segment_pose<Real>(bend.segment<2>(2 * i), geometry.segments[i].backbone_length_mm).matrix();
  }
  return Pose<Real>::from_matrix(tip);
}

Pose<Real> product_of_segment_poses_from_joints(const JointVector<Real>& joints, const RobotGeometry<Real>& geometry) {
  return product_of_segment_poses(bend_from_joints(joints), geometry);
}

// Rotation entries absolutely; position relative to the robot length.
template <typename S>
Real relative_distance(const Pose<S>& actual, const Pose<Real>& expected, Real length_mm) {
  return std::max((actual.rotation.template cast<Real>() - expected.rotation).cwiseAbs().maxCoeff(),
                  (actual.position_mm.template cast<Real>() - expected.position_mm).norm() / length_mm);
}

// Spatial Jacobian by central differences in long double, with one
// Richardson step (the log of T(q+h) T(q-h)^-1 is odd in h, so
// (4 D(h/2) - D(h)) / 3 is O(h^4)). h = 1e-4 keeps truncation and rounding
// (1e-19 * length / h) far below the tested tolerances.
template <typename PoseOf>
Jacobian<Real> spatial_finite_difference(const PoseOf& pose_of, const JointVector<Real>& q) {
  const auto central = [&](Eigen::Index k, Real h) -> Twist<Real> {
    JointVector<Real> plus = q;
    JointVector<Real> minus = q;
    plus[k] += h;
    minus[k] -= h;
    return log<Real>(pose_of(plus) * pose_of(minus).inverse()) / (2 * h);
  };
  const Real h = 1e-4L;
  Jacobian<Real> result(6, q.size());
  for (Eigen::Index k = 0; k < q.size(); ++k) result.col(k) = (4 * central(k, h / 2) - central(k, h)) / 3;
  return result;
}

// Linear rows relative to the robot length, angular rows relative to 1 rad.
template <typename S>
Real relative_jacobian_error(const Jacobian<S>& actual, const Jacobian<Real>& expected, Real length_mm) {
  const Jacobian<Real> error = actual.template cast<Real>() - expected;
  return std::max(error.template topRows<3>().cwiseAbs().maxCoeff() / length_mm,
                  error.template bottomRows<3>().cwiseAbs().maxCoeff());
}

// The tip pose and spatial tip Jacobian computed at `at` against pose_of (in
// long double) there and its central differences.
template <typename S, typename PoseOf>
void expect_tip_and_jacobian_of(const PoseOf& pose_of, const JointVector<S>& at, const Pose<S>& tip,
                                const Jacobian<S>& jacobian, Real length_mm, Real tolerance) {
  const JointVector<Real> reference_at = at.template cast<Real>();
  EXPECT_LE(relative_jacobian_error(jacobian, spatial_finite_difference(pose_of, reference_at), length_mm), tolerance);
  EXPECT_LE(relative_distance(tip, pose_of(reference_at), length_mm), tolerance);
}

TYPED_TEST(Chain, ForwardKinematicsIsProductOfSegmentPoses) {
  using S = TypeParam;
  for (int n = 1; n <= kMaxSegments; ++n) {
    for (int trial = 0; trial < 30; ++trial) {
      const RobotGeometry<S> geometry = this->random_geometry(n);
      const JointVector<S> joints = this->random_joints(geometry, S(0), 0.2L);
      Pose<S> tip;
      ASSERT_EQ(forward_kinematics(joints, geometry, tip), Status::ok);
      const Pose<Real> reference =
          product_of_segment_poses_from_joints(joints.template cast<Real>(), geometry.template cast<Real>());
      EXPECT_LE(relative_distance(tip, reference, total_length(geometry)), TestFixture::kTol) << n << " segments";

      // The unchecked bend-vector path is the same computation.
      const Pose<S> from_bend = forward_kinematics_bend(bend_from_joints(joints), geometry);
      EXPECT_LE(relative_distance(from_bend, tip.template cast<Real>(), total_length(geometry)), TestFixture::kTol);
    }
  }
}

TYPED_TEST(Chain, StraightRobotIsExact) {
  using S = TypeParam;
  for (int n = 1; n <= kMaxSegments; ++n) {
    const RobotGeometry<S> geometry = this->random_geometry(n);
    JointVector<S> joints = JointVector<S>::Zero(2 * n);
    for (int i = 0; i < n; ++i) joints[2 * i] = S(this->uniform(-kPi, kPi));  // alpha irrelevant
    Pose<S> tip;
    ASSERT_EQ(forward_kinematics(joints, geometry, tip), Status::ok);
    S length = S(0);
    for (int i = 0; i < n; ++i) length += geometry.segments[i].backbone_length_mm;
    EXPECT_EQ(tip.rotation, Mat3<S>::Identity());
    EXPECT_EQ(tip.position_mm, Vec3<S>(0, 0, length));
  }
}

TYPED_TEST(Chain, JointJacobianMatchesFiniteDifferences) {
  using S = TypeParam;
  for (int n = 1; n <= kMaxSegments; ++n) {
    for (int trial = 0; trial < 10; ++trial) {
      const RobotGeometry<S> geometry = this->random_geometry(n);
      // theta >= 1e-3: (alpha, theta) are only smooth coordinates away from
      // the straight pose, and the difference steps theta by 1e-4.
      const JointVector<S> joints = this->random_joints(geometry, S(1e-3));
      Pose<S> tip;
      Jacobian<S> jacobian;
      ASSERT_EQ(tip_jacobian(joints, geometry, tip, jacobian), Status::ok);
      ASSERT_EQ(jacobian.cols(), 2 * n);

      const RobotGeometry<Real> reference_geometry = geometry.template cast<Real>();
      const auto pose_of = [&](const JointVector<Real>& q) {
        return product_of_segment_poses_from_joints(q, reference_geometry);
      };
      SCOPED_TRACE(testing::Message() << n << " segments");
      expect_tip_and_jacobian_of(pose_of, joints, tip, jacobian, total_length(geometry), TestFixture::kTol);
    }
  }
}

TYPED_TEST(Chain, BendJacobianMatchesFiniteDifferencesIncludingStraightSegments) {
  using S = TypeParam;
  for (int n = 1; n <= kMaxSegments; ++n) {
    for (int trial = 0; trial < 10; ++trial) {
      const RobotGeometry<S> geometry = this->random_geometry(n);
      // Some segments exactly straight, one possibly nearly straight: the
      // bend vector is a smooth coordinate there and the Jacobian must be too.
      JointVector<S> joints = this->random_joints(geometry, S(0), 0.4L);
      if (trial % 2 == 1) joints[1] = S(1e-9);
      const JointVector<S> bend = bend_from_joints(joints);
      Pose<S> tip;
      Jacobian<S> jacobian;
      tip_jacobian_bend(bend, geometry, tip, jacobian);
      ASSERT_EQ(jacobian.cols(), 2 * n);

      const RobotGeometry<Real> reference_geometry = geometry.template cast<Real>();
      const auto pose_of = [&](const JointVector<Real>& b) { return product_of_segment_poses(b, reference_geometry); };
      SCOPED_TRACE(testing::Message() << n << " segments");
      expect_tip_and_jacobian_of(pose_of, bend, tip, jacobian, total_length(geometry), TestFixture::kTol);
    }
  }
}

TYPED_TEST(Chain, AllStraightBendJacobian) {
  using S = TypeParam;
  // The most common pose of all: every segment straight.
  for (int n = 1; n <= kMaxSegments; ++n) {
    const RobotGeometry<S> geometry = this->random_geometry(n);
    const JointVector<S> bend = JointVector<S>::Zero(2 * n);
    Pose<S> tip;
    Jacobian<S> jacobian;
    tip_jacobian_bend(bend, geometry, tip, jacobian);
    const RobotGeometry<Real> reference_geometry = geometry.template cast<Real>();
    const auto pose_of = [&](const JointVector<Real>& b) { return product_of_segment_poses(b, reference_geometry); };
    const Jacobian<Real> reference = spatial_finite_difference(pose_of, JointVector<Real>::Zero(2 * n));
    EXPECT_LE(relative_jacobian_error(jacobian, reference, total_length(geometry)), TestFixture::kTol);
  }
}

TYPED_TEST(Chain, JointJacobianIsBendJacobianThroughChainRule) {
  using S = TypeParam;
  // Column pairs are related by d(b_i)/d(alpha_i, theta_i); at theta_i = 0
  // the alpha column must vanish exactly.
  for (int n = 1; n <= kMaxSegments; ++n) {
    const RobotGeometry<S> geometry = this->random_geometry(n);
    const JointVector<S> joints = this->random_joints(geometry, S(0), 0.3L);
    Pose<S> tip;
    Jacobian<S> by_joints;
    Jacobian<S> by_bend;
    ASSERT_EQ(tip_jacobian(joints, geometry, tip, by_joints), Status::ok);
    tip_jacobian_bend(bend_from_joints(joints), geometry, tip, by_bend);
    Jacobian<S> chained(6, 2 * n);
    for (int i = 0; i < n; ++i) {
      const S alpha = joints[2 * i];
      const S theta = joints[2 * i + 1];
      Eigen::Matrix<S, 2, 2> d_bend;
      d_bend << -theta * std::sin(alpha), std::cos(alpha), theta * std::cos(alpha), std::sin(alpha);
      chained.template middleCols<2>(2 * i) = by_bend.template middleCols<2>(2 * i) * d_bend;
      if (theta == S(0)) {
        EXPECT_TRUE(by_joints.col(2 * i).isZero(0)) << "segment " << i;
      }
    }
    EXPECT_LE(relative_jacobian_error(by_joints, chained.template cast<Real>(), total_length(geometry)), TestFixture::kTol);
  }
}

TYPED_TEST(Chain, CablesAndJointsRoundTrip) {
  using S = TypeParam;
  for (int n = 1; n <= kMaxSegments; ++n) {
    const RobotGeometry<S> geometry = this->random_geometry(n);
    const JointVector<S> joints = this->random_joints(geometry, S(0), 0.2L);
    CableVector<S> cables;
    ASSERT_EQ(cables_from_joints(joints, geometry, cables), Status::ok);
    ASSERT_EQ(cables.size(), 4 * n);
    JointVector<S> back;
    ASSERT_EQ(joints_from_cables(cables, geometry, back), Status::ok);
    ASSERT_EQ(back.size(), 2 * n);
    // Cable rounding comes back amplified by L / r <= 40; compare bends.
    EXPECT_LE((bend_from_joints(back) - bend_from_joints(joints)).cwiseAbs().maxCoeff(), S(40) * S(TestFixture::kTol));
  }
}

TYPED_TEST(Chain, CompensationUndoesTheErrorTwist) {
  using S = TypeParam;
  for (int n = 1; n <= kMaxSegments; ++n) {
    for (int trial = 0; trial < 20; ++trial) {
      const RobotGeometry<S> geometry = this->random_geometry(n);
      Pose<S> nominal;
      ASSERT_EQ(forward_kinematics(this->random_joints(geometry), geometry, nominal), Status::ok);
      // A measured pose off by a few mm and degrees, as in the paper, and
      // every tenth one off by a large rotation (up to 3 rad).
      Twist<S> offset;
      const Real max_angle = trial % 10 == 0 ? 3.0L : 0.1L;
      const Vec3<Real> axis = Vec3<Real>(this->uniform(-1, 1), this->uniform(-1, 1), this->uniform(-1, 1)).normalized();
      offset.template head<3>() = Vec3<Real>(this->uniform(-5, 5), this->uniform(-5, 5), this->uniform(-5, 5)).template cast<S>();
      offset.template tail<3>() = (this->uniform(0, max_angle) * axis).template cast<S>();
      const Pose<S> measured = exp<S>(offset) * nominal;

      const Twist<S> error = tip_error_twist(measured, nominal);
      const Pose<S> compensated = compensate(error, nominal);
      const Real length = std::max(total_length(geometry), Real(measured.position_mm.norm()));
      EXPECT_LE(relative_distance(compensated, measured.template cast<Real>(), length), TestFixture::kTol);
      // The error twist is the applied one: log(exp(offset)) with |omega| < pi.
      EXPECT_LE((error - offset).template cast<Real>().norm(), TestFixture::kTol * length);

      const PoseError<S> none = pose_error(nominal, nominal);
      EXPECT_EQ(none.position_mm, S(0));
      EXPECT_LE(none.orientation_rad, 8 * std::numeric_limits<S>::epsilon());
      EXPECT_LE(tip_error_twist(nominal, nominal).norm(), S(TestFixture::kTol) * S(length));
    }
  }
}

TYPED_TEST(Chain, PoseErrorMeasuresDistanceAndAngle) {
  using S = TypeParam;
  Pose<S> model;
  model.rotation = Eigen::AngleAxis<S>(S(0.4), Vec3<S>(1, 2, 2).normalized()).toRotationMatrix();
  model.position_mm = Vec3<S>(10, -20, 300);
  Pose<S> measured;
  measured.rotation = Eigen::AngleAxis<S>(S(0.03), Vec3<S>(0, 0.6, 0.8)).toRotationMatrix() * model.rotation;
  measured.position_mm = model.position_mm + Vec3<S>(3, 0, 4);
  const PoseError<S> error = pose_error(measured, model);
  EXPECT_NEAR(error.position_mm, S(5), S(TestFixture::kTol) * S(300));
  EXPECT_NEAR(error.orientation_rad, S(0.03), S(TestFixture::kTol));
}

}  // namespace
}  // namespace cdcr::model
