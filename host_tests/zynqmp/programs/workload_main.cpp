// The whole runtime on the R5F with the trained image the Cortex-M boards
// carry (zynqmp.workload), on both of the RPU's cores as a board would have
// them: the first core (main) runs the runtime on can0 through the Xilinx
// CAN driver, every cycle at 1 kHz under the board's watchdog (board.hpp
// run_guarded); the second core (cdcr_zynqmp_second_core_main,
// second_core.hpp) plays the drives and the planner on can1, on the same
// emulated bus, with the one codec (peer_workload.hpp, shared with the MPS2
// boards' cycle budget). The peer knows the runtime only by its frames:
// every check of what the runtime did is made on the bus.
//   1. The golden replay: the host's cable sets, one a cycle; every POSE on
//      the bus within 0.02 mm and 1e-4 rad of the host model library's
//      double pose for the same cables (qemu_golden.hpp).
//   2. The mixed workload: forward-only cycles, position and pose targets
//      (one in eight unreachable), a streamed TRACKING path, the variance
//      in between; every target's final IK_REPORT on the bus, a converged
//      target's setpoints arriving at every drive and the pose, once the
//      drives report them, at the target.
//   3. A model update over CAN into the flash region (a RAM flash of two
//      slots, as on the MPS2 boards: QEMU emulates no flash the RPU can
//      write): the same model under another digest, sent by the update
//      sender the `cdcr deploy` tool uses, while the drives and targets go
//      on; it commits, UPDATE_REPORT names slot A active, and the poses
//      stay the host's.
//   4. Bus faults: frames with a foreign identifier (the acceptance filters
//      keep them out) or a bad length (rejected, counted in STATS), a flood
//      past the RX FIFO (no release missed by STATUS, poses go on), the
//      drives going silent (STATUS FAULT, stale input) and coming back
//      (RUN).
// The runtime's core checks, at the end, what only it knows: the flood's
// RX FIFO overflow counted by the driver, the active slot, no release
// missed, and the instructions of every Runtime::run_cycle: under -icount
// shift=0 the cycle counter counts instructions, every cycle is held to
// the board's budget (kCycleBudgetInstructions), the worst printed as
// `worst cycle: N instructions over C cycles (budget B)`.
//
// Two cores on one virtual clock. QEMU runs the cores in turn on one host
// thread, and its clock, which the cycle counter reads, advances with the
// instructions of every core; so a cycle's count would hold whatever the
// other core ran during it. A core gives up its turn at a YIELD (or WFE),
// and otherwise only when QEMU's time slice ends, rarely (a core spinning
// without YIELD kept its turn for a millisecond and more in probes, for
// good in one). Both cores keep
// the peer out of the runtime's cycles: the runtime's wait for its release
// (cycle_counter_timer.cpp) and the peer's wait for its own yield at every
// look at the clock, and the peer's periods sit half a period after the
// runtime's releases and must end within kPeerWorkLimitNs (the longest
// takes about 130 us), so the peer works while the runtime idles and is
// only ever waiting while the runtime computes. Should a time slice end
// inside a cycle, the peer's turn is one look at its clock, 24
// instructions (a YIELD forced into every cycle added 24 to the worst).
// The peer counts its turns in a shared word and flags its periods' work
// in another, and the runtime reads both around each cycle: a turn inside
// a cycle fails the run, as does a cycle begun or ended with the peer at
// work, or a period whose work runs past the limit, so the count printed
// is the runtime's own. Measured: no turn inside any of the 6,662 cycles.
//
// The cores share nothing but the program and, in .core_shared, the start
// handshake, the peer's turn count and work flag, and the end of the run
// with its verdict.

#include <cmath>
#include <cstdint>

#include <cdcr/firmware/protocol.hpp>
#include <cdcr/firmware/runtime.hpp>
#include <cdcr/firmware/update/update_sender.hpp>
#include <cdcr/zynqmp/console.hpp>
#include <cdcr/zynqmp/second_core.hpp>
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

// ---- What the cores share (.core_shared: not cached, second_core.hpp) ----

