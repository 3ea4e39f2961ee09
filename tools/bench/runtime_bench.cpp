// Per-cycle compute time of the firmware runtime on this host: the exact
// Runtime::run_cycle() of a board build, fed over the simulated bus in
// lockstep time, so only the cycle itself sits between the two clock reads.
//
// Cycle kinds, each with fresh cable feedback from every segment:
//   forward         the compensated pose estimate (RUN state);
//   IK stream       plus a TRACKING position target every cycle, a small step
//                   from the previous one;
//   IK jump         plus a position target anywhere in the workspace, the
//                   next one as soon as the runtime has answered the last;
//   IK pose jump    the same with full pose targets.
// IK runs in bounded slices, so every cycle of a run is timed, whether a
// request starts, continues or ends in it. Each kind runs three times: back
// to back, the code's own cost (and how often this machine takes the CPU
// from a thread that never sleeps), and twice at the runtime's 1 kHz, each
// cycle released by the Linux backend's timer as cdcr-runtime releases it:
// sleeping between cycles (on a virtual machine a thread that sleeps may
// wake on a cold cache or a descheduled core) and spinning to each release
// (cdcr-runtime --spin, a core kept for the runtime); the requests' own figures (the
// cycles and iterations each took, and whether it converged) come from
// their IK_REPORT. Targets are poses the simulated robot actually reaches,
// so the compensated IK can meet them.
//
// Baselines in the same process (on a shared machine only ratios to them are
// comparable between runs): one nominal forward_kinematics_bend() in float,
// and one bare GP predict of the image.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <random>
#include <stdexcept>
#include <optional>
#include <string>
#include <vector>

#include <time.h>

#include <CLI/CLI.hpp>
#include <Eigen/Geometry>

#include <cdcr/firmware/runtime.hpp>

#include <cdcr/sim/lockstep_timer.hpp>
#include <cdcr/sim/memory_model_storage.hpp>
#include <cdcr/sim/virtual_can.hpp>

#include "export/binary_file.hpp"
#include "cdcr/linux/posix_time.hpp"
#include "sim/simulated_platform.hpp"
#include "sim/simulated_robot.hpp"
#include "sim/target_frames.hpp"
#include "sim/workspace_sampler.hpp"

