// The cycle budget during model updates, on the board: the runtime with a
// RAM flash of two slots (hal/cortexm's RamFlash) takes whole transfers over
// the mailbox bus while the drives keep sending cable lengths every cycle and
// pose targets keep IK busy, and every Runtime::run_cycle is counted in
// instructions (QEMU -icount, as cycle_budget_main):
//   1. the model storage's image (the golden model) into slot A: transfer,
//      COMMIT (hash, CRC and parse a slice a cycle), the switch to slot A;
//   2. a second image (the same model with another creation time, hence
//      another digest) into slot B, committed and switched to;
//   3. ROLLBACK to slot A: its hash, the revoke, the switch.
// Prints the worst cycle of each phase and `worst cycle: N instructions over
// C cycles (budget B)`, and fails when a cycle exceeds the board's budget
// (80,000 instructions on the Cortex-M7, 120,000 on the Cortex-M4F), a
// cycle in RUN publishes no pose, or an update does not end on the slot it
// should.

#include <algorithm>

#include <cdcr/cortexm/semihosting.hpp>
#include <cdcr/firmware/runtime.hpp>
#include <cdcr/firmware/sha256.hpp>
#include <cdcr/firmware/update/update_sender.hpp>

#include "board.hpp"
#include "cycle_tally.hpp"
#include "golden_check.hpp"
#include "instruction_count.hpp"
#include "workload.hpp"

