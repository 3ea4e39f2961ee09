// The runtime with CiA 402 drives on the R5F's CAN controller
// (zynqmp.cia402): the CiA 402 backend (firmware/canopen, Hal::drives) on
// can0 through the Xilinx CAN driver at 1 Mbit/s, the trained image the
// Cortex-M boards carry, one drive per cable (16) on that bus, node ids 1
// to 16. can1, on the same emulated bus, plays the drives: the ones the
// host tests and the MPS2 boards' budget use (host_tests/support/
// cia402_test_drive.hpp), driven from this core between the runtime's
// cycles. QEMU's machine has two controllers on one bus and the drives
// need one, so here the runtime's drives are on can0 and its host's bus
// carries nothing; the deployable program has its drives on can1.
//   boot     NMT reset, boot-up, the SDO configuration, NMT start, enabling;
//            then RUN with the pose of the drives' positions
//   move     four targets (position and pose, given by call): each
//            converged, and the drives on their setpoints
//   fault    a drive's EMCY: FAULT drive_fault naming its node
//   recover  Runtime::recover_drives, and RUN again
// Under -icount shift=0 the cycle counter counts instructions: every
// Runtime::run_cycle is held to the board's budget (250,000), the worst
// printed as `worst cycle: N instructions over C cycles`.

#include <cmath>
#include <cstdint>

#include <cdcr/firmware/canopen/cia402_drives.hpp>
#include <cdcr/firmware/runtime.hpp>
#include <cdcr/zynqmp/console.hpp>
#include <cdcr/zynqmp/xilinx_can_controller.hpp>

#include "board.hpp"
#include "checks.hpp"
#include "counted_cycle.hpp"
#include "cia402_test_drive.hpp"
#include "golden_check.hpp"
#include "peer_workload.hpp"

namespace {

namespace canopen = cdcr::firmware::canopen;
namespace firmware = cdcr::firmware;
namespace hal = cdcr::hal;
namespace model = cdcr::model;
namespace protocol = cdcr::firmware::protocol;
namespace zynqmp = cdcr::zynqmp;
using namespace cdcr::zynqmp_checks;  // check, print, verdict, counted_run_cycle
using firmware::RuntimeState;

constexpr double kCountsPerMm = 1000.0;
constexpr int kFaultyDrive = 9;

// The runtime's host bus in this test: nothing on it.
struct QuietBus final : hal::CanBus {
  hal::CanStatus send(const hal::CanFrame&) override { return hal::CanStatus::ok; }
  hal::CanStatus receive(hal::CanFrame&) override { return hal::CanStatus::empty; }
  bool set_filters(const hal::CanFilter*, std::size_t) override { return true; }
  hal::CanErrorCounters error_counters() const override { return {}; }
};

// can1 as the drives' side of the bus.
struct DrivesSide final : hal::CanBus {
  zynqmp::XilinxCanController controller{zynqmp::kCan1Base};
  std::uint32_t refused = 0;
  hal::CanStatus send(const hal::CanFrame& frame) override {
    const hal::CanStatus status = controller.transmit(frame);
    if (status != hal::CanStatus::ok) ++refused;
    return status;
  }
  hal::CanStatus receive(hal::CanFrame& frame) override {
    return controller.receive(frame) ? hal::CanStatus::ok : hal::CanStatus::empty;
  }
  bool set_filters(const hal::CanFilter* filters, std::size_t count) override {
    return controller.set_filters(filters, count);
  }
  hal::CanErrorCounters error_counters() const override { return {}; }
};

cdcr::boards::zcu102_r5f::Board board;
QuietBus host;
DrivesSide peer;
const firmware::Geometry geometry = cdcr::boards::mps2::golden_geometry();
const int cables = geometry.cable_count();
canopen::TestDrive drives[firmware::kMaxDrives];

canopen::DriveManagerConfig drives_config() {
  canopen::DriveManagerConfig config;
  config.drive_count = cables;
  config.bus_count = 1;
  config.timing = {1000, 500, 20};
  config.max_speed_mm_per_s = 200.0;
  for (int s = 0; s < geometry.segment_count; ++s) {
    for (int i = geometry.first_cable(s); i < geometry.first_cable(s + 1); ++i) {
      config.drives[i] = {0, canopen::NodeId(i + 1), (i % 2 ? -1.0 : 1.0) * kCountsPerMm,
                          double(geometry.segments[s].backbone_length_mm) - 2.0};
    }
  }
  return config;
}
const canopen::DriveManagerConfig config = drives_config();
hal::CanBus* const drive_buses[firmware::kMaxDriveBuses] = {&board.can, nullptr, nullptr, nullptr};
canopen::Cia402Drives backend(config, drive_buses);

hal::Hal hal_with_drives() {
  hal::Hal h{board.timer, board.timer, host, board.model_storage, board.console};
  h.drives = &backend;
  return h;
}
firmware::Runtime runtime(hal_with_drives(), geometry);
firmware::Correction correction;
cdcr::qemu_programs::Random random_numbers{0x5EED402u};

std::uint64_t worst_counts = 0;
int cycles_run = 0;
int over_budget = 0;

// The drives' millisecond: every frame the runtime sent, then their own.
void exchange_with_drives() {
  hal::CanFrame frame;
  while (peer.receive(frame) == hal::CanStatus::ok)
    for (int i = 0; i < cables; ++i) drives[i].take(frame, peer);
  for (int i = 0; i < cables; ++i) drives[i].tick(peer);
}

void cycle() {
  const hal::TimerTick tick = board.timer.wait_next();
  exchange_with_drives();
  const std::uint64_t counts = counted_run_cycle(board.timer, runtime, tick);
  if (counts > worst_counts) worst_counts = counts;
  if (counts > cdcr::boards::zcu102_r5f::kCycleBudgetInstructions) ++over_budget;
  ++cycles_run;
}

bool running() {
  return runtime.state() == RuntimeState::run && runtime.has_pose() &&
         runtime.drives_health().condition == hal::DrivesCondition::ready;
}

int cycles_until_running(int limit) {
  for (int n = 1; n <= limit; ++n) {
    cycle();
    if (running()) return n;
  }
  return -1;
}

}  // namespace

