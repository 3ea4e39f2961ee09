#pragma once
// What the programs that measure the runtime on the MPS2 boards
// (cycle_budget, update_budget) drive it with: the same random numbers on
// every run and both boards, ideal drives that report the last setpoint of
// each segment every cycle, targets delivered as a planner sends them, and
// a cycle counted in instructions.

#include <algorithm>
#include <cstdint>

#include <cdcr/cortexm/semihosting.hpp>
#include <cdcr/firmware/runtime.hpp>

#include "board.hpp"
#include "instruction_count.hpp"

namespace cdcr::qemu_programs {

namespace model = cdcr::model;
namespace firmware = cdcr::firmware;
namespace protocol = cdcr::firmware::protocol;

// xorshift32.
class Random {
 public:
  explicit Random(std::uint32_t seed) : state_(seed) {}
  float uniform(float lo, float hi) {
    state_ ^= state_ << 13;
    state_ ^= state_ >> 17;
    state_ ^= state_ << 5;
    return lo + (hi - lo) * float(state_ >> 8) * (1.0f / 16777216.0f);
  }

 private:
  std::uint32_t state_;
};

// The drives of an ideal robot, on the board's mailbox bus.
struct IdealDrives {
  float lengths_mm[firmware::kMaxSegments][4] = {};
  int segments = 0;
  int silent_segment = -1;  // a drive that stops reporting

  // Takes the runtime's frames: setpoints move the drives, anything else
  // goes to `other` (a frame the workload itself answers). Then reports
  // every segment's lengths.
  template <typename OtherFrame>
  void exchange(boards::mps2::Board& board, OtherFrame&& other) {
    hal::CanFrame frame;
    while (board.can.take_transmitted(frame)) {
      protocol::CableSetpoint setpoint;
      if (protocol::decode(frame, setpoint) != protocol::DecodeStatus::ok) {
        other(frame);
        continue;
      }
      for (int k = 0; k < 4; ++k) lengths_mm[setpoint.segment][k] = float(setpoint.lengths_mm[k]);
    }
    for (int s = 0; s < segments; ++s) {
      if (s == silent_segment) continue;
      protocol::CableFeedback feedback{s, {lengths_mm[s][0], lengths_mm[s][1], lengths_mm[s][2], lengths_mm[s][3]}};
      if (protocol::encode(feedback, frame)) board.can.deliver(frame);
    }
  }
  void exchange(boards::mps2::Board& board) {
    exchange(board, [](const hal::CanFrame&) {});
  }
};

// A target's frames as a planner sends them: the orientation of a pose
// target, the position, then the commit frame.
inline void deliver_target(boards::mps2::Board& board, const model::Pose<float>& target, protocol::TargetMode mode,
                           bool tracking, std::uint8_t sequence, bool refuse_extrapolating = false) {
  hal::CanFrame frame;
  if (mode == protocol::TargetMode::pose) {
    Eigen::Quaternion<float> q(target.rotation);
    q.normalize();
    protocol::encode(protocol::TargetOrientation{q.w(), q.x(), q.y(), q.z()}, frame);
    board.can.deliver(frame);
  }
  protocol::encode(protocol::TargetPositionXy{target.position_mm.x(), target.position_mm.y()}, frame);
  board.can.deliver(frame);
  protocol::TargetPositionZ commit{target.position_mm.z(), mode, tracking, sequence};
  commit.refuse_extrapolating = refuse_extrapolating;
  protocol::encode(commit, frame);
  board.can.deliver(frame);
}

// Where the compensated model puts the tip for the given joints (targets
// are made this way, on the board, and not counted).
inline model::Pose<float> compensated_tip(const firmware::Correction& correction, const firmware::Geometry& geometry,
                                          const model::JointVector<float>& joints) {
  const model::JointVector<float> bend = model::bend_from_joints(joints);
  return model::exp(correction.predict(bend)) * model::forward_kinematics_bend(bend, geometry);
}

// ... at random joints, each segment bent at most theta_max_rad.
inline model::Pose<float> reachable_target(Random& random, const firmware::Correction& correction,
                                           const firmware::Geometry& geometry, float theta_max_rad) {
  model::JointVector<float> joints(2 * geometry.segment_count);
  for (int s = 0; s < geometry.segment_count; ++s) {
    joints[2 * s] = random.uniform(-3.14159f, 3.14159f);
    joints[2 * s + 1] = random.uniform(0.0f, std::min(theta_max_rad, geometry.segments[s].theta_max_rad));
  }
  return compensated_tip(correction, geometry, joints);
}

// The instructions of one Runtime::run_cycle, called through a function the
// compiler cannot inline into the counted region.
__attribute__((noinline)) inline void run_cycle_opaque(firmware::Runtime& runtime, const hal::TimerTick& tick) {
  runtime.run_cycle(tick);
}

inline std::uint32_t counted_cycle(const boards::mps2::InstructionCounter& counter, boards::mps2::Board& board,
                                   firmware::Runtime& runtime) {
  const hal::TimerTick tick{board.timer.now_ns(), 0};
  return counter.instructions([&] { run_cycle_opaque(runtime, tick); });
}

// The board's model image parsed and bound to `correction` (what the runtime
// itself bound at init), for the workload to make its targets with.
inline bool bind_board_image(boards::mps2::Board& board, firmware::Correction& correction, model::ImageView& image) {
  const hal::MemoryRegion region = board.model_storage.model_region();
  return model::parse_image(region.data, region.size_bytes, image, model::ImageCapacity{}) == model::ImageStatus::ok &&
         correction.bind(image) == model::Status::ok;
}

// The start every measuring program makes: SysTick counting at
// kCountingPeriodNs, the runtime booted into RUN, and the board's image bound
// to `correction`. False, with the reason printed, when one of them fails.
inline bool start_counting(boards::mps2::Board& board, firmware::Runtime& runtime,
                           firmware::Correction& correction, model::ImageView& image) {
  cortexm::attach_systick(board.timer);
  board.timer.start(boards::mps2::kCountingPeriodNs);
  if (runtime.init() != firmware::RuntimeState::run) {
    cortexm::console_write("FAIL: the runtime did not boot into RUN\n");
    return false;
  }
  if (!bind_board_image(board, correction, image)) {
    cortexm::console_write("FAIL: cannot bind the image\n");
    return false;
  }
  return true;
}

// `worst cycle: N instructions over C cycles (budget B)`, the line the
// budget tests and tools/bench read.
inline void report_worst_cycle(std::uint32_t worst, std::uint32_t cycles) {
  cortexm::console_write("worst cycle: ");
  cortexm::console_write_int(static_cast<std::int32_t>(worst));
  cortexm::console_write(" instructions over ");
  cortexm::console_write_int(static_cast<std::int32_t>(cycles));
  cortexm::console_write(" cycles (budget ");
  cortexm::console_write_int(static_cast<std::int32_t>(boards::mps2::kCycleBudgetInstructions));
  cortexm::console_write(")\n");
}

}  // namespace cdcr::qemu_programs