enum PeerState : std::uint32_t { kPeerPreparing = 0, kPeerReady = 1, kPeerDone = 2 };
// Set by the peer: ready once its image, its update and can1 are prepared
// (the runtime then starts its cycles), done when its scenario has ended.
CDCR_ZYNQMP_CORE_SHARED volatile std::uint32_t peer_state;
// The peer's failed checks, handed over with kPeerDone: the check count
// (checks.hpp) is the peer's while it runs and the runtime's core's again
// after, through this word, which no cache holds.
CDCR_ZYNQMP_CORE_SHARED volatile std::uint32_t peer_failures;
// Turns the peer has taken while waiting for its period (one per look at
// its clock, each followed by a YIELD), and whether it is at a period's
// work: between the two, every instruction the peer runs is seen.
CDCR_ZYNQMP_CORE_SHARED volatile std::uint32_t peer_turns;
CDCR_ZYNQMP_CORE_SHARED volatile std::uint32_t peer_working;

// ---- The runtime's core ----

// A RAM flash of two slots (peer_workload.hpp), as the MPS2 boards'
// update budget has.
UpdateFlash flash;
r5f::Board board;
firmware::Runtime runtime(hal_with_flash(board, flash), cdcr::boards::mps2::golden_geometry());

// The run ends when the peer says so; this many cycles without that is a
// peer that hung (the scenario takes about 6,700).
constexpr int kMaxCycles = 20'000;

int cycles_run = 0;
std::uint64_t counting_overhead = 0;
std::uint64_t worst_cycle = 0;
int over_budget = 0;
int first_over_budget_cycle = -1;
std::uint64_t first_over_budget_instructions = 0;
std::uint32_t most_peer_turns_inside = 0;
int cycles_with_peer_turns = 0;
int cycles_with_peer_working = 0;  // begun or ended while the peer was at a period's work

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
// budget; whether the peer ran inside it seen too (its turns, and its work
// under way at either end). Nothing printed: the console is the peer's
// until the run ends.
void run_counted_cycle(const cdcr::hal::TimerTick& tick) {
  const std::uint32_t turns_before = peer_turns;
  const bool working_before = peer_working != 0;
  const std::uint64_t instructions = counted(tick, true);
  const bool working_after = peer_working != 0;
  const std::uint32_t turns_inside = peer_turns - turns_before;
  if (turns_inside > most_peer_turns_inside) most_peer_turns_inside = turns_inside;
  if (turns_inside != 0) cycles_with_peer_turns += 1;
  if (working_before || working_after) cycles_with_peer_working += 1;
  if (instructions > worst_cycle) worst_cycle = instructions;
  if (instructions > r5f::kCycleBudgetInstructions && over_budget++ == 0) {
    first_over_budget_cycle = cycles_run;
    first_over_budget_instructions = instructions;
  }
  cycles_run += 1;
}

// ---- The peer's core ----

// The runtime's cycles are released at R + k ms; the peer's periods at
// about R + k ms - kPeriodNs / 2 (the runtime starts its cycles a period
// after the peer says ready, the peer its periods half a period after), so
// that what the peer sends in a period is what the runtime's next cycle
// receives, as the drives' reports before each cycle on a one-core board.
// The peer's work from a release on (the period's, and what it prepares
// for the next, such as a target) must end within kPeerWorkLimitNs, well
// before the runtime's next release: the peer never computes while the
// runtime does.
constexpr std::int64_t kPeriodNs = r5f::kCyclePeriodNs;
constexpr std::int64_t kPeerWorkLimitNs = 2 * kPeriodNs / 5;

zynqmp::CycleCounterTimer peer_clock{zynqmp::kQemuCycleCounterHz};
std::int64_t next_release_ns = 0;
std::int64_t period_release_ns = 0;
std::int64_t longest_period_work_ns = 0;
int periods_late = 0;
int periods_run = 0;

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

// The runtime's frames as the peer sees them: the bus view, and what
// STATUS, STATS and UPDATE_REPORT say beyond it.
BusView bus;
std::int64_t reported_overruns = -1;
std::int64_t reported_rejected_frames = -1;
protocol::UpdateReport last_update_report;
// UPDATE_REPORT's ACTIVE_SLOT for slot A (0 is the board's image, 2 slot B).
constexpr std::uint8_t kWireSlotA = 1;
int setpoint_frames[firmware::kMaxSegments] = {};  // CABLE_SETPOINT frames per segment

