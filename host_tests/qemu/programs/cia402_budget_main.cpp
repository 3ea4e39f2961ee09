// The cycle budget with the CiA 402 backend linked in, on the board: the
// runtime takes its cable lengths from CiA 402 drives over CANopen
// (firmware/canopen's Cia402Drives as Hal::drives), one drive per cable of
// the golden robot, four on each of up to four mailbox buses, the drives
// written to CiA 301/402 in fixed memory (host_tests/support/
// cia402_test_drive.hpp). Every Runtime::run_cycle is counted in
// instructions (QEMU -icount, as cycle_budget_main), through:
//   boot       NMT reset, the drives' boot-up, the SDO configuration (18
//              writes a drive, a few a cycle), NMT start, enabling;
//   move       position and pose targets from the host's mailbox, solved by
//              the runtime and followed by the drives (RPDOs, SYNC, TPDOs);
//   fault      one drive's EMCY: FAULT drive_fault naming its node, every
//              other drive quick-stopped;
//   recover    the host's DRIVES_COMMAND: reset, configuration and enabling
//              again, then RUN.
// Prints the worst cycle of each phase and `worst cycle: N instructions over
// C cycles (budget B)`, and fails when a cycle exceeds the board's budget
// (80,000 instructions on the Cortex-M7, 120,000 on the Cortex-M4F), the
// drives do not reach RUN, a target does not converge or the drives do not
// hold its setpoints, or the fault is not reported with its node.

#include <algorithm>
#include <cmath>

#include <cdcr/cortexm/mailbox_can.hpp>
#include <cdcr/cortexm/semihosting.hpp>
#include <cdcr/firmware/canopen/cia402_drives.hpp>
#include <cdcr/firmware/runtime.hpp>

#include "board.hpp"
#include "cia402_test_drive.hpp"
#include "cycle_tally.hpp"
#include "golden_check.hpp"
#include "instruction_count.hpp"
#include "workload.hpp"