int main() {
  zynqmp::console_write("zynqmp CiA 402: the runtime's drives on can0, 16 simulated drives on can1\n");
  check(board.start_can(), "can0 starts at 1 Mbit/s");
  check(peer.controller.start(cdcr::boards::zcu102_r5f::kCanTiming), "can1 starts at 1 Mbit/s");
  // The drives power up on the straight robot, two millimetres from 0.
  for (int i = 0; i < cables; ++i) {
    drives[i].node = config.drives[i].node;
    drives[i].position = 2.0 * config.drives[i].counts_per_mm;
  }
  const RuntimeState state = runtime.init();
  check(state == RuntimeState::run, "the trained image: RUN");
  model::ImageView image;
  check(cdcr::qemu_programs::bind_board_image(board, correction, image), "the image binds");
  board.timer.start(cdcr::boards::zcu102_r5f::kCyclePeriodNs);

  const int boot_cycles = cycles_until_running(5000);
  print("drives operational and RUN after ", boot_cycles, " cycles\n");
  check(boot_cycles > 0, "the drives reach RUN");

  for (int t = 0; t < 4 && boot_cycles > 0; ++t) {
    const model::Pose<float> target = cdcr::qemu_programs::reachable_target(random_numbers, correction, geometry, 0.6f);
    firmware::TargetRequest request;
    for (int k = 0; k < 3; ++k) request.position_mm[k] = double(target.position_mm[k]);
    const Eigen::Quaternionf q(target.rotation);
    request.quaternion[0] = q.w();
    request.quaternion[1] = q.x();
    request.quaternion[2] = q.y();
    request.quaternion[3] = q.z();
    request.mode = t % 2 ? protocol::TargetMode::pose : protocol::TargetMode::position;
    request.sequence = std::uint8_t(0x40 + t);
    runtime.set_target(request);
    for (int n = 0; n < 600; ++n) cycle();
    const bool converged = runtime.last_ik_report().sequence == request.sequence &&
                           runtime.last_ik_report().outcome == protocol::IkOutcome::converged;
    bool on_setpoints = true;
    for (int i = 0; i < cables; ++i)
      on_setpoints = on_setpoints && std::fabs(drives[i].position - double(drives[i].target)) <= 1.0 &&
                     drives[i].statusword == 0x0237;
    const double error_mm = double((runtime.latest_pose().pose.position_mm - target.position_mm).norm());
    print("target ", t, ": outcome ", int(runtime.last_ik_report().outcome), ", tip ",
          static_cast<std::int32_t>(error_mm * 1000.0 + 0.5), " um from it\n");
    check(converged, "the target converged");
    check(on_setpoints, "every drive on its setpoint");
    check(error_mm <= 0.05, "the pose of the drives' positions at the target");
  }

  drives[kFaultyDrive].fault(peer, 0x2310);
  for (int n = 0; n < 50; ++n) cycle();
  print("EMCY of node ", int(config.drives[kFaultyDrive].node), ": ", firmware::to_string(runtime.active_fault()),
        ", detail ", int(runtime.active_fault_detail().wire_value()), "\n");
  check(runtime.state() == RuntimeState::fault, "FAULT after the EMCY");
  check(runtime.active_fault() == firmware::FaultCode::drive_fault, "the fault is drive_fault");
  check(runtime.active_fault_detail() == firmware::FaultDetail::drive(config.drives[kFaultyDrive].node),
        "the fault names the drive's node");

  check(runtime.recover_drives(), "the drives take the recovery");
  const int recover_cycles = cycles_until_running(5000);
  print("recovered: RUN after ", recover_cycles, " cycles\n");
  check(recover_cycles > 0, "RUN again");
  for (int n = 0; n < 100; ++n) cycle();

  print("worst cycle: ", static_cast<std::uint32_t>(worst_counts), " instructions over ", cycles_run,
        " cycles (budget ", cdcr::boards::zcu102_r5f::kCycleBudgetInstructions, ")\n");
  check(over_budget == 0, "every cycle within the board's budget");
  check(board.timer.overruns() == 0, "no release missed");
  check(peer.refused == 0, "can1 queued every drive's frame");
  const hal::CanErrorCounters counters = board.can.error_counters();
  print("can0: ", counters.tx_dropped, " dropped, ", counters.rx_overruns, " overruns\n");
  check(counters.tx_dropped == 0 && counters.rx_overruns == 0, "can0 dropped nothing");
  return verdict();
}
