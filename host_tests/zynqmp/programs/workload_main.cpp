// The whole runtime on the R5F with the trained image the Cortex-M boards
// carry (zynqmp.workload): can0 through the Xilinx CAN driver, can1 on the
// same emulated bus playing the drives and the planner with the one codec
// (peer_workload.hpp, shared with the MPS2 boards' cycle budget), every
// cycle at 1 kHz under the board's watchdog (board.hpp run_guarded).
//   1. The golden replay: the host's cable sets, one a cycle; every POSE on
//      the bus within 0.02 mm and 1e-4 rad of the host model library's
//      double pose for the same cables (qemu_golden.hpp).
//   2. The mixed workload: forward-only cycles, position and pose targets
//      (one in eight unreachable), a streamed TRACKING path, the variance
//      in between; every IK_REPORT on the bus the runtime's, converged
//      targets' setpoints arriving at the drives and the pose reaching the
//      target.
//   3. A model update over CAN into the flash region (a RAM flash of two
//      slots, as on the MPS2 boards: QEMU emulates no flash the RPU can
//      write): the same model under another digest, sent by the update
//      sender the `cdcr deploy` tool uses, while the drives and targets go
//      on; it commits, the runtime switches to slot A, and its poses stay
//      the host's.
//   4. Bus faults: frames with a foreign identifier (the acceptance filters
//      keep them out) or a bad length (rejected, counted), a flood past the
//      RX FIFO (the overflow counted, no release missed, poses go on), the
//      drives going silent (STATUS FAULT, stale input) and coming back (RUN).
// Under -icount shift=0 the cycle counter counts instructions: every
// Runtime::run_cycle is held to the board's budget
// (kCycleBudgetInstructions), the worst printed as
// `worst cycle: N instructions over C cycles (budget B)`.

#include <cmath>
#include <cstdint>

#include <cdcr/firmware/protocol.hpp>
#include <cdcr/firmware/runtime.hpp>
#include <cdcr/firmware/update/update_sender.hpp>
#include <cdcr/zynqmp/console.hpp>
#include <cdcr/zynqmp/xilinx_can_controller.hpp>

#include "board.hpp"
#include "bus_view.hpp"
#include "checks.hpp"
#include "golden_check.hpp"
#include "peer_workload.hpp"

namespace {

namespace golden = cdcr::qemu_golden;
namespace zynqmp = cdcr::zynqmp;
namespace r5f = cdcr::boards::zcu102_r5f;
using namespace cdcr::qemu_programs;  // the peer's workload, and its model, firmware and protocol
using namespace cdcr::zynqmp_checks;  // check, check_equal, print, verdict
using cdcr::board_tests::BusView;
using cdcr::hal::CanFrame;
using cdcr::hal::CanStatus;
using firmware::FaultCode;
using firmware::RuntimeState;

// The host's pose for the same cables, as the bus carries it: 0.01 mm
// position steps and 1/32767 quaternion steps on top of the float path.
constexpr double kReplayPositionToleranceMm = 0.02;
constexpr double kReplayOrientationToleranceRad = 1e-4;

// A RAM flash of two slots (peer_workload.hpp), as the MPS2 boards'
// update budget has.
UpdateFlash flash;
r5f::Board board;
firmware::Runtime runtime(hal_with_flash(board, flash), cdcr::boards::mps2::golden_geometry());
firmware::Correction correction;

// can1 as the peer's end of the bus: peer_workload.hpp's PeerBus for the
// drives and the planner, a hal::CanBus for the update sender.
class ControllerPeer final : public cdcr::hal::CanBus {
 public:
  zynqmp::XilinxCanController controller{zynqmp::kCan1Base};
  int refused = 0;  // frames can1's TX FIFO did not take

  void deliver(const CanFrame& frame) { send(frame); }
  bool take_transmitted(CanFrame& frame) { return controller.receive(frame); }