namespace {

namespace console = cdcr::cortexm;
namespace canopen = cdcr::firmware::canopen;
namespace hal = cdcr::hal;
using namespace cdcr::qemu_programs;  // the workload, and its model, firmware and protocol

constexpr int kDrivesPerBus = 4;
constexpr double kCountsPerMm = 1000.0;
constexpr int kFaultyDrive = 5;  // bus 1, node 2

// One drives' bus: the runtime's end is the mailbox, the drives' end
// delivers into it (no filters are set on a drives' bus).
using DrivesMailbox = cdcr::cortexm::MailboxCan<32>;
struct DrivesEnd final : hal::CanBus {
  DrivesMailbox* mailbox = nullptr;
  hal::CanStatus send(const hal::CanFrame& frame) override {
    mailbox->deliver(frame);
    return hal::CanStatus::ok;
  }
  hal::CanStatus receive(hal::CanFrame& frame) override {
    return mailbox->take_transmitted(frame) ? hal::CanStatus::ok : hal::CanStatus::empty;
  }
  bool set_filters(const hal::CanFilter*, std::size_t) override { return true; }
  hal::CanErrorCounters error_counters() const override { return {}; }
};

cdcr::boards::mps2::Board board;
const firmware::Geometry geometry = cdcr::boards::mps2::golden_geometry();
const int cables = geometry.cable_count();
const int buses = (cables + kDrivesPerBus - 1) / kDrivesPerBus;

DrivesMailbox mailboxes[firmware::kMaxDriveBuses];
DrivesEnd drive_ends[firmware::kMaxDriveBuses];
hal::CanBus* const runtime_ends[firmware::kMaxDriveBuses] = {&mailboxes[0], &mailboxes[1], &mailboxes[2],
                                                             &mailboxes[3]};
canopen::TestDrive drives[firmware::kMaxDrives];

// Cable i on bus i / 4, node i % 4 + 1; every other drive counts down as
// its cable lengthens; position 0 two millimetres short of the backbone.
canopen::DriveManagerConfig drives_config() {
  canopen::DriveManagerConfig config;
  config.drive_count = cables;
  config.bus_count = buses;
  config.timing = {1000, 500, 20};
  config.max_speed_mm_per_s = 200.0;
  for (int s = 0; s < geometry.segment_count; ++s) {
    for (int i = geometry.first_cable(s); i < geometry.first_cable(s + 1); ++i) {
      config.drives[i] = {std::uint8_t(i / kDrivesPerBus), canopen::NodeId(i % kDrivesPerBus + 1),
                          (i % 2 ? -1.0 : 1.0) * kCountsPerMm, double(geometry.segments[s].backbone_length_mm) - 2.0};
    }
  }
  return config;
}
const canopen::DriveManagerConfig config = drives_config();
canopen::Cia402Drives backend(config, runtime_ends);

hal::Hal hal_with_drives() {
  hal::Hal h = board.hal();
  h.drives = &backend;
  return h;
}
firmware::Runtime runtime(hal_with_drives(), geometry);
firmware::Correction correction;
cdcr::boards::mps2::InstructionCounter counter{board.timer};
CycleTally tally;
cdcr::qemu_programs::Random random_numbers{0x5EED402u};

enum Phase { kBoot, kMove, kFault, kRecover, kPhases };
constexpr const char* kPhaseNames[kPhases] = {"boot", "move", "fault", "recover"};
std::uint32_t worst_of[kPhases] = {};
std::uint32_t cycles_of[kPhases] = {};
Phase phase = kBoot;

protocol::IkReport last_report;
bool has_report = false;

// The drives' millisecond: every frame the manager sent, then their own.
void exchange_with_drives() {
  hal::CanFrame frame;
  for (int b = 0; b < buses; ++b) {
    while (drive_ends[b].receive(frame) == hal::CanStatus::ok) {
      for (int i = 0; i < cables; ++i)
        if (config.drives[i].bus == b) drives[i].take(frame, drive_ends[b]);
    }
    for (int i = 0; i < cables; ++i)
      if (config.drives[i].bus == b) drives[i].tick(drive_ends[b]);
  }
  // The host's side: its mailbox emptied, the IK reports kept.
  while (board.can.take_transmitted(frame)) {
    protocol::IkReport report;
    if (protocol::decode(frame, report) == protocol::DecodeStatus::ok &&
        report.outcome != protocol::IkOutcome::in_progress) {
      last_report = report;
      has_report = true;
    }
  }
}

void cycle() {
  exchange_with_drives();
  const std::uint32_t instructions = tally.run_counted(counter, board, runtime);
  worst_of[phase] = std::max(worst_of[phase], instructions);
  ++cycles_of[phase];
}

bool running() {
  return runtime.state() == firmware::RuntimeState::run && runtime.has_pose() &&
         runtime.drives_health().condition == hal::DrivesCondition::ready;
}

// Cycles until running, at most `limit`; false if not reached.
bool run_until_running(int limit) {
  for (int n = 0; n < limit; ++n) {
    cycle();
    if (running()) return true;
  }
  return false;
}

// A target from the host; true when it converged and every drive holds
// its setpoint (within a count) 600 cycles later.
bool move_to(const model::Pose<float>& target, protocol::TargetMode mode, std::uint8_t sequence) {
  has_report = false;
  cdcr::qemu_programs::deliver_target(board.can, target, mode, false, sequence);
  for (int n = 0; n < 600; ++n) cycle();
  if (!has_report || last_report.sequence != sequence || last_report.outcome != protocol::IkOutcome::converged) {
    console::console_write("FAIL: target did not converge, sequence ");
    console::console_write_int(sequence);
    console::console_write("\n");
    return false;
  }
  for (int i = 0; i < cables; ++i) {
    if (std::fabs(drives[i].position - double(drives[i].target)) > 1.0 || drives[i].statusword != 0x0237) {
      console::console_write("FAIL: drive of cable ");
      console::console_write_int(i);
      console::console_write(" not on its setpoint\n");
      return false;
    }
  }
  return true;
}

}  // namespace

