// The non-constant-curvature segment: with c = 0 it must be the closed-form
// arc of the model, and with c != 0 it must agree with an independent
// construction (a chain of many short constant-curvature pieces) and with the
// curvature law it claims.

#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include <cdcr/model/segment.hpp>
#include <cdcr/model/units.hpp>

#include "sim/curved_segment.hpp"

namespace cdcr::sim {
namespace {

using Vec2 = model::Vec2<double>;
using Pose = model::Pose<double>;

using model::kPi;
constexpr double kLengthMm = 120.0;

std::vector<Vec2> test_bends() {
  std::vector<Vec2> bends = {Vec2(0.0, 0.0), Vec2(1e-9, -2e-9), Vec2(0.05, 0.0), Vec2(0.0, -0.2)};
  for (const double theta : {0.1, 0.7, 1.5707963267948966, 3.0}) {
    for (const double alpha : {-2.5, -0.3, 1.0, kPi}) bends.push_back(theta * Vec2(std::cos(alpha), std::sin(alpha)));
  }
  return bends;
}

void expect_pose_near(const Pose& actual, const Pose& expected, double position_tol_mm, double rotation_tol) {
  EXPECT_LE((actual.position_mm - expected.position_mm).norm(), position_tol_mm)
      << "actual " << actual.position_mm.transpose() << ", expected " << expected.position_mm.transpose();
  EXPECT_LE((actual.rotation - expected.rotation).cwiseAbs().maxCoeff(), rotation_tol);
}

// The constant-curvature arc: the Gauss-Legendre integral of the tangent must
// reproduce the model's closed form, which it does not use.
TEST(CurvedSegment, ZeroGradientIsTheConstantCurvatureArc) {
  for (const Vec2& bend : test_bends()) {
    SCOPED_TRACE(testing::Message() << "bend " << bend.transpose());
    expect_pose_near(curved_segment_pose(bend, kLengthMm, 0.0), model::segment_pose<double>(bend, kLengthMm), 1e-11,
                     1e-14);
  }
}

// Part of an arc is an arc: at fraction f the pose is the arc of bend f b and
// length f L.
TEST(CurvedSegment, ZeroGradientPartialArc) {
  for (const Vec2& bend : test_bends()) {
    for (const double f : {0.0, 0.25, 0.5, 0.9}) {
      SCOPED_TRACE(testing::Message() << "bend " << bend.transpose() << ", fraction " << f);
      expect_pose_near(curved_segment_pose(bend, kLengthMm, 0.0, f),
                       model::segment_pose<double>(Vec2(f * bend), f * kLengthMm), 1e-11, 1e-14);
    }
  }
}

// The same shape built another way: many short pieces, each an arc with the
// curvature at its own midpoint, chained with the model's closed form. The
// midpoint rule converges as 1/N^2, so 4000 pieces agree to about 1e-6 mm.
Pose chain_of_arcs(const Vec2& bend, double length_mm, double gradient, int pieces) {
  const double theta = bend.norm();
  const Vec2 direction = theta > 0.0 ? Vec2(bend / theta) : Vec2(1.0, 0.0);
  const double ds = length_mm / pieces;
  Pose pose;
  for (int k = 0; k < pieces; ++k) {
    const double s = (k + 0.5) * ds;
    const double curvature = theta / length_mm * (1.0 + gradient * (2.0 * s / length_mm - 1.0));
    pose = pose * model::segment_pose<double>(Vec2(curvature * ds * direction), ds);
  }
  return pose;
}

TEST(CurvedSegment, AgreesWithAChainOfShortArcs) {
  for (const double gradient : {-0.6, -0.3, 0.2, 0.9}) {
    for (const Vec2& bend : test_bends()) {
      SCOPED_TRACE(testing::Message() << "bend " << bend.transpose() << ", gradient " << gradient);
      expect_pose_near(curved_segment_pose(bend, kLengthMm, gradient), chain_of_arcs(bend, kLengthMm, gradient, 4000),
                       1e-5, 1e-9);
    }
  }
}

// The end rotation is the arc's (the mean curvature is unchanged), but the
// position is not.
TEST(CurvedSegment, GradientKeepsTheEndRotationAndMovesThePosition) {
  const Vec2 bend(0.4, -0.3);
  const Pose arc = model::segment_pose<double>(bend, kLengthMm);
  const Pose curved = curved_segment_pose(bend, kLengthMm, -0.3);
  EXPECT_LE((curved.rotation - arc.rotation).cwiseAbs().maxCoeff(), 1e-14);
  EXPECT_GT((curved.position_mm - arc.position_mm).norm(), 0.5);
  // More curvature near the base (c < 0) bends the segment earlier, so the
  // end disk lies further out in the bending direction.
  const Vec2 lateral_arc = arc.position_mm.head<2>();
  const Vec2 lateral_curved = curved.position_mm.head<2>();
  EXPECT_GT(lateral_curved.dot(bend.normalized()), lateral_arc.dot(bend.normalized()));
}

// kappa(s) = kappa_mean (1 + c (2 s / L - 1)): the tangent turns by the
// integral of the curvature, and the position advances along the tangent.
TEST(CurvedSegment, FollowsTheCurvatureLaw) {
  const Vec2 bend(0.9, 0.5);
  const double theta = bend.norm();
  const double c = 0.4;
  for (const double f : {0.1, 0.3, 0.6, 0.95}) {
    const double s = f * kLengthMm;
    const double expected_turn = theta / kLengthMm * (s + c * (s * s / kLengthMm - s));
    const Pose pose = curved_segment_pose(bend, kLengthMm, c, f);
    const double turn = std::acos(std::clamp(0.5 * (pose.rotation.trace() - 1.0), -1.0, 1.0));
    EXPECT_NEAR(turn, expected_turn, 1e-12) << "fraction " << f;

    const double h = 1e-4;
    const model::Vec3<double> velocity = (curved_segment_pose(bend, kLengthMm, c, f + h).position_mm -
                                          curved_segment_pose(bend, kLengthMm, c, f - h).position_mm) /
                                         (2.0 * h * kLengthMm);
    EXPECT_LE((velocity - pose.rotation.col(2)).norm(), 1e-7) << "fraction " << f;
  }
}

}  // namespace
}  // namespace cdcr::sim