  CanStatus send(const CanFrame& frame) override {
    const CanStatus status = controller.transmit(frame);
    if (status != CanStatus::ok) refused += 1;
    return status;
  }
  CanStatus receive(CanFrame& frame) override {
    return controller.receive(frame) ? CanStatus::ok : CanStatus::empty;
  }
  bool set_filters(const cdcr::hal::CanFilter* filters, std::size_t count) override {
    return controller.set_filters(filters, count);
  }
  cdcr::hal::CanErrorCounters error_counters() const override { return {}; }
};
ControllerPeer peer;
// The model update under way, if any; its frames share a cycle's room on
// the bus with the drives' and a target's (as update_budget_main).
firmware::UpdateSender* sender = nullptr;
constexpr std::uint32_t kUpdateFramesPerCycle = 25;

BusView bus;
IdealDrives drives;
Random random_numbers{0x2545F491u};
bool drives_report = true;  // false: the drives keep the setpoints they get, and say nothing

int cycles_run = 0;

// Every frame the runtime sent since the last look, decoded: setpoints move
// the drives, update reports go to the sender, the rest to the bus view.
// Then, unless silent, the drives report.
void exchange_with_drives() {
  const auto record = [](const CanFrame& frame) {
    if (sender != nullptr && protocol::update_report::kMessage.carries(frame.id)) {
      sender->on_report(frame, cycles_run, peer);
      return;
    }
    cdcr::board_tests::record(bus, frame);
  };
  if (drives_report) {
    drives.exchange(peer, record);
    return;
  }
  CanFrame frame;
  while (peer.take_transmitted(frame)) record(frame);
}

std::uint64_t counting_overhead = 0;
std::uint64_t worst_cycle = 0;
int over_budget = 0;

// Instructions of one Runtime::run_cycle (none with run false: the
// counting's own, which every count leaves out).
std::uint64_t counted(const cdcr::hal::TimerTick& tick, bool run) {
  asm volatile("" ::: "memory");
  const std::uint64_t start = board.timer.now_counts();
  asm volatile("" ::: "memory");
  if (run) run_cycle_opaque(runtime, tick);
  asm volatile("" ::: "memory");
  const std::uint64_t counts = board.timer.now_counts() - start;
  asm volatile("" ::: "memory");
  return counts > counting_overhead ? counts - counting_overhead : 0;
}

// Runtime::run_cycle for the release `tick`, counted and held to the
// budget.
void run_counted_cycle(const cdcr::hal::TimerTick& tick) {
  const std::uint64_t instructions = counted(tick, true);
  if (instructions > worst_cycle) worst_cycle = instructions;
  if (instructions > r5f::kCycleBudgetInstructions && ++over_budget <= 5) {
    print("over budget: cycle ", cycles_run, ", ", instructions, " instructions, IK units ",
          runtime.ik_units_last_cycle(), "\n");
  }
  cycles_run += 1;
}

// One release: the peer's frames (what the runtime sent last cycle, the
// drives' report, the update's share), then the counted cycle.
void cycle() {
  board.run_guarded([](const cdcr::hal::TimerTick& tick) {
    exchange_with_drives();
    if (sender != nullptr) sender->pump(cycles_run, peer, kUpdateFramesPerCycle);
    run_counted_cycle(tick);
  });
}

// The bus's pose against the host's double pose of golden case c.
cdcr::model::PoseError<double> bus_pose_error(int c) {
  cdcr::model::Pose<double> on_bus;
  for (int i = 0; i < 3; ++i) on_bus.position_mm[i] = bus.position_mm[i];
  const double* q = bus.quaternion;
  on_bus.rotation = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix();
  const cdcr::model::Pose<double> expected = cdcr::boards::mps2::golden_pose<double>(
      golden::kCompensatedPositionMm[c], golden::kCompensatedRotation[c]);
  return cdcr::model::pose_error(on_bus, expected);
}

void replay_golden_cases(int rounds) {
  double worst_position_mm = 0;
  double worst_orientation_rad = 0;
  for (int round = 0; round < rounds; ++round) {
    for (int c = 0; c < golden::kCases; ++c) {
      board.run_guarded([c](const cdcr::hal::TimerTick& tick) {
        CanFrame frame;
        while (peer.take_transmitted(frame)) cdcr::board_tests::record(bus, frame);
        cdcr::boards::mps2::deliver_cables(peer, c);
        run_counted_cycle(tick);
      });
      const int poses_before = bus.pose_frames;
      CanFrame frame;
      while (peer.take_transmitted(frame)) cdcr::board_tests::record(bus, frame);
      check(bus.pose_frames == poses_before + 3, "a pose on the bus for every golden cable set");
      check(bus.compensated_flag, "the replayed poses are compensated");
      const cdcr::model::PoseError<double> error = bus_pose_error(c);
      if (!(error.position_mm <= worst_position_mm)) worst_position_mm = error.position_mm;
      if (!(error.orientation_rad <= worst_orientation_rad)) worst_orientation_rad = error.orientation_rad;
    }
  }
  print("golden replay: ", rounds * golden::kCases, " cycles; largest difference bus - host (double): ");
  zynqmp::console_write_fixed(worst_position_mm, 4);
  zynqmp::console_write(" mm, ");
  zynqmp::console_write_fixed(worst_orientation_rad * 1e6, 1);
  zynqmp::console_write(" urad\n");
  check(worst_position_mm <= kReplayPositionToleranceMm, "replayed positions within 0.02 mm of the host's");
  check(worst_orientation_rad <= kReplayOrientationToleranceRad, "replayed orientations within 1e-4 rad of the host's");
}

std::uint8_t next_sequence = 0;
alignas(8) std::uint8_t updated_image[64 * 1024];
int targets_sent = 0;
int targets_converged = 0;
int reports_matching = 0;
int setpoints_at_drives = 0;
double worst_reached_mm = 0;

// A target from the planner, then cycles until its request ends. The
// IK_REPORT on the bus must be the runtime's; a converged target's
// setpoints must be what the drives hold, and the pose, once they report
// them, at the target.
void solve(const cdcr::model::Pose<float>& target, protocol::TargetMode mode) {
  const std::uint8_t sequence = next_sequence++;
  const int reports_before = bus.ik_reports;
  deliver_target(peer, target, mode, false, sequence);
  targets_sent += 1;
  int spent = 0;
  do {
    cycle();
    ++spent;
  } while (runtime.ik_running() && spent < firmware::kMaxIkCycles + 2);
  // Three more: the report and the setpoints reach the drives, the drives
  // report the new lengths, and the runtime publishes the pose there.
  cycle();
  cycle();
  cycle();
  const firmware::IkReport& report = runtime.last_ik_report();
  const bool reported = bus.ik_reports > reports_before && bus.ik_report.sequence == sequence &&
                        bus.ik_report.outcome == report.outcome;
  reports_matching += reported ? 1 : 0;
  if (report.outcome != protocol::IkOutcome::converged || report.sequence != sequence) return;
  targets_converged += 1;
  const firmware::Cables& setpoints = runtime.setpoints_mm();
  bool held = true;
  for (int s = 0; s < drives.segments; ++s) {
    for (int k = 0; k < 4; ++k) held = held && std::fabs(drives.lengths_mm[s][k] - setpoints[4 * s + k]) <= 0.006f;
  }
  setpoints_at_drives += held ? 1 : 0;
  double distance_sq = 0;
  for (int i = 0; i < 3; ++i) {
    const double d = bus.position_mm[i] - static_cast<double>(target.position_mm[i]);
    distance_sq += d * d;
  }
  const double reached_mm = std::sqrt(distance_sq);
  if (!(reached_mm <= worst_reached_mm)) worst_reached_mm = reached_mm;
}

}  // namespace

