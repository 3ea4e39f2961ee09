// The model runs inside the motor controller's fixed-rate cycle, where a heap
// allocation is a latency spike (and on the target, possibly a failure). Every
// type it uses is fixed-size or fixed-capacity; this test proves that the hot
// paths never reach the heap, in double and in float.
//
// This executable replaces the global operator new/delete family and
// interposes malloc, calloc, realloc, aligned_alloc and posix_memalign,
// forwarding to glibc's own entry points. Allocations are only counted while
// an AllocationCounter is alive, so gtest's own bookkeeping outside the
// measured regions does not count, and assertions are made only after the
// counter is stopped.

#include <atomic>
#include <cerrno>
#include <cstddef>
#include <cstdlib>
#include <new>
#include <vector>

#include <gtest/gtest.h>

#include "cdcr/model/kinematics.hpp"

extern "C" {
void* __libc_malloc(std::size_t size);
void* __libc_calloc(std::size_t count, std::size_t size);
void* __libc_realloc(void* pointer, std::size_t size);
void* __libc_memalign(std::size_t alignment, std::size_t size);
void __libc_free(void* pointer);
}

namespace {

std::atomic<bool> g_counting{false};
std::atomic<long> g_operator_new_calls{0};
std::atomic<long> g_malloc_calls{0};

void note(std::atomic<long>& counter) {
  if (g_counting.load(std::memory_order_relaxed)) counter.fetch_add(1, std::memory_order_relaxed);
}

void* checked_new(std::size_t size) {
  note(g_operator_new_calls);
  if (void* pointer = __libc_malloc(size == 0 ? 1 : size)) return pointer;
  throw std::bad_alloc();
}

void* checked_aligned_new(std::size_t size, std::align_val_t alignment) {
  note(g_operator_new_calls);
  if (void* pointer = __libc_memalign(static_cast<std::size_t>(alignment), size == 0 ? 1 : size)) return pointer;
  throw std::bad_alloc();
}

void* nothrow_new(std::size_t size) noexcept {
  note(g_operator_new_calls);
  return __libc_malloc(size == 0 ? 1 : size);
}

void* nothrow_aligned_new(std::size_t size, std::align_val_t alignment) noexcept {
  note(g_operator_new_calls);
  return __libc_memalign(static_cast<std::size_t>(alignment), size == 0 ? 1 : size);
}

}  // namespace

extern "C" {
void* malloc(std::size_t size) noexcept {
  note(g_malloc_calls);
  return __libc_malloc(size);
}
void* calloc(std::size_t count, std::size_t size) noexcept {
  note(g_malloc_calls);
  return __libc_calloc(count, size);
}
void* realloc(void* pointer, std::size_t size) noexcept {
  note(g_malloc_calls);
  return __libc_realloc(pointer, size);
}
void* aligned_alloc(std::size_t alignment, std::size_t size) noexcept {
  note(g_malloc_calls);
  return __libc_memalign(alignment, size);
}
int posix_memalign(void** out, std::size_t alignment, std::size_t size) noexcept {
  note(g_malloc_calls);
  if (alignment < sizeof(void*) || (alignment & (alignment - 1)) != 0) return EINVAL;
  void* pointer = __libc_memalign(alignment, size);
  if (pointer == nullptr) return ENOMEM;
  *out = pointer;
  return 0;
}
void free(void* pointer) noexcept { __libc_free(pointer); }
}

void* operator new(std::size_t size) { return checked_new(size); }
void* operator new[](std::size_t size) { return checked_new(size); }
void* operator new(std::size_t size, const std::nothrow_t&) noexcept { return nothrow_new(size); }
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept { return nothrow_new(size); }
void* operator new(std::size_t size, std::align_val_t alignment) { return checked_aligned_new(size, alignment); }
void* operator new[](std::size_t size, std::align_val_t alignment) { return checked_aligned_new(size, alignment); }
void* operator new(std::size_t size, std::align_val_t alignment, const std::nothrow_t&) noexcept {
  return nothrow_aligned_new(size, alignment);
}
void* operator new[](std::size_t size, std::align_val_t alignment, const std::nothrow_t&) noexcept {
  return nothrow_aligned_new(size, alignment);
}
void operator delete(void* pointer) noexcept { __libc_free(pointer); }
void operator delete[](void* pointer) noexcept { __libc_free(pointer); }
void operator delete(void* pointer, std::size_t) noexcept { __libc_free(pointer); }
void operator delete[](void* pointer, std::size_t) noexcept { __libc_free(pointer); }
void operator delete(void* pointer, const std::nothrow_t&) noexcept { __libc_free(pointer); }
void operator delete[](void* pointer, const std::nothrow_t&) noexcept { __libc_free(pointer); }
void operator delete(void* pointer, std::align_val_t) noexcept { __libc_free(pointer); }
void operator delete[](void* pointer, std::align_val_t) noexcept { __libc_free(pointer); }
void operator delete(void* pointer, std::size_t, std::align_val_t) noexcept { __libc_free(pointer); }
void operator delete[](void* pointer, std::size_t, std::align_val_t) noexcept { __libc_free(pointer); }
void operator delete(void* pointer, std::align_val_t, const std::nothrow_t&) noexcept { __libc_free(pointer); }
void operator delete[](void* pointer, std::align_val_t, const std::nothrow_t&) noexcept { __libc_free(pointer); }

namespace cdcr::model {
namespace {

class AllocationCounter {
 public:
  AllocationCounter() {
    g_operator_new_calls.store(0);
    g_malloc_calls.store(0);
    g_counting.store(true);
  }
  ~AllocationCounter() { stop(); }
  AllocationCounter(const AllocationCounter&) = delete;
  AllocationCounter& operator=(const AllocationCounter&) = delete;

  void stop() { g_counting.store(false); }
  long operator_new_calls() const { return g_operator_new_calls.load(); }
  long malloc_calls() const { return g_malloc_calls.load(); }
};

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
