// Instruction counts of the runtime's work on the board. Run under QEMU
// with `-icount shift=10` (tools/bench/run_qemu_bench.sh): every instruction
// then advances the virtual clock by exactly 2^10 ns, so SysTick ticks of the
// 25 MHz core clock count instructions, and the counts repeat exactly.
// QEMU models no pipeline or caches: these are instructions, not cycles.
//
// Measured, each over the golden cases:
//   forward_cycle   Runtime::run_cycle with one cable frame per segment
//                   waiting: decode, compensated forward path, pose frames
//   compensated_forward, gp_predict, nominal_forward: its parts
//   compensated_ik  one compensated IK call (pose target, the runtime's
//                   options) from one golden case's joints to the next's pose
//   ik_cycle        Runtime::run_cycle with cable frames and a pose target
//                   waiting: the forward path plus the first slice of IK
//                   (the request then continues over the next cycles)
// Every count has the cost of reading the counter (an empty measurement)
// subtracted.

#include <algorithm>

#include <cdcr/cortexm/semihosting.hpp>
#include <cdcr/cortexm/stack_watermark.hpp>
#include <cdcr/firmware/runtime.hpp>
#include <cdcr/model/work_costs.hpp>

#include "board.hpp"
#include "golden_check.hpp"
#include "instruction_count.hpp"
#include "workload.hpp"

namespace {

namespace golden = cdcr::qemu_golden;
namespace console = cdcr::cortexm;
namespace model = cdcr::model;

#if defined(__ARM_FP) && !(__ARM_FP & 0x8)
constexpr model::ForwardCycleInstructions kForwardCycle = model::kCortexM4fForwardCycle;
#else
constexpr model::ForwardCycleInstructions kForwardCycle = model::kCortexM7ForwardCycle;
#endif

cdcr::boards::mps2::Board board;
cdcr::firmware::Runtime runtime(board.hal(), cdcr::boards::mps2::golden_geometry());
cdcr::firmware::Correction correction;
model::ForwardResult<float> forward_result;
model::IkResult<float> ik_result;
model::Twist<float> predicted;
model::Pose<float> nominal_pose;

// A result the compiler must assume is read, so the work behind it stays.
template <typename T>
void keep(const T& result) {
  asm volatile("" : : "r"(&result) : "memory");
}

// Out of line, so that none of the work can be scheduled outside the counted
// region.
template <typename Work>
__attribute__((noinline)) void run_opaque(Work& work) {
  work();
}

cdcr::boards::mps2::InstructionCounter counter{board.timer};

template <typename Work>
std::uint32_t count_instructions(Work&& work) {
  return counter.instructions([&] { run_opaque(work); });
}

void report(const char* name, std::uint32_t* counts, int count) {
  std::sort(counts, counts + count);
  console::console_write("instructions ");
  console::console_write(name);
  console::console_write(" median ");
  console::console_write_int(static_cast<std::int32_t>(counts[count / 2]));
  console::console_write(" min ");
  console::console_write_int(static_cast<std::int32_t>(counts[0]));
  console::console_write(" max ");
  console::console_write_int(static_cast<std::int32_t>(counts[count - 1]));
  console::console_write("\n");
}

model::CableVector<float> golden_cables(int c) {
  model::CableVector<float> cables(4 * golden::kSegments);
  for (int k = 0; k < cables.size(); ++k) {
    cables[k] = static_cast<float>(golden::kCablesMm[c][k]);
  }
  return cables;
}

model::Pose<float> golden_pose(int c) {
  return cdcr::boards::mps2::golden_pose<float>(golden::kCompensatedPositionMm[c], golden::kCompensatedRotation[c]);
}

// The three target frames of a pose target, as a planner sends them.
void deliver_pose_target(const model::Pose<float>& target, std::uint8_t sequence) {
  cdcr::qemu_programs::deliver_target(board.can, target, cdcr::firmware::protocol::TargetMode::pose, false, sequence);
}

void drain_transmitted() {
  cdcr::hal::CanFrame sent;
  while (board.can.take_transmitted(sent)) {
  }
}

}  // namespace