// The model update under way, if any; its frames share a period's room on
// the bus with the drives' and a target's (as update_budget_main).
firmware::UpdateSender* sender = nullptr;
constexpr std::uint32_t kUpdateFramesPerCycle = 25;

IdealDrives drives;
Random random_numbers{0x2545F491u};
bool drives_report = true;  // false: the drives keep the setpoints they get, and say nothing
// The planner's model: the robot's geometry and the image the board
// carries (the same file, read from the program's .cdcr_model), for its
// targets and its update.
const firmware::Geometry geometry = cdcr::boards::mps2::golden_geometry();
struct PlannerFiles {
  zynqmp::SectionModelStorage model_storage;
} planner_files;
firmware::Correction correction;

// One frame the runtime sent, other than a setpoint.
void record(const CanFrame& frame) {
  if (protocol::update_report::kMessage.carries(frame.id)) {
    protocol::decode(frame, last_update_report);
    if (sender != nullptr) sender->on_report(frame, periods_run, peer);
    return;
  }
  cdcr::board_tests::record(bus, frame);
  protocol::Status status;
  protocol::Stats stats;
  if (protocol::decode(frame, status) == protocol::DecodeStatus::ok) {
    reported_overruns = status.overruns;
  } else if (protocol::decode(frame, static_cast<FaultCode>(bus.reported_fault), stats) ==
             protocol::DecodeStatus::ok) {
    reported_rejected_frames = stats.rejected_frames;
  }
}

// can1 as the drives see it: setpoints counted per segment on their way
// to IdealDrives.
struct DrivesBus {
  bool take_transmitted(CanFrame& frame) {
    if (!peer.take_transmitted(frame)) return false;
    protocol::CableSetpoint setpoint;
    if (protocol::decode(frame, setpoint) == protocol::DecodeStatus::ok) setpoint_frames[setpoint.segment] += 1;
    return true;
  }
  void deliver(const CanFrame& frame) { peer.deliver(frame); }
};
DrivesBus drives_bus;

// The golden case whose pose the runtime's next frames carry (-1: none).
int pending_golden_case = -1;
int golden_cases_checked = 0;
int golden_cases_to_report = 0;
double worst_position_mm = 0;
double worst_orientation_rad = 0;
int poses_before_golden_case = 0;

