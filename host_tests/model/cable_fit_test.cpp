// The fit of all four cables of a segment (cable_fit.hpp). The reference is
// a nonlinear least-squares fit of eq. (2) as the paper prints it,
//   l_j = 2 (L'/theta) sin(theta/2) - 2 r cos(alpha + (j - 1) pi/2) sin(theta/2),
// over (alpha, theta, L') by Eigen's Levenberg-Marquardt with numerical
// derivatives: nothing of the closed form under test.

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include <unsupported/Eigen/NonLinearOptimization>
#include <unsupported/Eigen/NumericalDiff>

#include "cdcr/model/cable_fit.hpp"
#include "cdcr/model/chain.hpp"

namespace cdcr::model {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Eq. (2) with the backbone length free; p = (alpha, theta, L').
Eigen::Vector4d paper_cables(const Eigen::Vector3d& p, double r) {
  const double half = std::sin(p[1] / 2.0);
  Eigen::Vector4d l;
  for (int j = 0; j < 4; ++j) {
    l[j] = 2.0 * (p[2] / p[1]) * half - 2.0 * r * std::cos(p[0] + j * kPi / 2.0) * half;
  }
  return l;
}

struct PaperResiduals {
  using Scalar = double;
  using InputType = Eigen::VectorXd;
  using ValueType = Eigen::VectorXd;
  using JacobianType = Eigen::MatrixXd;
  enum { InputsAtCompileTime = Eigen::Dynamic, ValuesAtCompileTime = Eigen::Dynamic };
  Eigen::Vector4d measured;
  double r;
  int inputs() const { return 3; }
  int values() const { return 4; }
  int operator()(const Eigen::VectorXd& p, Eigen::VectorXd& f) const {
    f = paper_cables(p, r) - measured;
    return 0;
  }
};

// (alpha, theta, L') minimising the squared residuals, from a start near
// the answer (the problem has one minimum for theta in (0, pi)).
Eigen::Vector3d reference_fit(const Eigen::Vector4d& measured, double r, const Eigen::Vector3d& start) {
  PaperResiduals residuals{{}, {}};
  residuals.measured = measured;
  residuals.r = r;
  Eigen::NumericalDiff<PaperResiduals, Eigen::Central> diff(residuals);
  Eigen::LevenbergMarquardt<Eigen::NumericalDiff<PaperResiduals, Eigen::Central>> lm(diff);
  lm.parameters.xtol = 1e-14;
  lm.parameters.ftol = 1e-14;
  lm.parameters.maxfev = 10000;
  Eigen::VectorXd p = start;
  lm.minimize(p);
  // (alpha + pi, -theta) is the same bend: report the one with theta >= 0.
  if (p[1] < 0.0) {
    p[0] += kPi;
    p[1] = -p[1];
  }
  return p;
}

const SegmentGeometry<double> kSegment{64.0, 8.0, 1.5707963267948966};

TEST(CableFitTest, ConsistentCablesFitAsTodayWithNoResidual) {
  for (const SegmentGeometry<double>& g :
       {kSegment, SegmentGeometry<double>{120.0, 67.0, 1.5707963267948966}, SegmentGeometry<double>{200.0, 8.0, 0.4}}) {
    for (double theta = 0.0; theta <= g.theta_max_rad; theta += g.theta_max_rad / 7.0) {
      for (double alpha = -kPi; alpha < kPi; alpha += 0.37) {
        Vec4<double> cables;
        ASSERT_EQ(cables_from_joints(SegmentJoints<double>{alpha, theta}, g, cables), Status::ok);
        SegmentJoints<double> today;
        ASSERT_EQ(joints_from_cables(cables, g, today), Status::ok);
        SegmentCableFit<double> fit;
        ASSERT_EQ(fit_cables(cables, g, fit), Status::ok);
        // The same operations: the same bits.
        EXPECT_EQ(fit.joints.alpha_rad, today.alpha_rad);
        // joints_from_cables reads a segment at its limit as the limit.
        if (today.theta_rad < g.theta_max_rad) {
          EXPECT_EQ(fit.joints.theta_rad, today.theta_rad);
        }
        EXPECT_NEAR(fit.joints.theta_rad, today.theta_rad, 1e-14);
        EXPECT_NEAR(fit.common_mode_mm, 0.0, 1e-12 * g.backbone_length_mm);
        EXPECT_NEAR(fit.pair_imbalance_mm, 0.0, 1e-12 * g.backbone_length_mm);
        EXPECT_FALSE(far_from_consistent(fit));
      }
    }
  }
}

TEST(CableFitTest, InconsistentCablesFitAsThePapersEquationWithTheLengthFree) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> alpha(-3.0, 3.0), theta(0.05, 2.6), length(-6.0, 6.0), noise(-3.0, 3.0);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Vector3d truth(alpha(rng), theta(rng), kSegment.backbone_length_mm + length(rng));
    Eigen::Vector4d measured = paper_cables(truth, kSegment.anchor_radius_mm);
    for (int j = 0; j < 4; ++j) measured[j] += noise(rng);
    SegmentCableFit<double> fit;
    ASSERT_EQ(fit_cables(Vec4<double>(measured), kSegment, fit), Status::ok);
    if (fit.beyond_reach) continue;
    const Eigen::Vector3d p = reference_fit(measured, kSegment.anchor_radius_mm, truth);
    const double reference_alpha = std::remainder(p[0], 2.0 * kPi);
    EXPECT_NEAR(std::remainder(fit.joints.alpha_rad - reference_alpha, 2.0 * kPi), 0.0, 1e-7) << trial;
    EXPECT_NEAR(fit.joints.theta_rad, p[1], 1e-7) << trial;
    // The common mode is what the free length adds to the cables' mean.
    const double s = std::sin(p[1] / 2.0) / (p[1] / 2.0);
    EXPECT_NEAR(fit.common_mode_mm, (p[2] - kSegment.backbone_length_mm) * s, 1e-6) << trial;
    // What the fit leaves is the pairs' imbalance, +-1/2 per cable.
    const Eigen::Vector4d left = measured - paper_cables(p, kSegment.anchor_radius_mm);
    const Eigen::Vector4d expected = fit.pair_imbalance_mm / 2.0 * Eigen::Vector4d(1, -1, 1, -1);
    EXPECT_LT((left - expected).cwiseAbs().maxCoeff(), 1e-6) << trial;
  }
}