int main() {
  cdcr::cortexm::paint_stack();
  model::ImageView image{};
  if (!cdcr::qemu_programs::start_counting(board, runtime, correction, image)) return 1;
  console::console_write("model: ");
  console::console_write_int(static_cast<std::int32_t>(image.training_points));
  console::console_write(" training points, ");
  console::console_write_int(image.input_dims);
  console::console_write(" inputs, 6 outputs, ");
  console::console_write_int(image.segment_count);
  console::console_write(" segments\n");

  // The opaque call is part of every count here, so part of the overhead.
  auto nothing = [] {};
  counter.calibrate([&] { run_opaque(nothing); });
  const cdcr::firmware::Geometry& geometry = runtime.geometry();
  constexpr int kCases = golden::kCases;
  std::uint32_t forward_cycle[kCases], compensated[kCases], gp[kCases], nominal[kCases], ik[kCases],
      ik_per_iteration[kCases], ik_cycle[kCases];
  bool ok = true;
  int not_converged = 0;
  for (int c = 0; c < kCases; ++c) {
    // A cycle without the STATUS heartbeat, which goes out every tenth.
    const std::uint32_t published = runtime.statistics().poses_published;
    cdcr::boards::mps2::deliver_cables(board.can, c);
    const cdcr::hal::TimerTick tick{board.timer.now_ns(), 0};
    forward_cycle[c] = count_instructions([&] { runtime.run_cycle(tick); });
    ok = ok && runtime.statistics().poses_published == published + 1;
    drain_transmitted();
    // The next cycle carries a target too.
    cdcr::boards::mps2::deliver_cables(board.can, c);
    deliver_pose_target(golden_pose((c + 1) % kCases), static_cast<std::uint8_t>(c));
    const cdcr::hal::TimerTick target_tick{board.timer.now_ns(), 0};
    ik_cycle[c] = count_instructions([&] { runtime.run_cycle(target_tick); });
    drain_transmitted();
    // The request continues over the next cycles, within the cycle budget.
    for (int spent = 1; runtime.ik_running() && spent <= cdcr::firmware::kMaxIkCycles; ++spent) {
      cdcr::boards::mps2::deliver_cables(board.can, c);
      const cdcr::hal::TimerTick next{board.timer.now_ns(), 0};
      runtime.run_cycle(next);
      drain_transmitted();
    }
    if (runtime.last_ik_report().sequence != c ||
        runtime.last_ik_report().outcome != cdcr::firmware::protocol::IkOutcome::converged) {
      console::console_write("FAIL: the runtime's request of case ");
      console::console_write_int(c);
      console::console_write(" ended with outcome ");
      console::console_write_int(static_cast<std::int32_t>(runtime.last_ik_report().outcome));
      console::console_write(" after ");
      console::console_write_int(runtime.last_ik_report().cycles);
      console::console_write(" cycles and ");
      console::console_write_int(runtime.last_ik_report().iterations);
      console::console_write(" iterations, position residual ");
      console::console_write_fixed(runtime.last_ik_report().position_error_mm, 5);
      console::console_write(" mm, orientation ");
      console::console_write_fixed(runtime.last_ik_report().orientation_error_rad, 6);
      console::console_write(" rad\n");
      ok = false;
    }
    // Keep the STATUS heartbeat (every tenth cycle) out of the counted ones.
    while ((runtime.statistics().cycles + 1) % cdcr::firmware::kStatusEveryCycles == 0 ||
           (runtime.statistics().cycles + 2) % cdcr::firmware::kStatusEveryCycles == 0) {
      const cdcr::hal::TimerTick skip{board.timer.now_ns(), 0};
      cdcr::boards::mps2::deliver_cables(board.can, c);
      runtime.run_cycle(skip);
      drain_transmitted();
    }

    const model::CableVector<float> cables = golden_cables(c);
    compensated[c] = count_instructions([&] {
      model::compensated_forward(cables, geometry, correction, forward_result);
      keep(forward_result);
    });
    const model::JointVector<float> bend = model::bend_from_joints(forward_result.joints);
    gp[c] = count_instructions([&] {
      predicted = correction.predict(bend);
      keep(predicted);
    });
    nominal[c] = count_instructions([&] {
      model::JointVector<float> joints;
      model::joints_from_cables(cables, geometry, joints);
      nominal_pose = model::forward_kinematics_bend(model::bend_from_joints(joints), geometry);
      keep(nominal_pose);
    });

    model::JointVector<float> start(2 * golden::kSegments);
    for (int k = 0; k < start.size(); ++k) start[k] = golden::kJoints[c][k];
    const model::Pose<float> target = golden_pose((c + 1) % kCases);
    model::IkOptions<float> options;
    options.max_iterations = cdcr::firmware::kMaxIkIterations;
    ik[c] = count_instructions([&] {
      ik_result = model::solve_ik(target, geometry, start, options, correction);
      keep(ik_result);
    });
    if (!ik_result.converged() && !(ik_result.position_error_mm <= cdcr::firmware::kIkAcceptedPositionErrorMm &&
                                    ik_result.orientation_error_rad <= cdcr::firmware::kIkAcceptedOrientationErrorRad)) {
      ++not_converged;
      console::console_write("FAIL: solve_ik of case ");
      console::console_write_int(c);
      console::console_write(" stopped at orientation error ");
      console::console_write_fixed(ik_result.orientation_error_rad, 6);
      console::console_write(" rad\n");
    }
    // Per GP evaluation (the solver's outer iteration), the unit of its cost.
    ik_per_iteration[c] = ik_result.corrections > 0 ? ik[c] / static_cast<std::uint32_t>(ik_result.corrections) : ik[c];
    console::console_write("case ");
    console::console_write_int(c);
    console::console_write(": forward_cycle ");
    console::console_write_int(static_cast<std::int32_t>(forward_cycle[c]));
    console::console_write(", compensated_ik ");
    console::console_write_int(static_cast<std::int32_t>(ik[c]));
    console::console_write(" in ");
    console::console_write_int(ik_result.iterations);
    console::console_write(" nominal iterations and ");
    console::console_write_int(ik_result.corrections);
    console::console_write(" GP evaluations, position error ");
    console::console_write_fixed(ik_result.position_error_mm, 5);
    console::console_write(" mm\n");
  }
  report("forward_cycle", forward_cycle, kCases);
  // The figure the trainer sizes models by must hold on the board.
  const std::uint32_t forward_limit = kForwardCycle.for_points(image.training_points, image.variance_rank > 0, image.extra_inputs);
  const std::uint32_t forward_worst = *std::max_element(forward_cycle, forward_cycle + kCases);
  if (forward_worst > forward_limit) {
    console::console_write("FAIL: a forward cycle took ");
    console::console_write_int(static_cast<std::int32_t>(forward_worst));
    console::console_write(" instructions, above the ");
    console::console_write_int(static_cast<std::int32_t>(forward_limit));
    console::console_write(" that model::ForwardCycleInstructions predicts for this model\n");
    ok = false;
  }
  report("compensated_forward", compensated, kCases);
  report("gp_predict", gp, kCases);
  report("nominal_forward", nominal, kCases);
  report("compensated_ik", ik, kCases);
  report("compensated_ik_per_gp_evaluation", ik_per_iteration, kCases);
  report("ik_cycle", ik_cycle, kCases);
  // The deepest the runtime goes: a cycle with a compensated IK call.
  console::console_write("stack: ");
  console::console_write_int(static_cast<std::int32_t>(cdcr::cortexm::stack_used_bytes()));
  console::console_write(" of ");
  console::console_write_int(static_cast<std::int32_t>(cdcr::cortexm::stack_reserved_bytes()));
  console::console_write(" bytes used\n");
  if (not_converged > 0) {
    console::console_write("FAIL: compensated IK did not converge on every case\n");
    ok = false;
  }
  console::console_write(ok ? "PASS\n" : "FAIL\n");
  return ok ? 0 : 1;
}