namespace {

namespace fw = cdcr::firmware;
namespace model = cdcr::model;
namespace protocol = cdcr::firmware::protocol;
namespace sim = cdcr::sim;
using Clock = std::chrono::steady_clock;

constexpr std::int64_t kPeriodNs = 1'000'000;  // 1 kHz: the simulated timer's period, and the paced runs' pace
constexpr std::size_t kRingSize = 4096;
// Per-cycle joint step of the tracked trajectory: up to 1 rad/s per joint at
// 1 kHz, well under a millimetre of tip motion per cycle.
constexpr double kStreamStepRad = 1e-3;
constexpr int kBaselineBatch = 4096;

struct Options {
  std::string image_path;
  int forward_cycles = 20000;
  int ik_cycles = 1000;
  int repetitions = 5;
  std::uint64_t seed = 1;
};


using CableFrames = std::vector<cdcr::hal::CanFrame>;

CableFrames cable_frames(const model::CableVector<double>& cables_mm, int segment_count) {
  CableFrames frames(static_cast<std::size_t>(segment_count));
  for (int s = 0; s < segment_count; ++s) {
    const protocol::CableFeedback feedback{
        s, {cables_mm[4 * s], cables_mm[4 * s + 1], cables_mm[4 * s + 2], cables_mm[4 * s + 3]}};
    if (!protocol::encode(feedback, frames[std::size_t(s)])) {
      throw std::runtime_error("cable length out of the frame's range");
    }
  }
  return frames;
}

using cdcr::sim::target_frames;

// Everything the cycles read, generated before any timing.
struct Workload {
  model::RobotGeometry<double> geometry;
  std::vector<CableFrames> feedback;                      // kRingSize workspace samples
  std::vector<fw::Joints> bends;                          // the same samples, for the baselines
  std::vector<std::vector<cdcr::hal::CanFrame>> stream;   // position targets along a trajectory
  std::vector<std::vector<cdcr::hal::CanFrame>> jump;     // position targets anywhere
  std::vector<std::vector<cdcr::hal::CanFrame>> pose_jump;
};

Workload make_workload(const fw::Runtime& runtime, const Options& options) {
  Workload w;
  w.geometry = runtime.geometry().cast<double>();
  sim::SimulatorConfig config;
  config.seed = options.seed;
  const sim::SimulatedRobot robot(w.geometry, config);
  sim::WorkspaceSampler sampler(w.geometry, config.workspace_theta_max_rad, options.seed + 1000);

  for (std::size_t k = 0; k < kRingSize; ++k) {
    const sim::WorkspaceSample sample = sampler.next();
    w.feedback.push_back(cable_frames(sample.cables_mm, w.geometry.segment_count));
    w.bends.push_back(model::bend_from_joints(sample.joints).cast<float>());
    const model::Pose<double> reached = robot.true_pose(sample.cables_mm);
    const auto sequence = static_cast<std::uint8_t>(k);
    w.jump.push_back(target_frames(reached, protocol::TargetMode::position, false, sequence));
    w.pose_jump.push_back(target_frames(reached, protocol::TargetMode::pose, false, sequence));
  }

  // A random walk in joint space, kept inside the sampled workspace.
  std::mt19937 rng(static_cast<std::uint32_t>(options.seed));
  std::uniform_real_distribution<double> step(-kStreamStepRad, kStreamStepRad);
  model::JointVector<double> joints = sampler.next().joints;
  for (std::size_t k = 0; k < kRingSize; ++k) {
    for (int s = 0; s < w.geometry.segment_count; ++s) {
      joints[2 * s] += step(rng);
      joints[2 * s + 1] = std::clamp(joints[2 * s + 1] + step(rng), 0.0, config.workspace_theta_max_rad);
    }
    model::CableVector<double> cables_mm;
    if (model::cables_from_joints(joints, w.geometry, cables_mm) != model::Status::ok) {
      throw std::runtime_error("trajectory left the nominal model's range");
    }
    w.stream.push_back(
        target_frames(robot.true_pose(cables_mm), protocol::TargetMode::position, true, static_cast<std::uint8_t>(k)));
  }
  return w;
}

struct CycleSamples {
  std::vector<std::int64_t> ns;
  // Thread CPU time of the same cycles: the wall-clock maximum on a shared
  // machine is usually a preemption, which this leaves out.
  std::vector<std::int64_t> cpu_ns;
  // Per request that ended (jump kinds): cycles and iterations it took.
  std::vector<int> request_cycles;
  std::vector<int> iterations;
  int converged = 0;
};

enum class CycleKind { forward, ik_stream, ik_jump, ik_pose_jump };
constexpr CycleKind kKinds[] = {CycleKind::forward, CycleKind::ik_stream, CycleKind::ik_jump, CycleKind::ik_pose_jump};
constexpr int kKindCount = 4;

const char* label(CycleKind kind) {
  switch (kind) {
    case CycleKind::forward: return "forward (pose estimate)";
    case CycleKind::ik_stream: return "forward + IK, position target on a trajectory";
    case CycleKind::ik_jump: return "forward + IK, position target anywhere";
    case CycleKind::ik_pose_jump: return "forward + IK, pose target anywhere";
  }
  return "?";
}

std::int64_t thread_cpu_ns() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return std::int64_t(t.tv_sec) * 1'000'000'000 + t.tv_nsec;
}

// back_to_back, or one cycle per millisecond of the monotonic clock, the
// timer sleeping or spinning to each release.
enum class Pace { back_to_back, sleep, spin };