TEST(CableFitTest, CablesFromAFitReadBackAsThatFit) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> alpha(-3.1, 3.1), theta(0.0, 3.0), residual(-5.0, 5.0);
  for (int trial = 0; trial < 500; ++trial) {
    SegmentCableFit<double> truth;
    truth.joints = SegmentJoints<double>{alpha(rng), theta(rng)};
    truth.common_mode_mm = residual(rng);
    truth.pair_imbalance_mm = residual(rng);
    SegmentCableFit<double> fit;
    ASSERT_EQ(fit_cables(cables_from_fit(truth, kSegment), kSegment, fit), Status::ok);
    EXPECT_NEAR(std::remainder(fit.joints.alpha_rad - truth.joints.alpha_rad, 2.0 * kPi), 0.0, 1e-9);
    EXPECT_NEAR(fit.joints.theta_rad, truth.joints.theta_rad, 1e-9);
    EXPECT_NEAR(fit.common_mode_mm, truth.common_mode_mm, 1e-9);
    EXPECT_NEAR(fit.pair_imbalance_mm, truth.pair_imbalance_mm, 1e-9);
    EXPECT_EQ(far_from_consistent(fit), std::abs(truth.common_mode_mm) > kFarFromConsistentMm ||
                                            std::abs(truth.pair_imbalance_mm) > kFarFromConsistentMm);
  }
}

TEST(CableFitTest, RefusesOnlyImpossibleLengths) {
  SegmentCableFit<double> fit;
  fit.common_mode_mm = 123.0;
  EXPECT_EQ(fit_cables(Vec4<double>(64.0, 64.0, std::nan(""), 64.0), kSegment, fit), Status::non_finite_input);
  EXPECT_EQ(fit_cables(Vec4<double>(64.0, 0.0, 64.0, 64.0), kSegment, fit), Status::cable_length_not_positive);
  EXPECT_EQ(fit.common_mode_mm, 123.0);  // left as it was
  // Differences beyond the anchors' reach (4 r = 32 mm): a bend of pi in
  // their direction, far from consistent.
  ASSERT_EQ(fit_cables(Vec4<double>(40.0, 64.0, 80.0, 64.0), kSegment, fit), Status::ok);
  EXPECT_TRUE(fit.beyond_reach);
  EXPECT_TRUE(far_from_consistent(fit));
  EXPECT_DOUBLE_EQ(fit.joints.theta_rad, kPi);
  EXPECT_DOUBLE_EQ(fit.joints.alpha_rad, 0.0);
  SegmentJoints<double> today;
  EXPECT_EQ(joints_from_cables(Vec4<double>(40.0, 64.0, 80.0, 64.0), kSegment, today),
            Status::cable_difference_out_of_range);
}

TEST(CableFitTest, MeasuredCablesReadAsTheRuntimeWithinTheLimitAndByTheFitBeyond) {
  RobotGeometry<double> g;
  g.segment_count = 2;
  g.segments[0] = kSegment;
  g.segments[1] = SegmentGeometry<double>{50.0, 6.0, 1.2};
  CableVector<double> cables(8);
  Vec4<double> first, second;
  ASSERT_EQ(cables_from_joints(SegmentJoints<double>{0.4, kSegment.theta_max_rad}, kSegment, first), Status::ok);
  ASSERT_EQ(cables_from_joints(SegmentJoints<double>{-1.0, 0.5}, g.segments[1], second), Status::ok);
  cables << first + Vec4<double>(0.3, -0.3, 0.3, -0.3), second + Vec4<double>::Constant(-0.8);
  JointVector<double> joints, today;
  CableResiduals<double> residuals;
  bool beyond = true;
  int far = -1;
  ASSERT_EQ(fit_measured_cables(cables, g, joints, residuals, 0.0, &beyond, &far), Status::ok);
  ASSERT_EQ(joints_from_cables(cables, g, today), Status::ok);
  EXPECT_FALSE(beyond);
  EXPECT_EQ(far, 2);  // 0.6 mm of imbalance, 0.8 mm of common mode
  EXPECT_EQ(joints, today);
  EXPECT_NEAR(residuals[1], 0.6, 1e-12);
  EXPECT_NEAR(residuals[2], -0.8, 1e-12);
  EXPECT_NEAR(residuals[0], 0.0, 1e-12);
  EXPECT_NEAR(residuals[3], 0.0, 1e-12);
  // Bent past theta_max: the runtime's map refuses, the fit reads it.
  ASSERT_EQ(cables_from_joints(SegmentJoints<double>{0.4, 1.5}, g.segments[0], first), Status::ok);
  g.segments[0].theta_max_rad = 1.0;
  cables.segment<4>(0) = first;
  ASSERT_EQ(joints_from_cables(cables, g, today), Status::theta_beyond_limit);
  ASSERT_EQ(fit_measured_cables(cables, g, joints, residuals, 0.0, &beyond, &far), Status::ok);
  EXPECT_TRUE(beyond);
  EXPECT_NEAR(joints[1], 1.5, 1e-12);
  EXPECT_NEAR(residuals[0], 0.0, 1e-12);
}

}  // namespace
}  // namespace cdcr::model
