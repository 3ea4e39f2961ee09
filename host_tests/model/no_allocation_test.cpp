// The model runs inside the motor controller's fixed-rate cycle, where a heap
// allocation is a latency spike (and on the target, possibly a failure). Every
// type it uses is fixed-size or fixed-capacity; this test proves that the hot
// paths never reach the heap, in double and in float.
//
// The counting hooks are host_tests/support/allocation_hooks.cpp; assertions
// are made only after the counter is stopped.

#include <cstdlib>
#include <vector>

#include <gtest/gtest.h>

#include "allocation_counter.hpp"
#include "cdcr/model/kinematics.hpp"
#include "cdcr/model/payload_compliance.hpp"

namespace cdcr::model {
namespace {

using test_support::AllocationCounter;

// Results are folded into volatile sinks so the optimiser can neither drop
// the measured work nor elide the control allocations.
volatile double g_checksum = 0;
void* volatile g_sink = nullptr;

void consume(double value) { g_checksum = g_checksum + value; }

template <typename Derived>
void consume(const Eigen::MatrixBase<Derived>& value) {
  consume(double(value.sum()));
}

template <typename S>
void consume(const Pose<S>& pose) {
  consume(pose.rotation);
  consume(pose.position_mm);
}

template <typename S>
void consume(const IkResult<S>& result) {
  consume(result.joints);
  consume(result.cables_mm);
  consume(double(result.position_error_mm) + double(result.orientation_error_rad) + result.iterations);
}

// eps(b) = eps0 + M b, the shape of the GP correction the runtime plugs in.
template <typename S>
struct AffineCorrection {
  Twist<S> eps0;
  Jacobian<S> slope;

  template <typename Bend, typename Derivative>
  Status operator()(const Bend& bend, Twist<S>& eps, Derivative& d_eps_d_bend) const {
    eps = eps0 + slope * bend;
    d_eps_d_bend = slope;
    return Status::ok;
  }
};

// One control-cycle's worth of model work: everything the runtime and the
// calibration use per sample. Returns a checksum of the statuses so nothing
// is optimised away and failures are visible after the counted region.
template <typename S>
struct Workload {
  RobotGeometry<S> geometry = RobotGeometry<S>::prototype();
  JointVector<S> joints;
  Pose<S> target;
  AffineCorrection<S> correction;

  Workload() {
    joints.resize(2 * geometry.segment_count);
    joints << S(0.4), S(0.15), S(-1.2), S(0.1), S(2.5), S(0.18), S(-3.0), S(0.05);
    JointVector<S> target_joints = joints;
    target_joints[1] += S(0.03);
    target_joints[4] -= S(0.2);
    forward_kinematics(target_joints, geometry, target);
    correction.eps0 << S(0.5), S(-0.2), S(0.1), S(0.002), S(-0.001), S(0.003);
    correction.slope = Jacobian<S>::Constant(6, 2 * geometry.segment_count, S(0.001));
  }

  int run() {
    int failures = 0;
    const auto check = [&failures](Status status) { failures += status != Status::ok; };

    Pose<S> tip;
    check(forward_kinematics(joints, geometry, tip));
    const Twist<S> twist = log(tip);
    const Pose<S> back = exp(twist);
    consume(back);

    Jacobian<S> jacobian;
    check(tip_jacobian(joints, geometry, tip, jacobian));
    tip_jacobian_bend(bend_from_joints(joints), geometry, tip, jacobian);
    consume(jacobian);

    CableVector<S> cables;
    check(cables_from_joints(joints, geometry, cables));
    JointVector<S> from_cables;
    check(joints_from_cables(cables, geometry, from_cables));
    consume(from_cables);

    // The payload's sag (Newton steps with an LU solve) and its inverse.
    PayloadCompliance<S> compliance;
    compliance.segments = geometry.segment_count;
    compliance.weighted_gravity = Vec3<S>(S(-2e-4), S(3e-5), S(1e-5));
    compliance.softening_per_rad = S(0.3);
    const JointVector<S> sagged = sagged_bends(bend_from_joints(joints), geometry, S(0.8), compliance);
    consume(sagged);
    consume(commanded_bends(sagged, geometry, S(0.8), compliance));

    const Twist<S> error = tip_error_twist(target, tip);
    const Pose<S> compensated = compensate(error, tip);
    const PoseError<S> difference = pose_error(compensated, target);
    consume(double(difference.position_mm + difference.orientation_rad));

    const IkResult<S> by_pose = solve_ik(target, geometry, joints);
    check(by_pose.status);
    consume(by_pose);
    const IkResult<S> by_position = solve_ik_position(Vec3<S>(target.position_mm), geometry, joints);
    check(by_position.status);
    consume(by_position);
    const IkResult<S> corrected = solve_ik(target, geometry, joints, IkOptions<S>{}, correction);
    check(corrected.status);
    consume(corrected);

    // An unreachable target: the longest path through the solver.
    Pose<S> far = target;
    far.position_mm.z() += S(1000);
    const IkResult<S> unreachable = solve_ik(far, geometry, joints);
    failures += unreachable.status != Status::ik_not_converged;
    consume(unreachable);
    return failures;
  }
};

template <typename S>
void expect_no_allocation() {
  Workload<S> workload;
  ASSERT_EQ(workload.run(), 0);  // warm-up, and proof the work succeeds

  AllocationCounter counter;
  const int failures = workload.run();
  counter.stop();

  EXPECT_EQ(failures, 0);
  EXPECT_EQ(counter.operator_new_calls(), 0);
  EXPECT_EQ(counter.malloc_calls(), 0);
}

TEST(NoAllocation, DoublePathNeverAllocates) { expect_no_allocation<double>(); }

TEST(NoAllocation, FloatPathNeverAllocates) { expect_no_allocation<float>(); }

// The counter must see what it is meant to see, or the tests above would
// pass vacuously.
TEST(NoAllocation, CounterSeesOperatorNew) {
  AllocationCounter counter;
  std::vector<int> values;
  values.push_back(1);
  g_sink = values.data();
  counter.stop();
  EXPECT_GT(counter.operator_new_calls(), 0);
}

TEST(NoAllocation, CounterSeesMalloc) {
  AllocationCounter counter;
  void* pointer = std::malloc(64);
  g_sink = pointer;
  void* grown = std::realloc(pointer, 4096);
  g_sink = grown;
  std::free(grown);
  void* zeroed = std::calloc(8, 8);
  g_sink = zeroed;
  std::free(zeroed);
  counter.stop();
  EXPECT_EQ(counter.malloc_calls(), 3);
}

TEST(NoAllocation, CounterIgnoresAllocationsOutsideItsRegion) {
  long counted = 0;
  {
    AllocationCounter counter;
    counter.stop();
    std::vector<int> values(100, 1);
    g_sink = values.data();
    counted = counter.operator_new_calls() + counter.malloc_calls();
  }
  EXPECT_EQ(counted, 0);
}

}  // namespace
}  // namespace cdcr::model
