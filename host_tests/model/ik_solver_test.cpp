// The resumable IK solver: a GP evaluation in slices has the bits of a
// whole one, the work a call does never exceeds its budget, and the result
// does not depend on how the work is sliced over calls (cycles).

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "cdcr/model/compensated_kinematics.hpp"
#include "cdcr/model/gp_correction.hpp"
#include "cdcr/model/ik_solver.hpp"
#include "export/image_writer.hpp"

#include "../support/synthetic_trained_model.hpp"

namespace cdcr::model {
namespace {

using Correction = GpCorrection<float, double, kMaxSegments>;
using Solver = IkSolver<float, kMaxSegments, Correction>;

struct Fixture {
  std::vector<std::uint8_t> image;
  ImageView view{};
  RobotGeometry<float> geometry;
  Correction correction;
};

// A model of several blocks and gradient chunks with a ragged end, its
// correction scaled to the size a trained model has (millimetres); the
// solvers are configured on it.
void make(Fixture& f, int training_points, std::initializer_list<Solver*> solvers = {}) {
  test_support::SyntheticModelOptions options;
  options.segments = 4;
  options.training_points = training_points;
  options.position_output_factor = 0.5;
  options.rotation_output_factor = 0.002;
  f.image = exporting::write_image(test_support::synthetic_trained_model(options));
  ImageCapacity capacity;
  capacity.max_training_points = 4096;
  ASSERT_EQ(parse_image(f.image.data(), f.image.size(), f.view, capacity), ImageStatus::ok);
  ASSERT_EQ(geometry_from_image(f.view, f.geometry), Status::ok);
  ASSERT_EQ(f.correction.bind(f.view), Status::ok);
  for (Solver* solver : solvers) solver->configure(f.geometry, f.correction);
}

// The compensated model's tip pose at a bend vector.
Pose<float> compensated_pose(const Fixture& f, const JointVector<float>& bend) {
  return exp(f.correction.predict(bend)) * forward_kinematics_bend(bend, f.geometry);
}

JointVector<float> random_joints(std::mt19937& rng, int segments, double theta_max) {
  std::uniform_real_distribution<double> alpha(-3.1, 3.1), theta(0.0, theta_max);
  JointVector<float> q(2 * segments);
  for (int s = 0; s < segments; ++s) {
    q[2 * s] = float(alpha(rng));
    q[2 * s + 1] = float(theta(rng));
  }
  return q;
}

TEST(IkSolver, SlicedEvaluationHasTheBitsOfAWholeOne) {
  Fixture f;
  make(f, 203);
  std::mt19937 rng(5);
  for (int trial = 0; trial < 10; ++trial) {
    const JointVector<float> bend = bend_from_joints(random_joints(rng, 4, 0.5));
    for (const bool with_gradient : {false, true}) {
      Correction::Evaluation whole, sliced;
      ASSERT_EQ(f.correction.begin_evaluation(bend, whole, with_gradient), Status::ok);
      ASSERT_EQ(f.correction.begin_evaluation(bend, sliced, with_gradient), Status::ok);
      EXPECT_EQ(f.correction.continue_evaluation(whole, 1u << 20),
                203u * (with_gradient ? Correction::kGradientPointUnits : 1u));
      int slices = 0;
      const std::uint32_t budget = with_gradient ? 300 : 20;
      while (!f.correction.evaluation_finished(sliced)) {
        const std::uint32_t spent = f.correction.continue_evaluation(sliced, budget);
        ASSERT_LE(spent, budget);
        ASSERT_GT(spent, 0u);
        ++slices;
      }
      EXPECT_GT(slices, 2);
      Twist<float> a, b;
      Jacobian<float> da, db;
      f.correction.evaluation_result(whole, a, da);
      f.correction.evaluation_result(sliced, b, db);
      for (int k = 0; k < 6; ++k) EXPECT_EQ(a[k], b[k]);
      EXPECT_TRUE(da == db);
      if (!with_gradient) {
        const Twist<float> predicted = f.correction.predict(bend);
        for (int k = 0; k < 6; ++k) EXPECT_EQ(a[k], predicted[k]);
      }
    }
  }
}

// Solves the same targets once without a budget and once in cycles of a
// small budget: identical iterates, so identical results, and no call over
// its budget.
TEST(IkSolver, ResultDoesNotDependOnTheBudgetAndNoCallExceedsIt) {
  Fixture f;
  static Solver whole, sliced;
  make(f, 203, {&whole, &sliced});
  std::mt19937 rng(11);
  const JointVector<float> start = random_joints(rng, 4, 0.1);
  int converged = 0;
  for (int trial = 0; trial < 30; ++trial) {
    const JointVector<float> q = random_joints(rng, 4, 0.3);
    const JointVector<float> b = bend_from_joints(q);
    const Pose<float> target = compensated_pose(f, b);
    const IkTargetKind kind = trial % 3 == 0 ? IkTargetKind::position : IkTargetKind::pose;
    ASSERT_EQ(whole.start(target, kind, start), Status::ok);
    ASSERT_EQ(sliced.start(target, kind, start), Status::ok);
    whole.run_to_end();
    const std::uint32_t budget = 300;
    int calls = 0;
    while (sliced.state() == IkSolveState::running) {
      ASSERT_LE(sliced.run(budget), budget);
      ASSERT_LT(++calls, 100000);
    }
    EXPECT_GT(calls, 1);
    EXPECT_EQ(whole.state(), sliced.state());
    EXPECT_EQ(whole.iterations(), sliced.iterations());
    EXPECT_EQ(whole.corrections(), sliced.corrections());
    EXPECT_TRUE(whole.best_bend() == sliced.best_bend());
    EXPECT_EQ(whole.units_spent(), sliced.units_spent());
    if (whole.state() == IkSolveState::converged) {
      ++converged;
      // Independently: the compensated model at the answer, in double.
      const JointVector<float> answer = sliced.best_joints();
      const Pose<float> tip = compensated_pose(f, bend_from_joints(answer));
      EXPECT_LE((tip.position_mm - target.position_mm).norm(), 5e-3f);
    }
  }
  EXPECT_GE(converged, 27);
}

// A budget smaller than one block or one nominal iteration does nothing,
// and a solve still ends once the budget allows.
TEST(IkSolver, TooSmallABudgetDoesNothing) {
  Fixture f;
  static Solver solver;
  make(f, 64, {&solver});
  std::mt19937 rng(3);
  const JointVector<float> q = random_joints(rng, 4, 0.2);
  const Pose<float> target = forward_kinematics_bend(JointVector<float>(bend_from_joints(q)), f.geometry);
  ASSERT_EQ(solver.start(target, IkTargetKind::pose, random_joints(rng, 4, 0.1)), Status::ok);
  EXPECT_EQ(solver.run(Correction::kBlockPoints * Correction::kGradientPointUnits - 1), 0u);
  EXPECT_EQ(solver.state(), IkSolveState::running);
  EXPECT_EQ(solver.run_to_end(), IkSolveState::converged);
}

// Warm starts along a path reuse the last point's correction and slope: a
// small step needs few evaluations.
TEST(IkSolver, WarmStartsAlongAPathNeedFewEvaluations) {
  Fixture f;
  static Solver solver;
  make(f, 203, {&solver});
  JointVector<float> q(8);
  for (int s = 0; s < 4; ++s) {
    q[2 * s] = 0.5f * float(s);
    q[2 * s + 1] = 0.15f;
  }
  const auto target_at = [&](double t) {
    JointVector<float> p = q;
    for (int s = 0; s < 4; ++s) p[2 * s] += float(0.2 * t);
    const JointVector<float> b = bend_from_joints(p);
    return compensated_pose(f, b);
  };
  ASSERT_EQ(solver.start(target_at(0), IkTargetKind::pose, q), Status::ok);
  ASSERT_EQ(solver.run_to_end(), IkSolveState::converged);
  int evaluations = 0;
  for (int step = 1; step <= 50; ++step) {
    ASSERT_EQ(solver.start_warm(target_at(step * 0.002), IkTargetKind::pose, q), Status::ok);
    solver.run_to_end();
    EXPECT_LE(solver.best_position_error_mm(), 0.01f) << step;
    evaluations += solver.corrections();
  }
  EXPECT_LE(evaluations, 50 * 3);
}

// The robot is redundant (eight joint variables for a pose): among the
// solutions of a target the solver prefers the ones near the preference's
// centre, without giving up the target. The compensated model's own poses at
// random bends of up to 0.15 rad (reachable by construction), each solved
// from the last answer (as a request starts from the setpoints in place):
// with a preference for the straight robot every target converges (checked
// on the compensated model at the answer, not by the solver's word), and the
// answers bend clearly less than the same chain's without it, which wanders
// off along the null space.
TEST(IkSolver, PrefersSolutionsNearThePreferencesCentre) {
  Fixture f;
  make(f, 203);
  const auto median_largest_bend = [&](bool prefer, int& converged) {
    static Solver solver;
    solver.configure(f.geometry, f.correction);
    if (prefer) {
      IkPreference<float, kMaxSegments> preference;
      preference.centre.setZero(8);
      preference.weight.setOnes(8);
      preference.gain = 0.3f;
      solver.set_preference(preference);
    }
    std::mt19937 rng(12);
    JointVector<float> start = JointVector<float>::Zero(8);
    for (int s = 0; s < 4; ++s) start[2 * s + 1] = 0.1f;
    std::vector<float> largest;
    converged = 0;
    for (int t = 0; t < 60; ++t) {
      const JointVector<float> b = bend_from_joints(random_joints(rng, 4, 0.15));
      const Pose<float> target = compensated_pose(f, b);
      EXPECT_EQ(solver.start(target, IkTargetKind::pose, start), Status::ok);
      while (solver.state() == IkSolveState::running) solver.run(500);
      const JointVector<float> answer = solver.best_bend();
      const Pose<float> reached = compensated_pose(f, answer);
      if ((reached.position_mm - target.position_mm).norm() > 0.005f) continue;
      ++converged;
      start = solver.best_joints();
      float theta = 0;
      for (int s = 0; s < 4; ++s) theta = std::max(theta, answer.segment<2>(2 * s).norm());
      largest.push_back(theta);
    }
    std::sort(largest.begin(), largest.end());
    return largest.empty() ? 0.0f : largest[largest.size() / 2];
  };
  int converged_without = 0, converged_with = 0;
  const float without = median_largest_bend(false, converged_without);
  const float with = median_largest_bend(true, converged_with);
  EXPECT_GE(converged_with, 59);
  EXPECT_GE(converged_without, 59);
  // The targets' own bends are at most 0.15 rad on every segment; with the
  // preference the median answer bends 0.128 rad at most, without it 0.165.
  EXPECT_LT(with, 0.85f * without) << "with " << with << " without " << without;
}

// A target started from the last solve's answer (the setpoints it left)
// starts where the correction is known: the solve needs no evaluation at its
// start, and reaches the target as a start from scratch there does; from
// any other joints it is start().
TEST(IkSolver, AStartAtTheLastAnswerReusesItsCorrection) {
  Fixture f;
  static Solver solver;
  make(f, 203, {&solver});
  std::mt19937 rng(31);
  const auto target_of = [&](const JointVector<float>& q) {
    const JointVector<float> b = bend_from_joints(q);
    return compensated_pose(f, b);
  };
  JointVector<float> straight = JointVector<float>::Zero(8);
  for (int s = 0; s < 4; ++s) straight[2 * s + 1] = 0.1f;
  int fewer = 0;
  for (int t = 0; t < 10; ++t) {
    const Pose<float> first = target_of(random_joints(rng, 4, 0.2));
    const JointVector<float> other = random_joints(rng, 4, 0.2);
    const Pose<float> second = target_of(random_joints(rng, 4, 0.2));
    // The same first solve each time: the solver is deterministic.
    const auto solve_first = [&] {
      ASSERT_EQ(solver.start(first, IkTargetKind::pose, straight), Status::ok);
      ASSERT_EQ(solver.run_to_end(), IkSolveState::converged);
    };
    solve_first();
    const JointVector<float> answer = solver.best_joints();
    ASSERT_EQ(solver.start(second, IkTargetKind::pose, answer), Status::ok);
    ASSERT_EQ(solver.run_to_end(), IkSolveState::converged) << t;
    const int from_scratch = solver.corrections();

    solve_first();
    ASSERT_EQ(solver.start_near(second, IkTargetKind::pose, solver.best_joints()), Status::ok);
    ASSERT_EQ(solver.run_to_end(), IkSolveState::converged) << t;
    EXPECT_LE(solver.best_position_error_mm(), 2e-3f);
    fewer += solver.corrections() < from_scratch ? 1 : 0;

    // From other joints it is start().
    ASSERT_EQ(solver.start(second, IkTargetKind::pose, other), Status::ok);
    solver.run_to_end();
    const int from_other = solver.corrections();
    solve_first();
    ASSERT_EQ(solver.start_near(second, IkTargetKind::pose, other), Status::ok);
    solver.run_to_end();
    EXPECT_EQ(solver.corrections(), from_other) << t;
  }
  EXPECT_GE(fewer, 7);
}

// A path streamed as the runtime streams it (a target every cycle, retarget()
// and one budget's worth of work, the linearised point taken when the solve
// is not done) follows one branch of solutions: the robot is redundant, and
// a solver that jumped between branches would send the drives across the
// workspace between two nearby targets. Along a smooth path of bends, no
// cycle's answer moves any bend more than ten times what the path moves it,
// and the last answer follows the last target.
TEST(IkSolver, AStreamedPathStaysOnOneBranch) {
  Fixture f;
  static Solver solver;
  make(f, 203, {&solver});
  JointVector<float> q(8);
  for (int s = 0; s < 4; ++s) {
    q[2 * s] = 0.8f * float(s) - 1.0f;
    q[2 * s + 1] = 0.12f;
  }
  const auto path_at = [&](int k) {
    JointVector<float> p = q;
    for (int s = 0; s < 4; ++s) {
      p[2 * s] += 0.002f * float(k);
      p[2 * s + 1] += 0.05f * std::sin(0.004f * float(k) + float(s));
    }
    return p;
  };
  const auto target_at = [&](int k) {
    const JointVector<float> b = bend_from_joints(path_at(k));
    return compensated_pose(f, b);
  };
  ASSERT_EQ(solver.start(target_at(0), IkTargetKind::pose, path_at(0)), Status::ok);
  ASSERT_EQ(solver.run_to_end(), IkSolveState::converged);
  JointVector<float> last = solver.best_bend();
  float largest_move = 0;
  for (int k = 1; k <= 600; ++k) {
    ASSERT_EQ(solver.retarget(target_at(k), IkTargetKind::pose, path_at(0)), Status::ok);
    solver.run(1000);
    const JointVector<float> now = solver.has_linearised_point() ? solver.linearised_bend() : solver.best_bend();
    largest_move = std::max(largest_move, (now - last).cwiseAbs().maxCoeff());
    last = now;
  }
  // A cycle of the path moves a bend component by about 0.5 mrad; the
  // answers moved at most 0.6 mrad a cycle.
  EXPECT_LT(largest_move, 0.005f);
  const Pose<float> reached = compensated_pose(f, last);
  EXPECT_LT((reached.position_mm - target_at(600).position_mm).norm(), 0.05f);
}

// Between evaluations the solver offers the linearised solve's point; its
// residual is the linearised model's, which near the last evaluation is the
// compensated model's (computed here from its joints) to well within the
// tracking threshold, and it is offered only while that solve runs.
TEST(IkSolver, LinearisedPointIsWhereItsResidualSays) {
  Fixture f;
  static Solver solver;
  make(f, 203, {&solver});
  std::mt19937 rng(7);
  int checked = 0;
  for (int t = 0; t < 10; ++t) {
    const JointVector<float> start = random_joints(rng, 4, 0.2);
    JointVector<float> goal = start;
    for (int s = 0; s < 4; ++s) goal[2 * s + 1] += 0.02f;
    const JointVector<float> goal_bend = bend_from_joints(goal);
    const Pose<float> target = compensated_pose(f, goal_bend);
    ASSERT_EQ(solver.start(target, IkTargetKind::position, start), Status::ok);
    while (solver.state() == IkSolveState::running) {
      solver.run(400);
      if (!solver.has_linearised_point()) continue;
      const JointVector<float> bend = bend_from_joints(solver.linearised_joints());
      const Pose<float> tip = compensated_pose(f, bend);
      const float exact = (target.position_mm - tip.position_mm).norm();
      EXPECT_NEAR(exact, solver.linearised_position_error_mm(), 0.05f) << "target " << t;
      ++checked;
    }
    EXPECT_FALSE(solver.has_linearised_point());
  }
  EXPECT_GT(checked, 20);
}

}  // namespace
}  // namespace cdcr::model