// One run of one cycle kind on a freshly booted runtime.
CycleSamples run_cycles(const std::vector<std::uint8_t>& image, const Workload& w, CycleKind kind, int cycles,
                        Pace pacing) {
  auto platform = std::make_unique<sim::SimulatedPlatform>();
  platform->storage.assign(image);
  auto runtime = std::make_unique<fw::Runtime>(platform->hal, fw::Geometry::prototype());
  if (runtime->init() != fw::RuntimeState::run) {
    throw std::runtime_error(std::string("image does not boot: ") + fw::to_string(runtime->boot_fault()));
  }
  cdcr::hal::CanBus& peer = platform->bus.node(1);
  platform->timer.start(kPeriodNs);
  const std::vector<std::vector<cdcr::hal::CanFrame>>* targets =
      kind == CycleKind::ik_stream ? &w.stream
      : kind == CycleKind::ik_jump ? &w.jump
      : kind == CycleKind::ik_pose_jump ? &w.pose_jump
                                        : nullptr;

  CycleSamples samples;
  samples.ns.reserve(std::size_t(cycles));
  cdcr::hal::CanFrame drained;
  std::size_t next_target = 0;
  bool awaiting_answer = false;
  // The Linux backend's timer, as cdcr-runtime paces its cycles.
  const cdcr::linux_host::PosixMonotonicClock clock;
  const bool paced = pacing != Pace::back_to_back;
  cdcr::linux_host::PosixPeriodicTimer pace(
      clock, pacing == Pace::spin ? cdcr::linux_host::ReleaseWait::spin : cdcr::linux_host::ReleaseWait::sleep);
  if (paced) pace.start(kPeriodNs);
  for (int k = 0; k < cycles; ++k) {
    const std::size_t i = std::size_t(k) % kRingSize;
    for (const auto& frame : w.feedback[i]) peer.send(frame);
    // A stream sends every cycle; a jump waits for the last one's answer.
    if (targets != nullptr && (kind == CycleKind::ik_stream || !awaiting_answer)) {
      for (const auto& frame : (*targets)[next_target++ % kRingSize]) peer.send(frame);
      awaiting_answer = true;
    }
    const cdcr::hal::TimerTick tick = platform->timer.wait_next();
    if (paced) pace.wait_next();
    const std::int64_t cpu_begin_ns = thread_cpu_ns();
    const Clock::time_point begin = Clock::now();
    runtime->run_cycle(tick);
    const Clock::time_point end = Clock::now();
    const std::int64_t cpu_end_ns = thread_cpu_ns();
    samples.ns.push_back(std::chrono::duration_cast<std::chrono::nanoseconds>(end - begin).count());
    samples.cpu_ns.push_back(cpu_end_ns - cpu_begin_ns);
    while (peer.receive(drained) == cdcr::hal::CanStatus::ok) {
    }
    if (kind != CycleKind::ik_stream && awaiting_answer && !runtime->ik_running()) {
      const fw::IkReport& report = runtime->last_ik_report();
      samples.request_cycles.push_back(report.cycles);
      samples.iterations.push_back(report.iterations);
      if (report.outcome == protocol::IkOutcome::converged) ++samples.converged;
      awaiting_answer = false;
    }
  }
  if (runtime->statistics().rejected_frames != 0 || runtime->statistics().rejected_cable_sets != 0 ||
      runtime->state() != fw::RuntimeState::run) {
    throw std::runtime_error(std::string("runtime left the nominal path: state ") + fw::to_string(runtime->state()));
  }
  return samples;
}

double percentile(std::vector<std::int64_t> values, double fraction) {
  if (values.empty()) return 0;
  const auto rank = static_cast<std::size_t>(std::ceil(fraction * double(values.size()))) - 1;
  std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(rank), values.end());
  return double(values[rank]);
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

template <typename Call>
double per_call_ns(Call&& call) {
  const Clock::time_point begin = Clock::now();
  for (int k = 0; k < kBaselineBatch; ++k) call(std::size_t(k) % kRingSize);
  return double(std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - begin).count()) / kBaselineBatch;
}

volatile float g_sink = 0;

// The GP loops the build selected (CDCR_MODEL_ARCH).
#if defined(CDCR_MODEL_ARCH_NAME)
constexpr const char* kSelectedArchName = CDCR_MODEL_ARCH_NAME;
#else
constexpr const char* kSelectedArchName = "selected";
#endif

// How often this machine takes the CPU from a busy thread, and for how long:
// gaps of more than 5 us between consecutive clock reads over one second. A
// cycle of duration d is hit with probability about rate x d, so once that
// exceeds 1 % the p99 of such cycles measures the machine, not the code.
struct Interruptions {
  double per_second = 0;
  double mean_us = 0;
};

