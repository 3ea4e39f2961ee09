// IK convergence on the demo's model: the image tools/demo.sh trains (700
// samples of the simulated robot, seed 1), made by the qemu.golden fixture.
// The targets are the compensated model's own poses at fixed, seeded bends,
// so every one is reachable; each is solved by the board's solver type in
// float from the runtime's straight start (alpha 0, theta 0.1 on every
// segment) with the runtime's bounds, to the solver's float tolerance
// (2 um, 2e-5 rad) on the compensated model.
//
// Near the straight robot the tip's travel along the backbone and its roll
// about it are weakly actuated (a few mm/rad, no more than the slope of
// this model's correction): the last outer iterations let the residual
// wander at 2-3 um (2.1 -> 2.5 -> 3.5 um), and a stall rule that ends the
// solve after two stalled iterations stops it a few um short. A third
// iteration is allowed within 3 tolerances (ik/restarts.hpp, Restarts::stalled).
//
// Which targets end a few um short depends on the last bits of the float
// arithmetic, so the counts differ from CPU to CPU: the image the build
// trains depends on OpenBLAS's kernels and glibc's maths variants, and the
// host's GP loops are AVX2 or portable. The floors below sit under the
// lowest count of 24 runs (the image trained with five kernel sets, each
// target set solved with the AVX2 and the portable GP loops, three target
// seeds) with a margin of about two standard deviations of the count; with
// the stall rule's third iteration removed, the near-straight count falls
// below its floor on every kernel set (tools/bench/README.md, "IK on
// other CPUs"). 2,000 targets a set keep the two apart.

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cdcr/model/compensated_kinematics.hpp"
#include "cdcr/model/flash_image.hpp"
#include "cdcr/model/gp_correction.hpp"
#include "cdcr/model/ik_solver.hpp"

namespace cdcr::model {
namespace {

using Correction = GpCorrection<float, double, kMaxSegments>;
using Solver = IkSolver<float, kMaxSegments, Correction>;

constexpr double kPi = 3.14159265358979323846;
constexpr int kTargets = 2000;

struct DemoModel {
  std::vector<std::uint8_t> image;
  ImageView view{};
  RobotGeometry<float> geometry;
  Correction correction;
};

// The image under test: the build's demo model, or the one named by
// CDCR_DEMO_MODEL_IMAGE (the same data trained with other CPUs' kernels).
std::string demo_model_path() {
  const char* path = std::getenv("CDCR_DEMO_MODEL_IMAGE");
  return path != nullptr ? path : CDCR_DEMO_MODEL_IMAGE;
}

// Added to every target set's seed: other target sets of the same kinds,
// for measuring the counts' spread (tools/bench/run_ik_other_cpus_bench.sh).
unsigned target_seed(unsigned seed) {
  const char* offset = std::getenv("CDCR_IK_TARGET_SEED_OFFSET");
  return seed + (offset != nullptr ? static_cast<unsigned>(std::strtoul(offset, nullptr, 10)) : 0u);
}

void load(DemoModel& m) {
  const std::string path = demo_model_path();
  std::ifstream file(path, std::ios::binary);
  ASSERT_TRUE(file) << "no demo model at " << path << " (the qemu.golden test makes it)";
  m.image.assign(std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>());
  ImageCapacity capacity;
  capacity.max_training_points = 4096;
  ASSERT_EQ(parse_image(m.image.data(), m.image.size(), m.view, capacity), ImageStatus::ok);
  ASSERT_EQ(geometry_from_image(m.view, m.geometry), Status::ok);
  ASSERT_EQ(m.correction.bind(m.view), Status::ok);
}

// Targets converged of `targets` compensated poses with theta up to
// theta_max; with one_at_limit, one segment (in turn) bent to its limit.
int converged_from_straight(const DemoModel& m, Solver& solver, double theta_max, int targets, unsigned seed,
                            bool one_at_limit = false) {
  IkSolverOptions<float> options;
  options.max_corrections = 40;  // the runtime's kMaxIkCorrections and kMaxIkIterations
  options.max_iterations = 400;
  solver.configure(m.geometry, m.correction, options);
  const int segments = m.geometry.segment_count;
  JointVector<float> straight(2 * segments);
  for (int s = 0; s < segments; ++s) {
    straight[2 * s] = 0.0f;
    straight[2 * s + 1] = 0.1f;
  }
  std::mt19937 rng(target_seed(seed));
  std::uniform_real_distribution<double> alpha(-kPi, kPi), theta(0.0, theta_max);
  int converged = 0;
  for (int t = 0; t < targets; ++t) {
    JointVector<float> q(2 * segments);
    for (int s = 0; s < segments; ++s) {
      q[2 * s] = float(alpha(rng));
      q[2 * s + 1] = float(theta(rng));
    }
    if (one_at_limit) q[2 * (t % segments) + 1] = m.geometry.segments[t % segments].theta_max_rad;
    const JointVector<float> b = bend_from_joints(q);
    const Pose<float> target = exp(m.correction.predict(b)) * forward_kinematics_bend(b, m.geometry);
    EXPECT_EQ(solver.start(target, IkTargetKind::pose, straight), Status::ok);
    solver.run_to_end();
    if (solver.state() != IkSolveState::converged) continue;
    ++converged;
    // Independently: the compensated model at the answer (predict() sums in
    // another order than the sliced evaluation: about 1 um apart here).
    const JointVector<float> answer = bend_from_joints(solver.best_joints());
    const Pose<float> tip = exp(m.correction.predict(answer)) * forward_kinematics_bend(answer, m.geometry);
    EXPECT_LE((tip.position_mm - target.position_mm).norm(), 5e-3f) << "target " << t;
  }
  return converged;
}

// kTargets of the model's own poses with every bend up to theta_max_rad, from the
// straight start: at least `floor` converge.
void expect_converged_from_straight(double theta_max_rad, unsigned seed, int floor) {
  DemoModel m;
  ASSERT_NO_FATAL_FAILURE(load(m));
  static Solver solver;
  const int converged = converged_from_straight(m, solver, theta_max_rad, kTargets, seed);
  ::testing::Test::RecordProperty("converged", converged);
  EXPECT_GE(converged, floor);
}

TEST(IkDemoModel, NearStraightPoseTargetsConvergeFromStraight) { expect_converged_from_straight(0.06, 2606u, 1935); }

TEST(IkDemoModel, PaperWorkspacePoseTargetsConvergeFromStraight) { expect_converged_from_straight(0.2, 2620u, 1930); }

// The full design range and targets on the theta limit: the restarts and
// the active set.
TEST(IkDemoModel, FullRangeAndLimitPoseTargetsConvergeFromStraight) {
  DemoModel m;
  ASSERT_NO_FATAL_FAILURE(load(m));
  static Solver solver;
  const int full_range = converged_from_straight(m, solver, kPi / 2, kTargets, 2657u);
  const int at_limit = converged_from_straight(m, solver, kPi / 2, kTargets, 2658u, true);
  RecordProperty("full_range_converged", full_range);
  RecordProperty("at_limit_converged", at_limit);
  EXPECT_GE(full_range, 1975);
  EXPECT_GE(at_limit, 1940);
}

}  // namespace
}  // namespace cdcr::model