// Every frame the runtime sent since the last look.
void take_runtime_frames() {
  CanFrame frame;
  while (drives_bus.take_transmitted(frame)) {
    protocol::CableSetpoint setpoint;
    if (protocol::decode(frame, setpoint) != protocol::DecodeStatus::ok) record(frame);
  }
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

// Once the frames of the cycle that got golden case c's cables are in:
// its pose against the host's; the replay's figures after its last case.
void settle_golden_case() {
  if (pending_golden_case < 0) return;
  check(bus.pose_frames == poses_before_golden_case + 3, "a pose on the bus for every golden cable set");
  check(bus.compensated_flag, "the replayed poses are compensated");
  const cdcr::model::PoseError<double> error = bus_pose_error(pending_golden_case);
  if (!(error.position_mm <= worst_position_mm)) worst_position_mm = error.position_mm;
  if (!(error.orientation_rad <= worst_orientation_rad)) worst_orientation_rad = error.orientation_rad;
  pending_golden_case = -1;
  golden_cases_checked += 1;
  if (golden_cases_checked < golden_cases_to_report) return;
  print("golden replay: ", golden_cases_checked, " cycles; largest difference bus - host (double): ");
  zynqmp::console_write_fixed(worst_position_mm, 4);
  zynqmp::console_write(" mm, ");
  zynqmp::console_write_fixed(worst_orientation_rad * 1e6, 1);
  zynqmp::console_write(" urad\n");
  check(worst_position_mm <= kReplayPositionToleranceMm, "replayed positions within 0.02 mm of the host's");
  check(worst_orientation_rad <= kReplayOrientationToleranceRad, "replayed orientations within 1e-4 rad of the host's");
  golden_cases_checked = 0;
  worst_position_mm = 0;
  worst_orientation_rad = 0;
}

// The end of the peer's work since its last release (the period's, and
// whatever it prepared after it for the next): in time, or counted late.
void finish_work() {
  if (periods_run == 0) return;
  const std::int64_t work_ns = peer_clock.now_ns() - period_release_ns;
  if (work_ns > longest_period_work_ns) longest_period_work_ns = work_ns;
  if (work_ns > kPeerWorkLimitNs) periods_late += 1;
}

// The start of a period: waits for its release, a turn at a time. The
// peer is at work (peer_working) everywhere but in this wait.
void begin_period() {
  finish_work();
  peer_working = 0;
  for (;;) {
    const std::int64_t now_ns = peer_clock.now_ns();
    if (now_ns >= next_release_ns) break;
    peer_turns = peer_turns + 1;
    zynqmp::yield_to_other_core();
  }
  peer_working = 1;
  period_release_ns = next_release_ns;
  next_release_ns += kPeriodNs;
}

void end_period() { periods_run += 1; }

// The drives' part of a period: the runtime's frames taken (setpoints move
// the drives), then, unless silent, every drive's report.
void exchange_with_drives() {
  if (drives_report) {
    drives.exchange(drives_bus, [](const CanFrame& frame) { record(frame); });
  } else {
    take_runtime_frames();
  }
  settle_golden_case();
}

// One period: the drives' exchange and the update's share.
void period() {
  begin_period();
  exchange_with_drives();
  if (sender != nullptr) sender->pump(periods_run, peer, kUpdateFramesPerCycle);
  end_period();
}

// The host's cable sets, one a period; each pose checked once the frames
// of the cycle that received it are in (the next period, or the first of
// what follows the replay).
void replay_golden_cases(int rounds) {
  golden_cases_to_report = rounds * golden::kCases;
  for (int round = 0; round < rounds; ++round) {
    for (int c = 0; c < golden::kCases; ++c) {
      begin_period();
      take_runtime_frames();
      settle_golden_case();
      poses_before_golden_case = bus.pose_frames;
      cdcr::boards::mps2::deliver_cables(peer, c);
      pending_golden_case = c;
      end_period();
    }
  }
}

// The update's image: the board's with another creation time (the same
// model under another digest).
alignas(8) std::uint8_t updated_image[64 * 1024];

// What became of the planner's targets, on the bus.
struct TargetOutcomes {
  int sent = 0;
  int converged = 0;
  int final_reports = 0;             // their final IK_REPORT on the bus
  int setpoints_at_every_drive = 0;  // converged, and their setpoints reached every drive
  double worst_reached_mm = 0;       // how far from a converged target the pose ended
};

// What the scenario's steps hand on to each other: the planner's next
// sequence number, what became of its targets (checked once the streamed
// path is over), and the POSE_UNCERTAINTY frames by the end of the
// forward-only periods.
struct Scenario {
  std::uint8_t next_sequence = 0;
  TargetOutcomes targets;
  int uncertainty_frames_forward = 0;
};

bool final_report_for(int reports_before, std::uint8_t sequence) {
  return bus.ik_reports > reports_before && bus.ik_report.sequence == sequence;
}

// A target from the planner, then periods until its final IK_REPORT is on
// the bus, and two more: the setpoints reach the drives, the drives report
// the new lengths, and the runtime publishes the pose there. A converged
// target's setpoints must have reached every drive, and the pose must be
// at the target.
void solve(Scenario& scenario, const cdcr::model::Pose<float>& target, protocol::TargetMode mode) {
  const std::uint8_t sequence = scenario.next_sequence++;
  const int reports_before = bus.ik_reports;
  int setpoints_before[firmware::kMaxSegments];
  for (int s = 0; s < drives.segments; ++s) setpoints_before[s] = setpoint_frames[s];
  begin_period();
  deliver_target(peer, target, mode, false, sequence);
  exchange_with_drives();
  end_period();
  TargetOutcomes& targets = scenario.targets;
  targets.sent += 1;
  for (int spent = 1; !final_report_for(reports_before, sequence) && spent < firmware::kMaxIkCycles + 3; ++spent) {
    period();
  }
  period();
  period();
  if (!final_report_for(reports_before, sequence)) return;
  targets.final_reports += 1;
  if (bus.ik_report.outcome != protocol::IkOutcome::converged) return;
  targets.converged += 1;
  bool every_drive = true;
  for (int s = 0; s < drives.segments; ++s) every_drive = every_drive && setpoint_frames[s] > setpoints_before[s];
  targets.setpoints_at_every_drive += every_drive ? 1 : 0;
  double distance_sq = 0;
  for (int i = 0; i < 3; ++i) {
    const double d = bus.position_mm[i] - static_cast<double>(target.position_mm[i]);
    distance_sq += d * d;
  }
  const double reached_mm = std::sqrt(distance_sq);
  if (!(reached_mm <= targets.worst_reached_mm)) targets.worst_reached_mm = reached_mm;
}

// The peer's own work before the cycles start, which would otherwise take
// the periods' room: can1 started, the planner's model (the image the
// board carries, the same file) bound, and the update's image made.
// Returns the image's size.
std::uint32_t prepare_planner() {
  check(peer.controller.start(r5f::kCanTiming), "can1 starts at 1 Mbit/s");
  cdcr::model::ImageView image{};
  check(bind_board_image(planner_files, correction, image), "the image binds");
  print("model: ", image.training_points, " training points\n");
  drives.segments = geometry.segment_count;
  const cdcr::hal::MemoryRegion region = planner_files.model_storage.model_region();
  const std::uint32_t image_size = static_cast<std::uint32_t>(region.size_bytes);
  check(image_size <= sizeof(updated_image), "the image fits the update's buffer");
  if (failures == 0) copy_with_other_creation_time(region.data, image_size, updated_image);
  return image_size;
}

// Ready: the runtime starts its cycles a period from about now; the peer's
// first period comes half a period before the runtime's first.
void signal_ready() {
  next_release_ns = peer_clock.now_ns() + kPeriodNs / 2;
  peer_state = kPeerReady;
}

// The drives start where golden case 0 has them; forward-only periods,
// with POSE_UNCERTAINTY on the bus.
void forward_only_periods(Scenario& scenario) {
  for (int s = 0; s < drives.segments; ++s) {
    for (int k = 0; k < 4; ++k) drives.lengths_mm[s][k] = float(golden::kCablesMm[0][4 * s + k]);
  }
  const int uncertainty_after_replay = bus.uncertainty_frames;
  for (int i = 0; i < 200; ++i) period();
  scenario.uncertainty_frames_forward = bus.uncertainty_frames;
  check(bus.uncertainty_frames > uncertainty_after_replay, "POSE_UNCERTAINTY on the bus between targets");
  check(bus.uncertainty.r95_position_mm > 0 && bus.uncertainty.r95_position_mm < 65,
        "the r95 position radius is a length");
}

// Targets in the paper's workspace, pose and position, one in eight
// unreachable.
void paper_workspace_targets(Scenario& scenario) {
  for (int t = 0; t < 48; ++t) {
    if (t % 8 == 7) {
      cdcr::model::Pose<float> far;
      far.position_mm = cdcr::model::Vec3<float>(900.0f, 0.0f, 50.0f);
      solve(scenario, far, protocol::TargetMode::position);
    } else {
      const bool pose = t % 3 != 0;
      solve(scenario, reachable_target(random_numbers, correction, geometry, 0.2f),
            pose ? protocol::TargetMode::pose : protocol::TargetMode::position);
    }
  }
}

// A streamed path: a TRACKING target every period, the compensated tip
// of joints that move smoothly (reachable by construction). Then periods
// until the last one's final report is in, the first of 100 more.
void streamed_path(Scenario& scenario) {
  cdcr::model::JointVector<float> joints(2 * drives.segments);
  int reports_before_last = 0;
  std::uint8_t last_sequence = 0;
  for (int step = 0; step < 300; ++step) {
    for (int s = 0; s < drives.segments; ++s) {
      joints[2 * s] = 0.8f * float(s) + 0.004f * float(step);
      joints[2 * s + 1] = 0.12f + 0.05f * std::sin(0.01f * float(step) + float(s));
    }
    const cdcr::model::Pose<float> tip = compensated_tip(correction, geometry, joints);
    begin_period();
    reports_before_last = bus.ik_reports;
    last_sequence = scenario.next_sequence++;
    deliver_target(peer, tip, protocol::TargetMode::position, true, last_sequence);
    exchange_with_drives();
    end_period();
  }
  for (int i = 0; i < firmware::kMaxIkCycles + 2 && !final_report_for(reports_before_last, last_sequence); ++i) {
    period();
  }
  check(final_report_for(reports_before_last, last_sequence), "the streamed path's last target ends");
  for (int i = 1; i < 100; ++i) period();
}

// What became of the targets, on the bus.
void check_targets(const Scenario& scenario) {
  const TargetOutcomes& targets = scenario.targets;
  print("targets: ", targets.sent, " sent, ", targets.converged, " converged, ", targets.final_reports,
        " with their final IK_REPORT on the bus, ", targets.setpoints_at_every_drive,
        " converged with their setpoints at every drive; pose at the target within ");
  zynqmp::console_write_fixed(targets.worst_reached_mm, 4);
  print(" mm; POSE_UNCERTAINTY frames ", bus.uncertainty_frames, "\n");
  check(targets.final_reports == targets.sent, "every target's final IK_REPORT is on the bus");
  check(targets.converged >= targets.sent * 3 / 4, "most targets converge");
  check(targets.setpoints_at_every_drive == targets.converged, "every converged target's setpoints reach every drive");
  check(targets.worst_reached_mm <= 0.1, "the pose the drives' lengths give is within 0.1 mm of the converged target");
  check(bus.uncertainty_frames > scenario.uncertainty_frames_forward, "POSE_UNCERTAINTY while targets come and go");
  check_equal(static_cast<std::uint32_t>(reported_rejected_frames), 0, "STATS: no frame rejected before the faults");
}

// A model update over CAN, targets going on meanwhile. The runtime runs
// the image the board carries (no slot) before it, slot A after it.
void model_update(Scenario& scenario, firmware::UpdateSender& update) {
  const int update_start_period = periods_run;
  update.resend_after = 199;
  sender = &update;
  for (int i = 0; i < 8'000 && update.outcome() == firmware::UpdateSender::Outcome::running; ++i) {
    begin_period();
    if (i == 0) update.start(peer, periods_run);
    if (i % 40 == 0) {
      deliver_target(peer, reachable_target(random_numbers, correction, geometry, 0.2f), protocol::TargetMode::pose,
                     false, scenario.next_sequence++);
    }
    exchange_with_drives();
    sender->pump(periods_run, peer, kUpdateFramesPerCycle);
    end_period();
  }
  for (int i = 0; i < 20; ++i) period();
  sender = nullptr;
  const bool committed = update.outcome() == firmware::UpdateSender::Outcome::committed;
  print("model update: ", update.total_blocks(), " blocks, ", update.frames_sent(), " frames, ", update.rewinds(),
        " rewinds, ", update.restarts(), " restarts over ", periods_run - update_start_period, " cycles; outcome ",
        committed ? "committed" : "not committed", "; UPDATE_REPORT: state ",
        static_cast<int>(last_update_report.state), ", active slot ", last_update_report.active_slot,
        "; STATUS state ", bus.reported_state, "\n");
  check(committed, "the model update commits");
  check(last_update_report.state == protocol::UpdateState::committed && last_update_report.active_slot == kWireSlotA,
        "UPDATE_REPORT: the runtime switched to the new model in slot A");
  check(bus.reported_state == static_cast<int>(RuntimeState::run), "STATUS: the runtime runs the new model");
}

// A foreign identifier the acceptance filters keep out, and a cable frame
// of the wrong length: rejected, counted, nothing else.
void bad_frames() {
  begin_period();
  CanFrame foreign;
  foreign.id = 0x7F0;
  foreign.dlc = 8;
  peer.deliver(foreign);
  CanFrame short_cable;
  protocol::encode(protocol::CableFeedback{0, {150, 150, 150, 150}}, short_cable);
  short_cable.dlc = 3;
  peer.deliver(short_cable);
  exchange_with_drives();
  end_period();
  for (int i = 0; i < 19; ++i) period();
  print("bad frames: STATS rejected ", static_cast<std::int32_t>(reported_rejected_frames), "; STATUS state ",
        bus.reported_state, "\n");
  check_equal(static_cast<std::uint32_t>(reported_rejected_frames), 1,
              "STATS: the short cable frame is rejected and counted, the foreign identifier has no effect");
  check(bus.reported_state == static_cast<int>(RuntimeState::run), "STATUS: bad frames leave the runtime in RUN");
}

// A flood: more frames in one period than the controller's RX FIFO and
// the driver's ring hold together. The overflow's count is the runtime's
// core's to check.
void flood() {
  const std::int64_t overruns_before_flood = reported_overruns;
  const int poses_before_flood = bus.pose_frames;
  begin_period();
  exchange_with_drives();
  for (std::size_t i = 0; i < zynqmp::kXilinxCanFifoFrames + 40; ++i) {
    CanFrame frame;
    const int s = int(i % drives.segments);
    protocol::encode(protocol::CableFeedback{s, {drives.lengths_mm[s][0], drives.lengths_mm[s][1],
                                                 drives.lengths_mm[s][2], drives.lengths_mm[s][3]}},
                     frame);
    peer.deliver(frame);
  }
  end_period();
  for (int i = 0; i < 50; ++i) period();
  print("flood: ", zynqmp::kXilinxCanFifoFrames + 40, " frames in one period; STATUS releases missed ",
        static_cast<std::int32_t>(reported_overruns - overruns_before_flood), ", poses since ",
        bus.pose_frames - poses_before_flood, " frames; state ", bus.reported_state, "\n");
  check_equal(static_cast<std::uint32_t>(reported_overruns - overruns_before_flood), 0,
              "STATUS: no release missed in the flood");
  check(bus.pose_frames - poses_before_flood >= 3 * 50, "poses go on through the flood");
  check(bus.reported_state == static_cast<int>(RuntimeState::run), "STATUS: the flood leaves the runtime in RUN");
}

// The drives go silent, then come back.
void silent_drives() {
  drives_report = false;
  for (int i = 0; i < 3 * firmware::kStaleInputCycles; ++i) period();
  print("drives silent: STATUS state ", bus.reported_state, ", fault ", bus.reported_fault, "\n");
  check(bus.reported_state == static_cast<int>(RuntimeState::fault), "STATUS reports FAULT once the drives are silent");
  check(bus.reported_fault == static_cast<int>(FaultCode::cable_input_stale), "STATUS reports stale cable input");
  drives_report = true;
  for (int i = 0; i < 3 * firmware::kStatusEveryCycles; ++i) period();
  print("drives back: STATUS state ", bus.reported_state, "\n");
  check(bus.reported_state == static_cast<int>(RuntimeState::run), "STATUS reports RUN once the drives are back");
}

// Periods until 2,000 have run, then the peer's own figures.
void finish_scenario() {
  while (periods_run < 2000) period();
  finish_work();
  print("peer: ", periods_run, " periods on the second core, the longest's work ",
        static_cast<std::int32_t>(longest_period_work_ns / 1000), " us (limit ",
        static_cast<std::int32_t>(kPeerWorkLimitNs / 1000), "), ", peer_turns, " turns waiting\n");
  check_equal(periods_late, 0, "peer periods whose work ran past the limit");
  check_equal(static_cast<std::uint32_t>(reported_overruns), 0, "STATUS: releases missed");
  check_equal(peer.refused, 0, "frames can1 could not send");
}

// The peer's scenario; its checks counted in checks.hpp's failures.
void run_peer() {
  const std::uint32_t image_size = prepare_planner();
  if (failures != 0) return;
  // The update's digest, made before the cycles start as its image is.
  firmware::UpdateSender update(updated_image, image_size);
  Scenario scenario;
  signal_ready();
  // 1. The host's cable sets, one a cycle, four rounds.
  replay_golden_cases(4);
  // 2. The mixed workload.
  forward_only_periods(scenario);
  paper_workspace_targets(scenario);
  streamed_path(scenario);
  check_targets(scenario);
  // 3. A model update; the new model's poses are the host's, as before it.
  model_update(scenario, update);
  replay_golden_cases(1);
  // 4. Bus faults.
  bad_frames();
  flood();
  silent_drives();
  finish_scenario();
}

}  // namespace