Interruptions measure_interruptions() {
  const Clock::time_point start = Clock::now();
  Clock::time_point previous = start;
  long count = 0;
  double total_us = 0;
  for (;;) {
    const Clock::time_point now = Clock::now();
    if (now - start > std::chrono::seconds(1)) break;
    const double gap_us = std::chrono::duration<double, std::micro>(now - previous).count();
    if (gap_us > 5.0) {
      ++count;
      total_us += gap_us;
    }
    previous = now;
  }
  return Interruptions{double(count), count > 0 ? total_us / double(count) : 0.0};
}

// The image on the simulated board, parsed for the bare baselines too.
struct BenchModel {
  explicit BenchModel(const std::vector<std::uint8_t>& image, const Options& options)
      : aligned(image), probe(boot(image)), workload(make_workload(probe, options)) {
    model::ImageCapacity capacity;
    capacity.max_training_points = fw::kMaxTrainingPoints;
    capacity.max_segments = fw::kMaxSegments;
    const auto region = aligned.model_region();
    if (model::parse_image(region.data, region.size_bytes, view, capacity) != model::ImageStatus::ok) {
      throw std::runtime_error("image does not parse");
    }
    if (correction.bind(view) != model::Status::ok) throw std::runtime_error("image does not bind");
    if (portable_correction.bind(view) != model::Status::ok) throw std::runtime_error("image does not bind");
  }

  fw::Runtime& boot(const std::vector<std::uint8_t>& image) {
    probe_platform.storage.assign(image);
    probe_runtime.emplace(probe_platform.hal, fw::Geometry::prototype());
    if (probe_runtime->init() != fw::RuntimeState::run) {
      throw std::runtime_error(std::string("image does not boot: ") + fw::to_string(probe_runtime->boot_fault()));
    }
    return *probe_runtime;
  }

  const sim::MemoryModelStorage aligned;
  sim::SimulatedPlatform probe_platform;
  std::optional<fw::Runtime> probe_runtime;
  fw::Runtime& probe;
  const Workload workload;
  model::ImageView view{};
  fw::Correction correction;
  // The plain C++ loops on the same image, for the ratio to the build's.
  model::GpCorrection<float, fw::Accumulator, fw::kMaxSegments, model::arch::Portable> portable_correction;
};

// Every run's figures: the baselines' per-call times and, per kind of
// cycle, the percentiles and the IK's requests.
struct Measurements {
  std::vector<double> fk_ns, gp_ns, portable_gp_ns, evaluation_ns;
  std::vector<double> p50[kKindCount], p99[kKindCount], paced_p99[kKindCount], spin_p99[kKindCount];
  std::vector<std::int64_t> all_iterations[kKindCount], all_request_cycles[kKindCount];
  std::int64_t worst_ns[kKindCount] = {}, worst_cpu_ns[kKindCount] = {};
  long converged[kKindCount] = {}, total[kKindCount] = {};
};

void measure_baselines(const BenchModel& m, Measurements& out) {
  const Workload& w = m.workload;
  const fw::Geometry& geometry = m.probe.geometry();
  out.fk_ns.push_back(per_call_ns([&](std::size_t i) {
    g_sink = g_sink + model::forward_kinematics_bend(w.bends[i], geometry).position_mm.x();
  }));
  out.gp_ns.push_back(per_call_ns([&](std::size_t i) { g_sink = g_sink + m.correction.predict(w.bends[i])[0]; }));
  out.portable_gp_ns.push_back(
      per_call_ns([&](std::size_t i) { g_sink = g_sink + m.portable_correction.predict(w.bends[i])[0]; }));
  // What each IK iteration evaluates (see evaluate_model in inverse_kinematics.hpp).
  out.evaluation_ns.push_back(per_call_ns([&](std::size_t i) {
    model::Pose<float> tip;
    model::Jacobian<float, fw::kMaxSegments> jacobian, d_eps;
    model::Twist<float> eps;
    model::tip_jacobian_bend(w.bends[i], geometry, tip, jacobian);
    m.correction(w.bends[i], eps, d_eps);
    const model::Pose<float> correction_pose = model::exp(eps);
    model::apply_adjoint(correction_pose, jacobian);
    jacobian.noalias() += model::left_jacobian(eps) * d_eps;
    g_sink = g_sink + (correction_pose * tip).position_mm.x() + jacobian(0, 0);
  }));
}