int main() {
  for (int b = 0; b < firmware::kMaxDriveBuses; ++b) drive_ends[b].mailbox = &mailboxes[b];
  model::ImageView image;
  // The drives power up on the straight robot: every cable the backbone's
  // length, two millimetres from position 0.
  for (int i = 0; i < cables; ++i) {
    drives[i].node = config.drives[i].node;
    drives[i].position = 2.0 * config.drives[i].counts_per_mm;
  }
  if (buses > firmware::kMaxDriveBuses || !start_counting(board, runtime, correction, image)) return 1;
  console::console_write("CiA 402 drives: ");
  console::console_write_int(cables);
  console::console_write(" on ");
  console::console_write_int(buses);
  console::console_write(" buses\n");

  tally.expect_poses(false);
  bool ok = run_until_running(5000);
  if (!ok) console::console_write("FAIL: the drives did not reach RUN\n");
  tally.expect_poses(true);

  phase = kMove;
  for (int t = 0; ok && t < 4; ++t) {
    const model::Pose<float> target = cdcr::qemu_programs::reachable_target(random_numbers, correction, geometry, 0.6f);
    ok = move_to(target, t % 2 ? protocol::TargetMode::pose : protocol::TargetMode::position,
                 std::uint8_t(0x40 + t));
  }

  phase = kFault;
  drives[kFaultyDrive].fault(drive_ends[config.drives[kFaultyDrive].bus], 0x2310);
  for (int n = 0; n < 50; ++n) cycle();
  const bool reported = runtime.state() == firmware::RuntimeState::fault &&
                        runtime.active_fault() == firmware::FaultCode::drive_fault &&
                        runtime.active_fault_detail() == firmware::FaultDetail::drive(config.drives[kFaultyDrive].node);
  console::console_write(reported ? "EMCY: FAULT drive_fault, node " : "FAIL: EMCY not reported, node ");
  console::console_write_int(config.drives[kFaultyDrive].node);
  console::console_write("\n");
  ok = ok && reported;

  phase = kRecover;
  hal::CanFrame command;
  protocol::encode(protocol::DrivesCommand{}, command);
  board.can.deliver(command);
  const bool recovered = run_until_running(5000);
  console::console_write(recovered ? "recovered: RUN\n" : "FAIL: not recovered\n");
  ok = ok && recovered;
  for (int n = 0; n < 100; ++n) cycle();

  // What the drives cost a cycle apart from the rest (what the runtime
  // charges them, kWorkCosts.drive units each): the backend's calls of one
  // operational cycle, on the drives' frames of the last.
  exchange_with_drives();
  double lengths_mm[firmware::kMaxDrives];
  double setpoints_mm[firmware::kMaxDrives];
  const bool have_lengths = [&] {
    backend.receive();
    return backend.lengths(setpoints_mm, cables);
  }();
  exchange_with_drives();
  const std::uint32_t drives_instructions = counter.instructions([&] {
    backend.receive();
    backend.lengths(lengths_mm, cables);
    backend.command(setpoints_mm, cables);
    backend.transmit();
  });
  console::console_write("the drives' work: ");
  console::console_write_int(static_cast<std::int32_t>(drives_instructions));
  console::console_write(" instructions a cycle for ");
  console::console_write_int(cables);
  console::console_write(" drives (charged ");
  console::console_write_int(static_cast<std::int32_t>(firmware::kWorkCosts.drive));
  console::console_write(" units each)\n");
  ok = ok && have_lengths;

  cdcr::qemu_programs::report_phases(kPhaseNames, worst_of, cycles_of, kPhases);
  ok = tally.report() && ok;
  console::console_write(ok ? "PASS\n" : "FAIL\n");
  return ok ? 0 : 1;
}