int main() {
  zynqmp::console_write("zynqmp workload: the runtime with a trained image on can0, drives and planner on can1\n");
  check(board.start_can(), "can0 starts at 1 Mbit/s");
  check(peer.controller.start(r5f::kCanTiming), "can1 starts at 1 Mbit/s");
  const RuntimeState boot = runtime.init();
  cdcr::model::ImageView image{};
  check(boot == RuntimeState::run, "the trained image boots into RUN");
  check(runtime.can_filters_accepted(), "the controller takes the runtime's acceptance filters");
  check(bind_board_image(board, correction, image), "the image binds");
  print("model: ", image.training_points, " training points; IK work per cycle ", runtime.ik_units_per_cycle(),
        " units\n");
  if (failures != 0) return verdict();
  drives.segments = runtime.geometry().segment_count;

  // The update's image and its digest, made before the cycles start: the
  // peer's own work, which would otherwise take the board's periods.
  const cdcr::hal::MemoryRegion region = board.model_storage.model_region();
  const std::uint32_t image_size = static_cast<std::uint32_t>(region.size_bytes);
  check(runtime.model_update().enabled(), "model updates are enabled with the flash region");
  check(image_size <= sizeof(updated_image), "the image fits the update's buffer");
  if (failures != 0) return verdict();
  copy_with_other_creation_time(region.data, image_size, updated_image);
  firmware::UpdateSender update(updated_image, image_size);

  board.start_cycles();
  const cdcr::hal::TimerTick no_tick{};
  counting_overhead = counted(no_tick, false);

  // 1. The host's cable sets, one a cycle, four rounds.
  replay_golden_cases(4);
  const int uncertainty_after_replay = bus.uncertainty_frames;

  // 2. The drives start where golden case 0 has them; forward-only cycles.
  for (int s = 0; s < drives.segments; ++s) {
    for (int k = 0; k < 4; ++k) drives.lengths_mm[s][k] = float(golden::kCablesMm[0][4 * s + k]);
  }
  for (int i = 0; i < 200; ++i) cycle();
  const int uncertainty_forward = bus.uncertainty_frames;
  check(bus.uncertainty_frames > uncertainty_after_replay, "POSE_UNCERTAINTY on the bus between targets");
  check(bus.uncertainty.r95_position_mm > 0 && bus.uncertainty.r95_position_mm < 65,
        "the r95 position radius is a length");

  // Targets in the paper's workspace, pose and position, one in eight
  // unreachable.
  for (int t = 0; t < 48; ++t) {
    if (t % 8 == 7) {
      cdcr::model::Pose<float> far;
      far.position_mm = cdcr::model::Vec3<float>(900.0f, 0.0f, 50.0f);
      solve(far, protocol::TargetMode::position);
    } else {
      const bool pose = t % 3 != 0;
      solve(reachable_target(random_numbers, correction, runtime.geometry(), 0.2f),
            pose ? protocol::TargetMode::pose : protocol::TargetMode::position);
    }
  }

  // A streamed path: a TRACKING target every cycle, the compensated tip of
  // joints that move smoothly (reachable by construction).
  cdcr::model::JointVector<float> joints(2 * drives.segments);
  for (int step = 0; step < 300; ++step) {
    for (int s = 0; s < drives.segments; ++s) {
      joints[2 * s] = 0.8f * float(s) + 0.004f * float(step);
      joints[2 * s + 1] = 0.12f + 0.05f * std::sin(0.01f * float(step) + float(s));
    }
    deliver_target(peer, compensated_tip(correction, runtime.geometry(), joints), protocol::TargetMode::position, true,
                   next_sequence++);
    cycle();
  }
  while (runtime.ik_running()) cycle();
  for (int i = 0; i < 100; ++i) cycle();

  print("targets: ", targets_sent, " sent, ", targets_converged, " converged, ", reports_matching,
        " IK_REPORTs on the bus matching the runtime's, ", setpoints_at_drives,
        " converged with their setpoints at the drives; pose at the target within ");
  zynqmp::console_write_fixed(worst_reached_mm, 4);
  print(" mm; POSE_UNCERTAINTY frames ", bus.uncertainty_frames, "\n");
  check(reports_matching == targets_sent, "every target's IK_REPORT on the bus is the runtime's");
  check(targets_converged >= targets_sent * 3 / 4, "most targets converge");
  check(setpoints_at_drives == targets_converged, "every converged target's setpoints reach the drives");
  check(worst_reached_mm <= 0.1, "the pose the drives' lengths give is within 0.1 mm of the converged target");
  check(bus.uncertainty_frames > uncertainty_forward, "POSE_UNCERTAINTY while targets come and go");
  check_equal(runtime.statistics().rejected_frames, 0, "no frame rejected before the faults");

  // 3. A model update over CAN, targets going on meanwhile.
  const int update_start_cycle = cycles_run;
  std::uint64_t worst_before_update = worst_cycle;
  worst_cycle = 0;
  {
    update.resend_after = 199;
    sender = &update;
    update.start(peer, cycles_run);
    for (int i = 0; i < 8'000 && update.outcome() == firmware::UpdateSender::Outcome::running; ++i) {
      if (i % 40 == 0) {
        deliver_target(peer, reachable_target(random_numbers, correction, runtime.geometry(), 0.2f),
                       protocol::TargetMode::pose, false, next_sequence++);
      }
      cycle();
    }
    for (int i = 0; i < 20; ++i) cycle();
    sender = nullptr;
    print("model update: ", update.total_blocks(), " blocks, ", update.frames_sent(), " frames, ", update.rewinds(),
          " rewinds, ", update.restarts(), " restarts over ", cycles_run - update_start_cycle,
          " cycles; outcome ", update.outcome() == firmware::UpdateSender::Outcome::committed ? "committed" : "not committed",
          ", active slot ", runtime.model_update().active_slot(), ", state ", firmware::to_string(runtime.state()),
          "; worst cycle meanwhile ", worst_cycle, " instructions\n");
    check(update.outcome() == firmware::UpdateSender::Outcome::committed, "the model update commits");
  }
  check(runtime.model_update().active_slot() == 0, "the runtime switches to the new model in slot A");
  check(runtime.state() == RuntimeState::run, "the runtime runs the new model");
  if (worst_before_update > worst_cycle) worst_cycle = worst_before_update;
  // The new model's poses: the host's, as before the update.
  replay_golden_cases(1);

  // 4. Bus faults. A foreign identifier the acceptance filters keep out,
  // and a cable frame of the wrong length: rejected, counted, nothing else.
  CanFrame foreign;
  foreign.id = 0x7F0;
  foreign.dlc = 8;
  peer.deliver(foreign);
  CanFrame short_cable;
  protocol::encode(protocol::CableFeedback{0, {150, 150, 150, 150}}, short_cable);
  short_cable.dlc = 3;
  peer.deliver(short_cable);
  for (int i = 0; i < 20; ++i) cycle();
  print("bad frames: rejected ", runtime.statistics().rejected_frames, "; state ",
        firmware::to_string(runtime.state()), "\n");
  check_equal(runtime.statistics().rejected_frames, 1, "the short cable frame is rejected and counted, the foreign identifier has no effect");
  check(runtime.state() == RuntimeState::run, "bad frames leave the runtime in RUN");

  // A flood: more frames in one period than the controller's RX FIFO and
  // the driver's ring hold together.
  const std::uint32_t overruns_before = board.can.error_counters().rx_overruns;
  const std::uint32_t missed_before = board.timer.overruns();
  const int poses_before_flood = bus.pose_frames;
  board.run_guarded([](const cdcr::hal::TimerTick& tick) {
    exchange_with_drives();
    for (std::size_t i = 0; i < zynqmp::kXilinxCanFifoFrames + 40; ++i) {
      CanFrame frame;
      protocol::encode(protocol::CableFeedback{int(i % drives.segments),
                                               {drives.lengths_mm[i % drives.segments][0], drives.lengths_mm[i % drives.segments][1],
                                                drives.lengths_mm[i % drives.segments][2], drives.lengths_mm[i % drives.segments][3]}},
                       frame);
      peer.deliver(frame);
    }
    run_counted_cycle(tick);
  });
  for (int i = 0; i < 50; ++i) cycle();
  const std::uint32_t flood_overruns = board.can.error_counters().rx_overruns - overruns_before;
  print("flood: ", zynqmp::kXilinxCanFifoFrames + 40, " frames in one period; RX overflows counted ", flood_overruns,
        ", releases missed ", board.timer.overruns() - missed_before, ", poses since ", bus.pose_frames - poses_before_flood,
        " frames; state ", firmware::to_string(runtime.state()), "\n");
  check(flood_overruns >= 1, "the flood's RX FIFO overflow is counted");
  check_equal(board.timer.overruns() - missed_before, 0, "no release missed in the flood");
  check(bus.pose_frames - poses_before_flood >= 3 * 50, "poses go on through the flood");
  check(runtime.state() == RuntimeState::run, "the flood leaves the runtime in RUN");

  // The drives go silent, then come back.
  drives_report = false;
  for (int i = 0; i < 3 * firmware::kStaleInputCycles; ++i) cycle();
  print("drives silent: STATUS state ", bus.reported_state, ", fault ", bus.reported_fault, "\n");
  check(bus.reported_state == static_cast<int>(RuntimeState::fault), "STATUS reports FAULT once the drives are silent");
  check(bus.reported_fault == static_cast<int>(FaultCode::cable_input_stale), "STATUS reports stale cable input");
  drives_report = true;
  for (int i = 0; i < 3 * firmware::kStatusEveryCycles; ++i) cycle();
  print("drives back: STATUS state ", bus.reported_state, "\n");
  check(bus.reported_state == static_cast<int>(RuntimeState::run), "STATUS reports RUN once the drives are back");

  while (cycles_run < 2000) cycle();
  print("worst cycle: ", worst_cycle, " instructions over ", cycles_run, " cycles (budget ",
        r5f::kCycleBudgetInstructions, ")\n");
  check_equal(over_budget, 0, "cycles over budget");
  check_equal(board.timer.overruns(), 0, "releases missed");
  check_equal(peer.refused, 0, "frames can1 could not send");
  const cdcr::hal::CanErrorCounters counters = board.can.error_counters();
  check(counters.tx_dropped == 0 && counters.bus_errors == 0, "nothing dropped, no bus errors");
  return verdict();
}
