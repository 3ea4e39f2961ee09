// A segment's cable layout (geometry.hpp's CableLayout) and the maps that
// read it (segment.hpp, cable_fit.hpp, chain.hpp). The references do not
// share the layout's code: eqs. (3)-(5) and eq. (2) written out for the
// paper's four cables, eq. (2) with each anchor's angle for three cables,
// and Eigen's Householder QR on the least-squares problem for measured
// angles.

#include <cmath>
#include <random>

#include <Eigen/QR>
#include <gtest/gtest.h>

#include "cdcr/model/cable_fit.hpp"
#include "cdcr/model/chain.hpp"

namespace cdcr::model {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;

// Eq. (2) with cable j anchored at angle psi_j:
//   l_j = 2 sin(theta/2) (L/theta - r cos(alpha - psi_j)),
// the paper's form for psi_j = -(j - 1) 90 degrees.
double eq2_cable(double alpha, double theta, double psi, double length, double radius) {
  const double half_sine = std::sin(theta / 2.0);
  const double arc = theta > 0.0 ? 2.0 * half_sine * length / theta : length;
  return arc - 2.0 * half_sine * radius * std::cos(alpha - psi);
}

template <typename S>
void expect_papers_values_bit_for_bit(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> length(60.0, 140.0);
  const SegmentGeometry<S> g{S(120), S(67), S(3.1)};
  for (int k = 0; k < 2000; ++k) {
    Vec4<S> l;
    for (int j = 0; j < 4; ++j) l[j] = S(length(rng));
    const CableDifferences<S> d = cable_differences(l, g);
    ASSERT_EQ(d.status, Status::ok);
    EXPECT_EQ(d.d31, l[2] - l[0]);
    EXPECT_EQ(d.d24, l[1] - l[3]);
    EXPECT_EQ(d.mean, (l[0] + l[1] + l[2] + l[3]) / S(4));
    EXPECT_EQ(pair_imbalance(g.cables, l), ((l[0] + l[2]) - (l[1] + l[3])) / S(2));

    const SegmentJoints<S> q{S(length(rng) / 20.0 - 5.0), S(length(rng) / 140.0)};
    SegmentCables<S> cables;
    ASSERT_EQ(cables_from_joints(q, g, cables), Status::ok);
    const Vec2<S> b = bend_from_joints(q);
    const S s = series::sinc(q.theta_rad / S(2));
    const S mean = g.backbone_length_mm * s;
    const S r = g.anchor_radius_mm * s;
    EXPECT_EQ(cables[0], mean - r * b.x());
    EXPECT_EQ(cables[1], mean + r * b.y());
    EXPECT_EQ(cables[2], mean + r * b.x());
    EXPECT_EQ(cables[3], mean - r * b.y());
  }
}

// The default layout gives what eqs. (3)-(5) and eq. (2) gave before there
// were layouts, to the last bit, in both scalar types.
TEST(CableLayout, ThePapersLayoutGivesEqs3To5BitForBit) {
  expect_papers_values_bit_for_bit<double>(1);
  expect_papers_values_bit_for_bit<float>(2);
  EXPECT_EQ(CableLayout<double>::evenly_spaced(4), CableLayout<double>{});
  EXPECT_EQ(CableLayout<double>{}.validate(), Status::ok);
  EXPECT_NEAR(CableLayout<double>{}.spread(), 0.5, 1e-15);

  // The same anchors by angle: the weights derived by least squares are the
  // exact ones to rounding.
  const double psi[4] = {0.0, -90 * kDeg, -180 * kDeg, -270 * kDeg};
  const CableLayout<double> derived = CableLayout<double>::at_angles(4, psi);
  const CableLayout<double> exact;
  ASSERT_EQ(derived.validate(), Status::ok);
  for (int j = 0; j < 4; ++j) {
    EXPECT_NEAR(derived.mean_weights[j], exact.mean_weights[j], 1e-15) << j;
    EXPECT_NEAR(derived.chord_x_weights[j], exact.chord_x_weights[j], 1e-15) << j;
    EXPECT_NEAR(derived.chord_y_weights[j], exact.chord_y_weights[j], 1e-15) << j;
    EXPECT_NEAR(derived.imbalance_weights[j], exact.imbalance_weights[j], 1e-15) << j;
  }
}

// Three cables at 120 degrees: eq. (2) per anchor, read back by the fit.
TEST(CableLayout, ThreeCablesAt120DegreesReadTheBendTheyMake) {
  SegmentGeometry<double> g{64.0, 8.0, 1.5707963267948966};
  g.cables = CableLayout<double>::evenly_spaced(3);
  ASSERT_EQ(g.cables.validate(), Status::ok);
  EXPECT_NEAR(g.cables.spread(), 0.5, 1e-15);
  const double psi[3] = {0.0, -120 * kDeg, -240 * kDeg};
  for (double theta = 0.0; theta <= g.theta_max_rad; theta += g.theta_max_rad / 9.0) {
    for (double alpha = -kPi + 0.05; alpha < kPi; alpha += 0.31) {
      SegmentCables<double> cables;
      ASSERT_EQ(cables_from_joints(SegmentJoints<double>{alpha, theta}, g, cables), Status::ok);
      ASSERT_EQ(cables.size(), 3);
      for (int j = 0; j < 3; ++j) {
        EXPECT_NEAR(cables[j], eq2_cable(alpha, theta, psi[j], g.backbone_length_mm, g.anchor_radius_mm), 1e-12);
      }
      SegmentJoints<double> q;
      ASSERT_EQ(joints_from_cables(cables, g, q), Status::ok);
      EXPECT_NEAR(q.theta_rad, theta, 1e-9);
      if (theta > 1e-6) EXPECT_NEAR(std::remainder(q.alpha_rad - alpha, 2 * kPi), 0.0, 1e-9);
      SegmentCableFit<double> fit;
      ASSERT_EQ(fit_cables(cables, g, fit), Status::ok);
      EXPECT_NEAR(fit.common_mode_mm, 0.0, 1e-12);
      EXPECT_EQ(fit.pair_imbalance_mm, 0.0);
    }
  }
  // All three cables 0.5 mm slack: a common mode of 0.5 mm and the same bend.
  SegmentCables<double> cables;
  ASSERT_EQ(cables_from_joints(SegmentJoints<double>{0.7, 0.9}, g, cables), Status::ok);
  SegmentCableFit<double> fit;
  ASSERT_EQ(fit_cables(SegmentCables<double>(cables.array() + 0.5), g, fit), Status::ok);
  EXPECT_NEAR(fit.common_mode_mm, 0.5, 1e-12);
  EXPECT_NEAR(fit.joints.theta_rad, 0.9, 1e-12);
  // Four lengths for a three-cable segment are not its cables.
  SegmentJoints<double> q;
  EXPECT_EQ(joints_from_cables(Vec4<double>::Constant(64.0), g, q), Status::invalid_segment_count);
  Vec4<double> four;
  EXPECT_EQ(cables_from_joints(SegmentJoints<double>{0.0, 0.1}, g, four), Status::invalid_segment_count);
}

// Four anchors at measured angles, off the paper's by a few degrees, and
// cables that eq. (2) does not explain: the fit is the least-squares one
// (Householder QR on l_j = m - (D / 2) . e_j), and what it leaves is the
// imbalance along n.
TEST(CableLayout, MeasuredAnglesFitByLeastSquares) {
  const double psi[4] = {3 * kDeg, -86 * kDeg, -183 * kDeg, -268 * kDeg};
  SegmentGeometry<double> g{120.0, 67.0, 1.5707963267948966};
  g.cables = CableLayout<double>::at_angles(4, psi);
  ASSERT_EQ(g.cables.validate(), Status::ok);
  Eigen::Matrix<double, 4, 3> a;
  for (int j = 0; j < 4; ++j) a.row(j) << 1.0, -std::cos(psi[j]) / 2.0, -std::sin(psi[j]) / 2.0;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> length(100.0, 140.0);
  for (int k = 0; k < 200; ++k) {
    Vec4<double> l;
    for (int j = 0; j < 4; ++j) l[j] = length(rng);
    const Eigen::Vector3d solution = a.householderQr().solve(l);
    const CableDifferences<double> d = cable_differences(l, g);
    ASSERT_EQ(d.status, Status::ok);
    EXPECT_NEAR(d.mean, solution[0], 1e-9);
    EXPECT_NEAR(d.d31, solution[1], 1e-9);
    EXPECT_NEAR(d.d24, solution[2], 1e-9);
    const Vec4<double> residual = l - a * solution;
    EXPECT_NEAR(std::abs(pair_imbalance(g.cables, l)), residual.norm(), 1e-9);

    // The fit and eq. (2) with the fit's residuals are each other's inverse.
    SegmentCableFit<double> fit;
    ASSERT_EQ(fit_cables(l, g, fit), Status::ok);
    if (fit.beyond_reach) continue;
    const SegmentCables<double> again = cables_from_fit(fit, g);
    ASSERT_EQ(again.size(), 4);
    EXPECT_LT((again - l).cwiseAbs().maxCoeff(), 1e-9);
  }
  // n is a unit vector orthogonal to A's columns.
  Vec4<double> n;
  for (int j = 0; j < 4; ++j) n[j] = g.cables.imbalance_weights[j];
  EXPECT_NEAR(n.norm(), 1.0, 1e-12);
  EXPECT_LT((a.transpose() * n).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_GT(n[0], 0.0);
}

TEST(CableLayout, LayoutsThatCannotReadABendAreRefused) {
  const double on_a_line[3] = {0.0, kPi, 0.0};
  EXPECT_EQ(CableLayout<double>::at_angles(3, on_a_line).validate(), Status::invalid_geometry);
  const double close[3] = {0.0, 5 * kDeg, 10 * kDeg};
  EXPECT_EQ(CableLayout<double>::at_angles(3, close).validate(), Status::invalid_geometry);
  const double psi[4] = {0.0, -kPi / 2, -kPi, kPi / 2};
  EXPECT_EQ(CableLayout<double>::at_angles(2, psi).validate(), Status::invalid_geometry);
  EXPECT_EQ(CableLayout<double>::at_angles(5, psi).validate(), Status::invalid_geometry);
  CableLayout<double> scaled;
  scaled.anchor_x[0] = 2.0;
  EXPECT_EQ(scaled.validate(), Status::invalid_geometry);
  CableLayout<double> not_finite;
  not_finite.chord_x_weights[2] = std::nan("");
  EXPECT_EQ(not_finite.validate(), Status::non_finite_input);
  SegmentGeometry<double> g{120.0, 67.0, 1.5};
  g.cables.count = 5;
  EXPECT_EQ(g.validate(), Status::invalid_geometry);
}

// A robot of a three-cable segment and a four-cable one: its cables are
// stacked segment by segment, 3 then 4.
TEST(CableLayout, ARobotStacksEachSegmentsOwnCables) {
  RobotGeometry<double> g = RobotGeometry<double>::uniform(2, 120.0, 67.0);
  g.segments[0].cables = CableLayout<double>::evenly_spaced(3);
  EXPECT_EQ(g.cable_count(), 7);
  EXPECT_EQ(g.first_cable(1), 3);
  EXPECT_FALSE(g.paper_cables());
  EXPECT_TRUE(RobotGeometry<double>::prototype().paper_cables());
  JointVector<double> q(4);
  q << 0.4, 0.6, -2.0, 0.3;
  CableVector<double> cables;
  ASSERT_EQ(cables_from_joints(q, g, cables), Status::ok);
  ASSERT_EQ(cables.size(), 7);
  SegmentCables<double> first, second;
  ASSERT_EQ(cables_from_joints(SegmentJoints<double>{0.4, 0.6}, g.segments[0], first), Status::ok);
  ASSERT_EQ(cables_from_joints(SegmentJoints<double>{-2.0, 0.3}, g.segments[1], second), Status::ok);
  EXPECT_EQ(cables.head(3), first);
  EXPECT_EQ(cables.tail(4), second);
  JointVector<double> back;
  ASSERT_EQ(joints_from_cables(cables, g, back), Status::ok);
  EXPECT_LT((back - q).cwiseAbs().maxCoeff(), 1e-9);
  CableResiduals<double> residuals;
  ASSERT_EQ(fit_cables(cables, g, back, residuals), Status::ok);
  EXPECT_LT(residuals.cwiseAbs().maxCoeff(), 1e-9);
  CableVector<double> eight(8);
  eight.setConstant(120.0);
  EXPECT_EQ(joints_from_cables(eight, g, back), Status::invalid_segment_count);
  // The geometry in float keeps its layouts.
  EXPECT_EQ(g.cast<float>().segments[0].cables, g.segments[0].cables.cast<float>());
  EXPECT_EQ(g.cast<float>().cable_count(), 7);
}

}  // namespace
}  // namespace cdcr::model
