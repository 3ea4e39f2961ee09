// Every class of bad input is reported through its Status, never as NaN in
// an output, and a failed call leaves its outputs as they were: a caller on
// the control cycle can keep using the last good value.

#include <cmath>
#include <limits>
#include <ostream>
#include <set>
#include <string>

#include <gtest/gtest.h>

#include "cdcr/model/kinematics.hpp"

namespace cdcr::model {

void PrintTo(Status status, std::ostream* os) { *os << to_string(status); }

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

const SegmentGeometry<double> kSegment{120.0, 10.0, 1.5707963267948966};  // 4r = 40 mm

constexpr Status kAllStatuses[] = {
    Status::ok,
    Status::non_finite_input,
    Status::invalid_geometry,
    Status::cable_length_not_positive,
    Status::cable_difference_out_of_range,
    Status::theta_beyond_limit,
    Status::invalid_segment_count,
    Status::ik_not_converged,
    Status::correction_failed,
};

TEST(StatusText, EveryStatusHasItsOwnText) {
  std::set<std::string> seen;
  for (const Status status : kAllStatuses) {
    const std::string text = to_string(status);
    EXPECT_FALSE(text.empty());
    EXPECT_NE(text, "unknown status");
    EXPECT_TRUE(seen.insert(text).second) << "duplicate: " << text;
  }
  EXPECT_EQ(seen.size(), std::size(kAllStatuses));
  // The enumerators are dense from ok to correction_failed: the list above
  // is all of them.
  EXPECT_EQ(static_cast<int>(Status::correction_failed) + 1, static_cast<int>(std::size(kAllStatuses)));
}

// ---------------------------------------------------------------- geometry

TEST(BadGeometry, NonFiniteSegmentParameters) {
  for (const double bad : {kNaN, kInf, -kInf}) {
    EXPECT_EQ((SegmentGeometry<double>{bad, 10, 1}.validate()), Status::non_finite_input);
    EXPECT_EQ((SegmentGeometry<double>{120, bad, 1}.validate()), Status::non_finite_input);
    EXPECT_EQ((SegmentGeometry<double>{120, 10, bad}.validate()), Status::non_finite_input);
  }
}

TEST(BadGeometry, NonPositiveSegmentParameters) {
  for (const double bad : {0.0, -0.0, -1e-300, -5.0}) {
    EXPECT_EQ((SegmentGeometry<double>{bad, 10, 1}.validate()), Status::invalid_geometry) << bad;
    EXPECT_EQ((SegmentGeometry<double>{120, bad, 1}.validate()), Status::invalid_geometry) << bad;
    EXPECT_EQ((SegmentGeometry<double>{120, 10, bad}.validate()), Status::invalid_geometry) << bad;
  }
  EXPECT_EQ(kSegment.validate(), Status::ok);
}

TEST(BadGeometry, SegmentCountOutsideCapacity) {
  RobotGeometry<double> geometry = RobotGeometry<double>::prototype();
  for (const int count : {0, -1, RobotGeometry<double>::kCapacity + 1, 1000}) {
    geometry.segment_count = count;
    EXPECT_EQ(geometry.validate(), Status::invalid_segment_count) << count;
  }
  geometry.segment_count = RobotGeometry<double>::kCapacity;
  EXPECT_EQ(geometry.validate(), Status::ok);
}

TEST(BadGeometry, OneBadSegmentInvalidatesTheRobot) {
  RobotGeometry<double> geometry = RobotGeometry<double>::prototype();
  geometry.segments[2].anchor_radius_mm = 0;
  EXPECT_EQ(geometry.validate(), Status::invalid_geometry);
  geometry.segments[2].anchor_radius_mm = kNaN;
  EXPECT_EQ(geometry.validate(), Status::non_finite_input);
  // Slots beyond segment_count are not part of the robot.
  geometry = RobotGeometry<double>::prototype();
  geometry.segments[geometry.segment_count].backbone_length_mm = kNaN;
  EXPECT_EQ(geometry.validate(), Status::ok);
}

// ------------------------------------------------------- segment: cables

// Calls joints_from_cables on a sentinel output and checks that it is left
// alone on failure.
Status segment_joints_status(const Vec4<double>& cables, const SegmentGeometry<double>& geometry = kSegment) {
  SegmentJoints<double> joints{7.0, 9.0};
  const Status status = joints_from_cables(cables, geometry, joints);
  if (status != Status::ok) {
    EXPECT_EQ(joints.alpha_rad, 7.0);
    EXPECT_EQ(joints.theta_rad, 9.0);
  } else {
    EXPECT_TRUE(std::isfinite(joints.alpha_rad) && std::isfinite(joints.theta_rad));
  }
  return status;
}

TEST(BadSegmentCables, NonFinite) {
  for (int k = 0; k < 4; ++k) {
    for (const double bad : {kNaN, kInf, -kInf}) {
      Vec4<double> cables = Vec4<double>::Constant(120);
      cables[k] = bad;
      EXPECT_EQ(segment_joints_status(cables), Status::non_finite_input) << "cable " << k << " = " << bad;
    }
  }
}

TEST(BadSegmentCables, NotPositive) {
  for (int k = 0; k < 4; ++k) {
    for (const double bad : {0.0, -0.0, -1.0}) {
      Vec4<double> cables = Vec4<double>::Constant(120);
      cables[k] = bad;
      EXPECT_EQ(segment_joints_status(cables), Status::cable_length_not_positive) << "cable " << k << " = " << bad;
    }
  }
}

TEST(BadSegmentCables, DifferenceBeyondFourRadii) {
  // 4r = 40 mm. Each difference alone beyond it, in both signs.
  EXPECT_EQ(segment_joints_status({100, 120, 141, 120}), Status::cable_difference_out_of_range);
  EXPECT_EQ(segment_joints_status({141, 120, 100, 120}), Status::cable_difference_out_of_range);
  EXPECT_EQ(segment_joints_status({120, 100, 120, 141}), Status::cable_difference_out_of_range);
  EXPECT_EQ(segment_joints_status({120, 141, 120, 100}), Status::cable_difference_out_of_range);
  // Each difference below 4r, their hypot (42.4 mm) beyond it.
  EXPECT_EQ(segment_joints_status({100, 130, 130, 100}), Status::cable_difference_out_of_range);
  // Exactly 4r is theta = pi: in range of asin, beyond a pi/2 limit.
  EXPECT_EQ(segment_joints_status({100, 120, 140, 120}), Status::theta_beyond_limit);
  EXPECT_EQ(segment_joints_status({100, 120, 140, 120}, SegmentGeometry<double>{120, 10, 3.15}), Status::ok);
}

TEST(BadSegmentCables, ThetaBeyondLimit) {
  const SegmentGeometry<double> stiff{120, 10, 0.1};
  // chord 10 mm: theta = 2 asin(10 / 40) = 0.505 rad > 0.1.
  EXPECT_EQ(segment_joints_status({115, 120, 125, 120}, stiff), Status::theta_beyond_limit);
  EXPECT_EQ(segment_joints_status({120, 120, 120, 120}, stiff), Status::ok);
}

TEST(BadSegmentCables, LimitWithinMeasurementResolution) {
  // A segment at theta_max = pi/2, its cables in 0.01 mm steps rounded away
  // from the straight pose: beyond the limit by the rounding, which is the
  // limit itself for a drive that reports in such steps.
  const SegmentGeometry<double> g{120, 10, 1.5707963267948966};
  const double step = 0.01;
  const double alpha = 0.4;
  Vec4<double> cables;
  ASSERT_EQ(cables_from_joints(SegmentJoints<double>{alpha, g.theta_max_rad}, g, cables), Status::ok);
  // l3 - l1 = 4r sin(theta/2) cos(alpha) and l2 - l4 likewise with sin:
  // round l3 and l2 up, l1 and l4 down.
  Vec4<double> measured(std::floor(cables[0] / step) * step, std::ceil(cables[1] / step) * step,
                        std::ceil(cables[2] / step) * step, std::floor(cables[3] / step) * step);
  SegmentJoints<double> joints;
  EXPECT_EQ(joints_from_cables(measured, g, joints), Status::theta_beyond_limit);
  ASSERT_EQ(joints_from_cables(measured, g, joints, step), Status::ok);
  EXPECT_DOUBLE_EQ(joints.theta_rad, g.theta_max_rad);
  EXPECT_NEAR(joints.alpha_rad, alpha, 1e-3);
  // Two steps beyond on both differences is beyond any rounding.
  measured[2] += 2 * step;
  measured[1] += 2 * step;
  EXPECT_EQ(joints_from_cables(measured, g, joints, step), Status::theta_beyond_limit);
}

TEST(BadSegmentCables, BadGeometry) {
  EXPECT_EQ(segment_joints_status(Vec4<double>::Constant(120), SegmentGeometry<double>{120, 0, 1}),
            Status::invalid_geometry);
  EXPECT_EQ(segment_joints_status(Vec4<double>::Constant(120), SegmentGeometry<double>{-120, 10, 1}),
            Status::invalid_geometry);
  EXPECT_EQ(segment_joints_status(Vec4<double>::Constant(120), SegmentGeometry<double>{120, 10, 0}),
            Status::invalid_geometry);
  EXPECT_EQ(segment_joints_status(Vec4<double>::Constant(120), SegmentGeometry<double>{kNaN, 10, 1}),
            Status::non_finite_input);
}

// ------------------------------------------------------- segment: joints

Status segment_cables_status(const SegmentJoints<double>& joints, const SegmentGeometry<double>& geometry = kSegment) {
  const Vec4<double> sentinel(1, 2, 3, 4);
  Vec4<double> cables = sentinel;
  const Status status = cables_from_joints(joints, geometry, cables);
  if (status != Status::ok) {
    EXPECT_EQ(cables, sentinel);
  } else {
    EXPECT_TRUE(cables.allFinite());
  }
  return status;
}

TEST(BadSegmentJoints, NonFinite) {
  for (const double bad : {kNaN, kInf, -kInf}) {
    EXPECT_EQ(segment_cables_status({bad, 0.1}), Status::non_finite_input) << bad;
    EXPECT_EQ(segment_cables_status({0.1, bad}), Status::non_finite_input) << bad;
  }
}

TEST(BadSegmentJoints, ThetaOutsideRange) {
  EXPECT_EQ(segment_cables_status({0.3, -1e-12}), Status::theta_beyond_limit);
  EXPECT_EQ(segment_cables_status({0.3, -0.5}), Status::theta_beyond_limit);
  EXPECT_EQ(segment_cables_status({0.3, 1.58}), Status::theta_beyond_limit);
  EXPECT_EQ(segment_cables_status({0.3, kSegment.theta_max_rad}), Status::ok);
  EXPECT_EQ(segment_cables_status({0.3, 0.0}), Status::ok);
  EXPECT_EQ(check_joints(SegmentJoints<double>{0.3, -0.5}, kSegment), Status::theta_beyond_limit);
}

TEST(BadSegmentJoints, BendThatWouldNeedNegativeCable) {
  // r theta > L: the inner cable would have to be shorter than zero.
  const SegmentGeometry<double> wide{10, 100, 1.5};
  EXPECT_EQ(segment_cables_status({0.0, 1.0}, wide), Status::cable_length_not_positive);
}

TEST(BadSegmentJoints, BadGeometry) {
  EXPECT_EQ(segment_cables_status({0.0, 0.1}, SegmentGeometry<double>{0, 10, 1}), Status::invalid_geometry);
  EXPECT_EQ(segment_cables_status({0.0, 0.1}, SegmentGeometry<double>{120, 10, -1}), Status::invalid_geometry);
  EXPECT_EQ(segment_cables_status({0.0, 0.1}, SegmentGeometry<double>{120, kInf, 1}), Status::non_finite_input);
}

// ------------------------------------------------------------ robot level

class BadRobotInput : public ::testing::Test {
 protected:
  RobotGeometry<double> geometry = RobotGeometry<double>::prototype();
  JointVector<double> good_joints = JointVector<double>::Constant(8, 0.1);
  CableVector<double> good_cables = CableVector<double>::Constant(16, 120);