void measure_cycles(const std::vector<std::uint8_t>& image, const BenchModel& m, const Options& options,
                    Measurements& out) {
  for (int k = 0; k < kKindCount; ++k) {
    const CycleKind kind = kKinds[k];
    const int cycles = kind == CycleKind::forward ? options.forward_cycles : options.ik_cycles;
    const CycleSamples s = run_cycles(image, m.workload, kind, cycles, Pace::back_to_back);
    out.paced_p99[k].push_back(percentile(run_cycles(image, m.workload, kind, cycles, Pace::sleep).ns, 0.99));
    out.spin_p99[k].push_back(percentile(run_cycles(image, m.workload, kind, cycles, Pace::spin).ns, 0.99));
    out.p50[k].push_back(percentile(s.ns, 0.50));
    out.p99[k].push_back(percentile(s.ns, 0.99));
    out.worst_ns[k] = std::max(out.worst_ns[k], *std::max_element(s.ns.begin(), s.ns.end()));
    out.worst_cpu_ns[k] = std::max(out.worst_cpu_ns[k], *std::max_element(s.cpu_ns.begin(), s.cpu_ns.end()));
    out.all_iterations[k].insert(out.all_iterations[k].end(), s.iterations.begin(), s.iterations.end());
    out.all_request_cycles[k].insert(out.all_request_cycles[k].end(), s.request_cycles.begin(),
                                     s.request_cycles.end());
    out.converged[k] += s.converged;
    out.total[k] += long(s.iterations.size());
  }
}

