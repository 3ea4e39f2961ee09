// Cost of the model's hot paths, in float (the firmware's scalar) and double
// (the host's), for the four-segment prototype.
//
// Every benchmark walks a ring of pre-generated configurations so that no
// input is a compile-time constant and the branch predictor cannot learn a
// single path. A plain Eigen product chain runs in the same process: on a
// shared or throttled machine only ratios to it are comparable between runs.

#include <benchmark/benchmark.h>

#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <type_traits>
#include <vector>

#include "cdcr/model/kinematics.hpp"

namespace {

using namespace cdcr::model;

constexpr std::size_t kRingSize = 256;
constexpr unsigned kSeed = 20200519;
constexpr double kPi = 3.14159265358979323846;
// Table 1's joints lie within this bend per segment.
constexpr double kSampledThetaMaxRad = 0.2;
// How far the previous cycle's solution typically is from the new target's on
// a fixed-rate loop.
constexpr double kWarmStartOffsetRad = 0.02;
constexpr double kColdStartThetaRad = 0.05;

// Runs step(k) once per benchmark iteration, k walking the ring of inputs;
// what step returns is kept from the optimiser.
template <typename Step>
void over_ring(benchmark::State& state, Step step) {
  std::size_t k = 0;
  for (auto _ : state) {
    if constexpr (std::is_void_v<std::invoke_result_t<Step&, std::size_t>>) {
      step(k);
    } else {
      auto result = step(k);
      benchmark::DoNotOptimize(result);
    }
    k = (k + 1) % kRingSize;
  }
}

[[noreturn]] void fail_setup(const char* what, Status status) {
  std::fprintf(stderr, "benchmark input generation failed: %s: %s\n", what, to_string(status));
  std::exit(EXIT_FAILURE);
}

// Inputs are drawn once in double and rounded to S, so both scalar types see
// the same configurations.
template <typename S>
struct Workload {
  RobotGeometry<S> geometry;
  std::vector<JointVector<S>> joints;
  std::vector<JointVector<S>> bends;
  std::vector<CableVector<S>> cables_mm;
  std::vector<Pose<S>> tips;
  std::vector<Twist<S>> tip_twists;
  std::vector<JointVector<S>> warm_starts;
  JointVector<S> cold_start;
};

template <typename S>
Workload<S> make_workload() {
  const auto geometry = RobotGeometry<double>::prototype();
  const int joint_count = 2 * geometry.segment_count;
  std::mt19937 rng(kSeed);
  std::uniform_real_distribution<double> alpha_rad(-kPi, kPi);
  std::uniform_real_distribution<double> theta_rad(0.0, kSampledThetaMaxRad);
  std::uniform_real_distribution<double> offset_rad(-kWarmStartOffsetRad, kWarmStartOffsetRad);

  Workload<S> w;
  w.geometry = RobotGeometry<S>::prototype();
  for (std::size_t k = 0; k < kRingSize; ++k) {
    JointVector<double> joints(joint_count);
    JointVector<double> warm_start(joint_count);
    for (int i = 0; i < geometry.segment_count; ++i) {
      joints[2 * i] = alpha_rad(rng);
      joints[2 * i + 1] = theta_rad(rng);
      warm_start[2 * i] = joints[2 * i] + offset_rad(rng);
      warm_start[2 * i + 1] = std::abs(joints[2 * i + 1] + offset_rad(rng));
    }
    CableVector<double> cables_mm;
    if (const Status s = cables_from_joints(joints, geometry, cables_mm); s != Status::ok) fail_setup("cables", s);
    Pose<double> tip;
    if (const Status s = forward_kinematics(joints, geometry, tip); s != Status::ok) fail_setup("tip pose", s);

    w.joints.push_back(joints.cast<S>());
    w.bends.push_back(bend_from_joints(joints).cast<S>());
    w.cables_mm.push_back(cables_mm.cast<S>());
    w.tips.push_back(tip.cast<S>());
    w.tip_twists.push_back(cdcr::model::log(tip).cast<S>());
    w.warm_starts.push_back(warm_start.cast<S>());
  }
  w.cold_start.resize(joint_count);
  for (int i = 0; i < geometry.segment_count; ++i) {
    w.cold_start[2 * i] = S(0);
    w.cold_start[2 * i + 1] = S(kColdStartThetaRad);
  }
  return w;
}

template <typename S>
const Workload<S>& workload() {
  static const Workload<S> w = make_workload<S>();
  return w;
}

void report_failures(benchmark::State& state, std::size_t failures) {
  if (failures != 0) state.SkipWithError("a model call returned an error status");
}

// Reference cost: the product of four 4x4 double matrices, the naive way to
// chain four segment transforms.
void baseline_mat4_chain(benchmark::State& state) {
  std::vector<Mat4<double>> matrices;
  const auto geometry = RobotGeometry<double>::prototype();
  for (const auto& bend : workload<double>().bends) {
    for (int i = 0; i < geometry.segment_count; ++i) {
      const Vec2<double> b = bend.segment<2>(2 * i);
      matrices.push_back(segment_pose<double>(b, geometry.segments[i].backbone_length_mm).matrix());
    }
  }
  over_ring(state, [&](std::size_t k) {
    const Mat4<double>* m = &matrices[4 * k];
    return Mat4<double>(m[0] * m[1] * m[2] * m[3]);
  });
}

// The checked path a caller takes from measured cable lengths.
template <typename S>
void fk_from_cables(benchmark::State& state) {
  const Workload<S>& w = workload<S>();
  std::size_t failures = 0;
  over_ring(state, [&](std::size_t k) {
    JointVector<S> joints;
    Pose<S> tip;
    failures += joints_from_cables(w.cables_mm[k], w.geometry, joints) != Status::ok;
    failures += forward_kinematics(joints, w.geometry, tip) != Status::ok;
    benchmark::DoNotOptimize(tip);
  });
  report_failures(state, failures);
}

template <typename S>
void fk_from_bend(benchmark::State& state) {
  const Workload<S>& w = workload<S>();
  over_ring(state, [&](std::size_t k) { return forward_kinematics_bend(w.bends[k], w.geometry); });
}

template <typename S>
void se3_exp(benchmark::State& state) {
  const Workload<S>& w = workload<S>();
  over_ring(state, [&](std::size_t k) { return cdcr::model::exp(w.tip_twists[k]); });
}

template <typename S>
void se3_log(benchmark::State& state) {
  const Workload<S>& w = workload<S>();
  over_ring(state, [&](std::size_t k) { return cdcr::model::log(w.tips[k]); });
}

template <typename S>
void jacobian_bend(benchmark::State& state) {
  const Workload<S>& w = workload<S>();
  over_ring(state, [&](std::size_t k) {
    Pose<S> tip;
    Jacobian<S> jacobian;
    tip_jacobian_bend(w.bends[k], w.geometry, tip, jacobian);
    benchmark::DoNotOptimize(tip);
    benchmark::DoNotOptimize(jacobian);
  });
}

enum class Target { pose, position };
enum class Start { warm, cold };

// Counters: mean IK iterations per call and the fraction of calls that
// reached the tolerance.
template <typename S, Target target, Start start>
void run_ik(benchmark::State& state) {
  const Workload<S>& w = workload<S>();
  std::size_t failures = 0;
  double iterations = 0;
  double converged = 0;
  over_ring(state, [&](std::size_t k) {
    const JointVector<S>& initial = start == Start::warm ? w.warm_starts[k] : w.cold_start;
    IkResult<S> result;
    if constexpr (target == Target::pose) {
      result = solve_ik(w.tips[k], w.geometry, initial);
    } else {
      result = solve_ik_position(w.tips[k].position_mm, w.geometry, initial);
    }
    benchmark::DoNotOptimize(result);
    iterations += result.iterations;
    converged += result.converged();
    failures += !result.converged() && result.status != Status::ik_not_converged;
  });
  state.counters["ik_iterations"] = benchmark::Counter(iterations, benchmark::Counter::kAvgIterations);
  state.counters["converged"] = benchmark::Counter(converged, benchmark::Counter::kAvgIterations);
  report_failures(state, failures);
}

BENCHMARK(baseline_mat4_chain);
BENCHMARK_TEMPLATE(fk_from_cables, float);
BENCHMARK_TEMPLATE(fk_from_cables, double);
BENCHMARK_TEMPLATE(fk_from_bend, float);
BENCHMARK_TEMPLATE(fk_from_bend, double);
BENCHMARK_TEMPLATE(se3_exp, float);
BENCHMARK_TEMPLATE(se3_exp, double);
BENCHMARK_TEMPLATE(se3_log, float);
BENCHMARK_TEMPLATE(se3_log, double);
BENCHMARK_TEMPLATE(jacobian_bend, float);
BENCHMARK_TEMPLATE(jacobian_bend, double);
// Named ik_<target>_<start><scalar>.
BENCHMARK_TEMPLATE(run_ik, float, Target::pose, Start::warm)->Name("ik_pose_warm<float>");
BENCHMARK_TEMPLATE(run_ik, double, Target::pose, Start::warm)->Name("ik_pose_warm<double>");
BENCHMARK_TEMPLATE(run_ik, float, Target::pose, Start::cold)->Name("ik_pose_cold<float>");
BENCHMARK_TEMPLATE(run_ik, double, Target::pose, Start::cold)->Name("ik_pose_cold<double>");
BENCHMARK_TEMPLATE(run_ik, float, Target::position, Start::warm)->Name("ik_position_warm<float>");
BENCHMARK_TEMPLATE(run_ik, double, Target::position, Start::warm)->Name("ik_position_warm<double>");
BENCHMARK_TEMPLATE(run_ik, float, Target::position, Start::cold)->Name("ik_position_cold<float>");
BENCHMARK_TEMPLATE(run_ik, double, Target::position, Start::cold)->Name("ik_position_cold<double>");

}  // namespace

BENCHMARK_MAIN();