  // Runs every joint-consuming function and checks that all of them report
  // `expected` and leave their outputs alone.
  void expect_joints_rejected(const JointVector<double>& joints, const RobotGeometry<double>& g, Status expected) {
    EXPECT_EQ(check_joints(joints, g), expected);

    const CableVector<double> cable_sentinel = CableVector<double>::Constant(5, 3.0);
    CableVector<double> cables = cable_sentinel;
    EXPECT_EQ(cables_from_joints(joints, g, cables), expected);
    EXPECT_EQ(cables, cable_sentinel);

    Pose<double> sentinel_pose;
    sentinel_pose.position_mm = Vec3<double>(1, 2, 3);
    sentinel_pose.rotation = 2 * Mat3<double>::Identity();
    Pose<double> tip = sentinel_pose;
    EXPECT_EQ(forward_kinematics(joints, g, tip), expected);
    EXPECT_EQ(tip.matrix(), sentinel_pose.matrix());

    const Jacobian<double> jacobian_sentinel = Jacobian<double>::Constant(6, 3, 4.0);
    Jacobian<double> jacobian = jacobian_sentinel;
    tip = sentinel_pose;
    EXPECT_EQ(tip_jacobian(joints, g, tip, jacobian), expected);
    EXPECT_EQ(tip.matrix(), sentinel_pose.matrix());
    EXPECT_EQ(jacobian, jacobian_sentinel);

    // The same initial guess handed to the solver.
    expect_ik_rejected(fk_target(), g, joints, expected);
  }