namespace {

namespace console = cdcr::cortexm;
using namespace cdcr::qemu_programs;  // the workload, and its model, firmware and protocol

// A RAM flash of two slots (peer_workload.hpp).
cdcr::qemu_programs::UpdateFlash flash;
cdcr::boards::mps2::Board board;
firmware::Runtime runtime(cdcr::qemu_programs::hal_with_flash(board, flash), cdcr::boards::mps2::golden_geometry());
firmware::Correction correction;

cdcr::boards::mps2::InstructionCounter counter{board.timer};

// What the update's charges stand for on this core: 64 bytes of the
// verification pass (SHA-256 and the parser's scan), the most of 16 such.
void report_update_costs(const std::uint8_t* image, std::uint32_t size) {
  firmware::Sha256 hash;
  model::ImageScan scan;
  scan.begin(image, size);
  std::uint32_t most = 0;
  for (std::uint32_t at = 0; at + 64 <= 1024 && at + 64 <= size; at += 64) {
    most = std::max(most, counter.instructions([&] {
      hash.update(image + at, 64);
      scan.step(64);
    }));
  }
  console::console_write("update costs (instructions): 64 bytes hashed and scanned ");
  console::console_write_int(static_cast<std::int32_t>(most));
  console::console_write(" (charged ");
  console::console_write_int(static_cast<std::int32_t>(firmware::kUpdateHashUnitsPer64Bytes));
  console::console_write(" units)\n");
}

// The same workload on every run and both boards (workload.hpp).
cdcr::qemu_programs::Random random_numbers{0x9E3779B9u};
cdcr::qemu_programs::IdealDrives drives;
int& segments = drives.segments;

// The host's side of the mailbox: what the sender sends is delivered to
// the runtime; the runtime's reports reach the sender through exchange().
class HostSide final : public cdcr::hal::CanBus {
 public:
  cdcr::hal::CanStatus send(const cdcr::hal::CanFrame& frame) override {
    board.can.deliver(frame);
    return cdcr::hal::CanStatus::ok;
  }
  cdcr::hal::CanStatus receive(cdcr::hal::CanFrame&) override { return cdcr::hal::CanStatus::empty; }
  bool set_filters(const cdcr::hal::CanFilter*, std::size_t) override { return true; }
  cdcr::hal::CanErrorCounters error_counters() const override { return {}; }
};

HostSide host;
CycleTally tally;
// The transfer under way (firmware/update/update_sender.hpp, as `cdcr
// deploy` sends), silent for 200 cycles before it asks again.
firmware::UpdateSender* sender = nullptr;

// The ideal drives, and the runtime's reports to the sender.
void exchange() {
  drives.exchange(board.can, [](const cdcr::hal::CanFrame& frame) {
    if (sender != nullptr && protocol::update_report::kMessage.carries(frame.id)) {
      sender->on_report(frame, tally.cycles_run(), host);
    }
  });
}

// A pose target at random joints, through the runtime's compensated model.
std::uint8_t next_sequence = 0;
void deliver_target() {
  const model::Pose<float> target =
      cdcr::qemu_programs::reachable_target(random_numbers, correction, runtime.geometry(), 0.2f);
  cdcr::qemu_programs::deliver_target(board.can, target, protocol::TargetMode::pose, false, next_sequence++);
}

enum Phase { kTransfer, kCommit, kSwitch, kOther, kPhases };
const char* const kPhaseNames[kPhases] = {"transfer", "commit (hash, CRC, parse, header)", "switch", "other"};
std::uint32_t worst_of[kPhases] = {};
std::uint32_t cycles_of[kPhases] = {};
std::uint32_t switches = 0;

// One counted cycle: the drives' frames, the sender's (what the mailbox has
// room for beside them and a target's), a target every 40 cycles.
void cycle() {
  exchange();
  if (tally.cycles_run() % 40 == 0) deliver_target();
  if (sender != nullptr) sender->pump(tally.cycles_run(), host, 32 - segments - 3);
  const firmware::ModelUpdate& update = runtime.model_update();
  const protocol::UpdateState before = update.state();
  const int slot_before = update.active_slot();
  const std::uint32_t sequence_before = update.active_sequence();
  const std::uint32_t instructions = tally.run_counted(counter, board, runtime);
  Phase phase = kOther;
  if (update.active_slot() != slot_before || update.active_sequence() != sequence_before) {
    phase = kSwitch;
    ++switches;
  } else if (before == protocol::UpdateState::preparing || before == protocol::UpdateState::receiving) {
    phase = kTransfer;
  } else if (before == protocol::UpdateState::verifying) {
    phase = kCommit;
  }
  worst_of[phase] = std::max(worst_of[phase], instructions);
  cycles_of[phase] += 1;
  if (tally.among_first_over_budget(12)) {
    tally.print_over_budget(runtime, [&] {
      console::console_write(" (");
      console::console_write(kPhaseNames[phase]);
      console::console_write(", update state ");
      console::console_write_int(static_cast<std::int32_t>(before));
      console::console_write(")");
    });
    console::console_write("\n");
  }
}

// Cycles until the sender is done (committed and switched) or refused.
bool transfer(const std::uint8_t* image, std::uint32_t size, int expected_slot) {
  firmware::UpdateSender update(image, size);
  // pump() restarts after resend_after cycles without a report, and it
  // runs once a cycle: the 201st silent cycle.
  update.resend_after = 199;
  sender = &update;
  update.start(host, tally.cycles_run());
  for (int i = 0; i < 20'000 && update.outcome() == firmware::UpdateSender::Outcome::running; ++i) cycle();
  for (int i = 0; i < 20; ++i) cycle();
  sender = nullptr;
  const bool ok = update.outcome() == firmware::UpdateSender::Outcome::committed &&
                  runtime.model_update().active_slot() == expected_slot &&
                  runtime.state() == firmware::RuntimeState::run;
  console::console_write(ok ? "update into slot " : "FAIL: update into slot ");
  console::console_write_int(expected_slot);
  console::console_write(ok ? " committed and running\n" : " did not commit or does not run\n");
  return ok;
}

// The second image: the golden one with another creation time, so that its
// digest differs.
alignas(8) std::uint8_t second_image[64 * 1024];

}  // namespace

int main() {
  model::ImageView image{};
  if (!cdcr::qemu_programs::start_counting(board, runtime, correction, image)) return 1;
  const cdcr::hal::MemoryRegion region = board.model_storage.model_region();
  if (!runtime.model_update().enabled() || region.size_bytes > sizeof(second_image)) {
    console::console_write("FAIL: model updates are not enabled, or the image is larger than the second one's room\n");
    return 1;
  }
  segments = runtime.geometry().segment_count;
  counter.calibrate();
  for (int s = 0; s < segments; ++s) {
    for (int k = 0; k < 4; ++k) drives.lengths_mm[s][k] = float(cdcr::qemu_golden::kCablesMm[0][4 * s + k]);
  }
  const std::uint32_t size = static_cast<std::uint32_t>(region.size_bytes);
  console::console_write("image: ");
  console::console_write_int(static_cast<std::int32_t>(size));
  console::console_write(" bytes, ");
  console::console_write_int(static_cast<std::int32_t>(image.training_points));
  console::console_write(" training points\n");

  report_update_costs(region.data, size);

  cdcr::qemu_programs::copy_with_other_creation_time(region.data, size, second_image);

  for (int i = 0; i < 100; ++i) cycle();
  bool ok = transfer(region.data, size, 0);
  ok = transfer(second_image, size, 1) && ok;

  // Rollback to slot A: its hash a slice a cycle, the revoke, the switch.
  cdcr::hal::CanFrame frame;
  protocol::UpdateCommandFrame rollback;
  rollback.command = protocol::UpdateCommand::rollback;
  protocol::encode(rollback, frame);
  board.can.deliver(frame);
  for (int i = 0; i < 500 && runtime.model_update().active_slot() != 0; ++i) cycle();
  for (int i = 0; i < 20; ++i) cycle();
  const bool rolled_back = runtime.model_update().active_slot() == 0 && runtime.state() == firmware::RuntimeState::run;
  console::console_write(rolled_back ? "rollback to slot 0: running\n" : "FAIL: rollback to slot 0\n");
  ok = ok && rolled_back;

  cdcr::qemu_programs::report_phases(kPhaseNames, worst_of, cycles_of, kPhases);
  ok = tally.report() && ok;
  if (switches != 3) {
    console::console_write("FAIL: expected 3 switches\n");
    ok = false;
  }
  console::console_write(ok ? "PASS\n" : "FAIL\n");
  return ok ? 0 : 1;
}