// The second core: the peer, from the runtime's first cycle to the end of
// the scenario; then its verdict to the runtime's core, and park.
extern "C" void cdcr_zynqmp_second_core_main() {
  peer_working = 1;
  peer_clock.enable();
  run_peer();
  peer_failures = static_cast<std::uint32_t>(failures);
  peer_working = 0;
  peer_state = kPeerDone;
}

int main() {
  zynqmp::console_write(
      "zynqmp workload: the runtime with a trained image on can0 (first R5F core), drives and planner on can1 "
      "(second core)\n");
  check(board.start_can(), "can0 starts at 1 Mbit/s");
  const RuntimeState boot = runtime.init();
  check(boot == RuntimeState::run, "the trained image boots into RUN");
  check(runtime.can_filters_accepted(), "the controller takes the runtime's acceptance filters");
  check(runtime.model_update().enabled(), "model updates are enabled with the flash region");
  print("runtime: IK work per cycle ", runtime.ik_units_per_cycle(), " units\n");
  if (failures != 0) return verdict();

  // The peer prepares; the cycles start when it is ready (or has failed).
  // The shared words start cleared whatever the RAM held (the start-up
  // leaves .core_shared alone).
  peer_state = kPeerPreparing;
  peer_failures = 0;
  peer_turns = 0;
  peer_working = 0;
  zynqmp::release_second_core();
  while (peer_state == kPeerPreparing) zynqmp::yield_to_other_core();
  board.start_cycles();
  const cdcr::hal::TimerTick no_tick{};
  counting_overhead = counted(no_tick, false);
  while (peer_state != kPeerDone && cycles_run < kMaxCycles) board.run_guarded(run_counted_cycle);

  // The console is this core's again; so is the check count, with the
  // peer's failures.
  failures = static_cast<int>(peer_failures);
  check(peer_state == kPeerDone, "the peer ends its scenario");
  if (over_budget != 0) {
    print("over budget: ", over_budget, " cycles, the first cycle ", first_over_budget_cycle, " with ",
          static_cast<std::uint32_t>(first_over_budget_instructions), " instructions\n");
  }
  print("peer turns inside a cycle: at most ", most_peer_turns_inside, ", in ", cycles_with_peer_turns, " of ",
        cycles_run, " cycles; cycles begun or ended with the peer at work: ", cycles_with_peer_working, "\n");
  print("runtime: RX FIFO overflows counted ", board.can.error_counters().rx_overruns, ", rejected frames ",
        runtime.statistics().rejected_frames, ", active slot ", runtime.model_update().active_slot(), ", state ",
        firmware::to_string(runtime.state()), "\n");
  print("worst cycle: ", worst_cycle, " instructions over ", cycles_run, " cycles (budget ",
        r5f::kCycleBudgetInstructions, ")\n");
  check(cycles_run >= 2000, "2,000 cycles or more");
  check_equal(over_budget, 0, "cycles over budget");
  check_equal(most_peer_turns_inside, 0,
              "peer turns inside a cycle (their instructions would count as the runtime's)");
  check_equal(cycles_with_peer_working, 0, "cycles begun or ended with the peer at a period's work");
  check_equal(board.timer.overruns(), 0, "releases missed");
  check(board.can.error_counters().rx_overruns >= 1, "the flood's RX FIFO overflow is counted");
  check(runtime.model_update().active_slot() == 0, "the runtime runs the new model from slot A");
  check(runtime.state() == RuntimeState::run, "the runtime ends in RUN");
  const cdcr::hal::CanErrorCounters counters = board.can.error_counters();
  check(counters.tx_dropped == 0 && counters.bus_errors == 0, "nothing dropped, no bus errors");
  return verdict();
}