  void expect_cables_rejected(const CableVector<double>& cables, const RobotGeometry<double>& g, Status expected) {
    const JointVector<double> sentinel = JointVector<double>::Constant(3, 5.0);
    JointVector<double> joints = sentinel;
    EXPECT_EQ(joints_from_cables(cables, g, joints), expected);
    EXPECT_EQ(joints, sentinel);
  }

  static void expect_no_nan(const IkResult<double>& result) {
    EXPECT_FALSE(std::isnan(result.position_error_mm));
    EXPECT_FALSE(std::isnan(result.orientation_error_rad));
    EXPECT_FALSE(result.joints.hasNaN());
    EXPECT_FALSE(result.cables_mm.hasNaN());
    EXPECT_FALSE(result.converged());
  }

  static void expect_ik_rejected(const Pose<double>& target, const RobotGeometry<double>& g,
                                 const JointVector<double>& initial, Status expected) {
    const IkResult<double> by_pose = solve_ik(target, g, initial);
    EXPECT_EQ(by_pose.status, expected);
    expect_no_nan(by_pose);
    const IkResult<double> by_position = solve_ik_position(target.position_mm, g, initial);
    EXPECT_EQ(by_position.status, expected);
    expect_no_nan(by_position);
  }

  Pose<double> fk_target() const {
    Pose<double> target;
    EXPECT_EQ(forward_kinematics(good_joints, geometry, target), Status::ok);
    return target;
  }
};

TEST_F(BadRobotInput, GoodInputIsAccepted) {
  EXPECT_EQ(check_joints(good_joints, geometry), Status::ok);
  JointVector<double> joints;
  EXPECT_EQ(joints_from_cables(good_cables, geometry, joints), Status::ok);
  EXPECT_TRUE(solve_ik(fk_target(), geometry, good_joints).converged());
}

TEST_F(BadRobotInput, NonFiniteJoints) {
  for (Eigen::Index k = 0; k < good_joints.size(); ++k) {
    for (const double bad : {kNaN, kInf, -kInf}) {
      JointVector<double> joints = good_joints;
      joints[k] = bad;
      expect_joints_rejected(joints, geometry, Status::non_finite_input);
    }
  }
}

TEST_F(BadRobotInput, ThetaOutsideLimits) {
  for (int i = 0; i < geometry.segment_count; ++i) {
    for (const double bad : {-1e-9, -1.0, 1.6, 100.0}) {
      JointVector<double> joints = good_joints;
      joints[2 * i + 1] = bad;
      expect_joints_rejected(joints, geometry, Status::theta_beyond_limit);
    }
  }
}

TEST_F(BadRobotInput, JointCountMismatch) {
  for (const int size : {0, 2, 7, 9, 16}) {
    expect_joints_rejected(JointVector<double>::Constant(size, 0.1), geometry, Status::invalid_segment_count);
  }
}

TEST_F(BadRobotInput, SegmentCountOutsideCapacity) {
  for (const int count : {0, -3, kMaxSegments + 1}) {
    RobotGeometry<double> g = geometry;
    g.segment_count = count;
    expect_joints_rejected(good_joints, g, Status::invalid_segment_count);
    expect_cables_rejected(good_cables, g, Status::invalid_segment_count);
  }
}

TEST_F(BadRobotInput, BadGeometry) {
  struct Case {
    int field;
    double value;
    Status expected;
  };
  const Case cases[] = {
      {0, 0.0, Status::invalid_geometry},  {0, -120.0, Status::invalid_geometry}, {1, 0.0, Status::invalid_geometry},
      {1, -67.0, Status::invalid_geometry}, {2, 0.0, Status::invalid_geometry},   {2, -1.0, Status::invalid_geometry},
      {0, kNaN, Status::non_finite_input},  {1, kInf, Status::non_finite_input},   {2, kNaN, Status::non_finite_input},
  };
  for (const Case& c : cases) {
    RobotGeometry<double> g = geometry;
    SegmentGeometry<double>& s = g.segments[1];
    (c.field == 0 ? s.backbone_length_mm : c.field == 1 ? s.anchor_radius_mm : s.theta_max_rad) = c.value;
    expect_joints_rejected(good_joints, g, c.expected);
    expect_cables_rejected(good_cables, g, c.expected);
  }
}

TEST_F(BadRobotInput, CableCountMismatch) {
  for (const int size : {0, 4, 15, 17, 32}) {
    expect_cables_rejected(CableVector<double>::Constant(size, 120), geometry, Status::invalid_segment_count);
  }
}

TEST_F(BadRobotInput, BadCables) {
  struct Case {
    Eigen::Index index;
    double value;
    Status expected;
  };
  // Segment 3's cables are 8..11; r = 67, so 4r = 268 mm.
  const Case cases[] = {
      {9, kNaN, Status::non_finite_input},         {15, kInf, Status::non_finite_input},
      {0, -kInf, Status::non_finite_input},        {8, 0.0, Status::cable_length_not_positive},
      {12, -3.0, Status::cable_length_not_positive}, {10, 400.0, Status::cable_difference_out_of_range},
      {6, 320.0, Status::theta_beyond_limit},
  };
  for (const Case& c : cases) {
    CableVector<double> cables = good_cables;
    cables[c.index] = c.value;
    expect_cables_rejected(cables, geometry, c.expected);
  }
}

TEST_F(BadRobotInput, NonFiniteTargets) {
  for (const double bad : {kNaN, kInf, -kInf}) {
    for (int k = 0; k < 3; ++k) {
      Pose<double> target = fk_target();
      target.position_mm[k] = bad;
      expect_ik_rejected(target, geometry, good_joints, Status::non_finite_input);
    }
    Pose<double> target = fk_target();
    target.rotation(1, 2) = bad;
    const IkResult<double> result = solve_ik(target, geometry, good_joints);
    EXPECT_EQ(result.status, Status::non_finite_input);
    expect_no_nan(result);
  }
}

TEST_F(BadRobotInput, FloatPathReportsTheSame) {
  const RobotGeometry<float> g = RobotGeometry<float>::prototype();
  JointVector<float> joints = JointVector<float>::Constant(8, 0.1f);
  joints[3] = std::numeric_limits<float>::quiet_NaN();
  Pose<float> tip;
  EXPECT_EQ(forward_kinematics(joints, g, tip), Status::non_finite_input);
  joints[3] = -0.1f;
  EXPECT_EQ(forward_kinematics(joints, g, tip), Status::theta_beyond_limit);
  CableVector<float> cables = CableVector<float>::Constant(16, 120.0f);
  cables[2] = 500.0f;
  JointVector<float> out;
  EXPECT_EQ(joints_from_cables(cables, g, out), Status::cable_difference_out_of_range);
  Vec3<float> target(0, 0, std::numeric_limits<float>::infinity());
  const IkResult<float> result = solve_ik_position(target, g, JointVector<float>(JointVector<float>::Zero(8)));
  EXPECT_EQ(result.status, Status::non_finite_input);
  EXPECT_FALSE(std::isnan(result.position_error_mm));
}

}  // namespace
}  // namespace cdcr::model