void print_table(const BenchModel& m, const Options& options, const Measurements& r) {
  const model::ImageView& view = m.view;
  const double fk_baseline_ns = median(r.fk_ns);
  const double gp_baseline_ns = median(r.gp_ns);
  const double portable_gp_baseline_ns = median(r.portable_gp_ns);
  const double evaluation_baseline_ns = median(r.evaluation_ns);
  std::printf("Image: %u training points, %d inputs (%s), %d segments; IK: %u work units per cycle, "
              "at most %d cycles per request\n",
              view.training_points, view.input_dims, model::to_string(view.encoding), view.segment_count,
              m.probe.ik_units_per_cycle(), fw::kMaxIkCycles);
  std::printf("%d runs; per run %d forward cycles and %d cycles of each IK kind, back to back and then at "
              "1 kHz, sleeping and spinning to each release. p50/p99: median over runs; max: worst of all runs "
              "back to back.\n\n",
              options.repetitions, options.forward_cycles, options.ik_cycles);
  std::printf("| cycle | p50 us | p99 us | max us | max us, thread CPU | p99 us at 1 kHz, sleeping | "
              "p99 us at 1 kHz, spinning | p50 / FK | p99 / FK | requests | cycles per request p50 / p99 / max | "
              "iterations p50 / p99 / max | converged |\n");
  std::printf("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  double worst_p99_us = 0;
  double worst_paced_p99_us = 0;
  double worst_spin_p99_us = 0;
  for (int k = 0; k < kKindCount; ++k) {
    const double m50 = median(r.p50[k]), m99 = median(r.p99[k]), paced99 = median(r.paced_p99[k]);
    const double spin99 = median(r.spin_p99[k]);
    worst_p99_us = std::max(worst_p99_us, m99 * 1e-3);
    worst_paced_p99_us = std::max(worst_paced_p99_us, paced99 * 1e-3);
    worst_spin_p99_us = std::max(worst_spin_p99_us, spin99 * 1e-3);
    std::printf("| %s | %.2f | %.2f | %.1f | %.1f | %.2f | %.2f | %.1f | %.1f |", label(kKinds[k]), m50 * 1e-3,
                m99 * 1e-3, double(r.worst_ns[k]) * 1e-3, double(r.worst_cpu_ns[k]) * 1e-3, paced99 * 1e-3,
                spin99 * 1e-3, m50 / fk_baseline_ns, m99 / fk_baseline_ns);
    if (r.total[k] == 0) {
      std::printf(" - | - | - | - |\n");
    } else {
      std::printf(" %ld | %.0f / %.0f / %.0f | %.0f / %.0f / %.0f | %.1f%% |\n", r.total[k],
                  percentile(r.all_request_cycles[k], 0.5), percentile(r.all_request_cycles[k], 0.99),
                  percentile(r.all_request_cycles[k], 1.0), percentile(r.all_iterations[k], 0.5),
                  percentile(r.all_iterations[k], 0.99), percentile(r.all_iterations[k], 1.0),
                  100.0 * double(r.converged[k]) / double(r.total[k]));
    }
  }
  std::printf("| baseline: nominal FK (`forward_kinematics_bend`, float) | %.3f | | | | | | 1.0 | | | | | |\n",
              fk_baseline_ns * 1e-3);
  std::printf("| baseline: bare GP predict (%u points, %s loops) | %.2f | | | | | | %.1f | | | | | |\n",
              view.training_points, kSelectedArchName, gp_baseline_ns * 1e-3, gp_baseline_ns / fk_baseline_ns);
  std::printf("| baseline: bare GP predict (%u points, portable loops) | %.2f | | | | | | %.1f | | | | | |\n",
              view.training_points, portable_gp_baseline_ns * 1e-3, portable_gp_baseline_ns / fk_baseline_ns);
  std::printf("| one full model evaluation (FK, Jacobian, GP mean and gradient) | %.2f | | | | | | %.1f | | | | | "
              "|\n",
              evaluation_baseline_ns * 1e-3, evaluation_baseline_ns / fk_baseline_ns);
  std::printf("\nHost goal p99 <= 15 us for every kind of cycle: %s back to back (worst p99 %.2f us), %s at 1 kHz "
              "spinning to each release (%.2f us), %s at 1 kHz sleeping between cycles (%.2f us)\n",
              worst_p99_us <= 15.0 ? "met" : "NOT met", worst_p99_us,
              worst_spin_p99_us <= 15.0 ? "met" : "NOT met", worst_spin_p99_us,
              worst_paced_p99_us <= 15.0 ? "met" : "NOT met", worst_paced_p99_us);
  const Interruptions interruptions = measure_interruptions();
  std::printf("This machine interrupts a busy thread %.0f times a second, for %.1f us on average: a %.1f us cycle "
              "(the IK kinds' p50) is hit %.1f %% of the time.\n",
              interruptions.per_second, interruptions.mean_us, median(r.p50[kKindCount - 1]) * 1e-3,
              100.0 * interruptions.per_second * median(r.p50[kKindCount - 1]) * 1e-9);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Per-cycle compute time of the firmware runtime on this host (simulated bus, lockstep time)."};
  app.name("cdcr-bench-runtime");
  Options options;
  app.add_option("--image", options.image_path, "model image (flash image v2, or v1)")->required();
  app.add_option("--forward-cycles", options.forward_cycles, "forward cycles per run")->capture_default_str();
  app.add_option("--ik-cycles", options.ik_cycles, "cycles per run of each IK kind")->capture_default_str();
  app.add_option("--repetitions", options.repetitions,
                 "runs of every kind, each at 1 kHz and back to back; the table shows medians")
      ->capture_default_str();
  app.add_option("--seed", options.seed, "simulated robot (as cdcr simulate --seed)")->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  if (options.forward_cycles < 1 || options.ik_cycles < 1 || options.repetitions < 1) {
    std::fprintf(stderr, "cdcr-bench-runtime: error: cycle and repetition counts must be positive\n");
    return 2;
  }

  try {
    const std::vector<std::uint8_t> image = cdcr::exporting::read_binary_file(options.image_path);
    const BenchModel bench_model(image, options);
    Measurements measurements;
    for (int r = 0; r < options.repetitions; ++r) {
      measure_baselines(bench_model, measurements);
      measure_cycles(image, bench_model, options, measurements);
    }
    print_table(bench_model, options, measurements);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "cdcr-bench-runtime: error: %s\n", e.what());
    return 1;
  }
}
