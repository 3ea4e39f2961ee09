// The runtime on the R5F with the CAN driver in the loop (zynqmp.forward_path):
// can1, on the same emulated bus, plays the drives. Each 1 ms cycle it sends
// one cable frame per segment; the runtime receives them through can0,
// runs the forward path and publishes the pose; can1 receives the POSE
// frames and STATUS. No model image is linked, so the runtime boots into
// DEGRADED (image missing) and publishes the nominal poses. Every pose
// decoded from the bus must be the runtime's own, within the frames'
// rounding; then the drives go silent and STATUS must turn to FAULT
// (stale input).
//
// The test runs it under -icount shift=0: one instruction advances QEMU's
// virtual clock by 1 ns, and the cycle counter counts 1 GHz of it, so the
// counter counts instructions; no release may be missed, and the costliest
// cycle is printed as `worst cycle: N instructions over C cycles`.

#include <cmath>
#include <cstdint>

#include <cdcr/firmware/protocol.hpp>
#include <cdcr/firmware/runtime.hpp>
#include <cdcr/zynqmp/console.hpp>
#include <cdcr/zynqmp/xilinx_can_controller.hpp>

#include "board.hpp"
#include "bus_view.hpp"
#include "checks.hpp"
#include "counted_cycle.hpp"

namespace {

namespace protocol = cdcr::firmware::protocol;
namespace zynqmp = cdcr::zynqmp;
using namespace cdcr::zynqmp_checks;  // check, check_equal, verdict
using namespace cdcr::board_tests;  // BusView, record
using cdcr::firmware::FaultCode;
using cdcr::firmware::RuntimeState;

constexpr int kCycles = 300;
// What the pose frames round to: 0.01 mm steps, quaternion components in
// 1/32767 steps (a rotation matrix element moves by at most about 4 steps).
constexpr double kBusPositionToleranceMm = 0.0051;
constexpr double kBusRotationTolerance = 4.0 / 32767.0;

cdcr::boards::zcu102_r5f::Board board;
cdcr::firmware::Runtime runtime(board.hal(), cdcr::firmware::Geometry::prototype());
zynqmp::XilinxCanController drives{zynqmp::kCan1Base};

// Everything the runtime sent, as the drives' controller received it.
void drain(BusView& bus) {
  cdcr::hal::CanFrame frame;
  while (drives.receive(frame)) record(bus, frame);
}

// One cable set per cycle: every segment bent about its own axis by an
// amount that changes from cycle to cycle (opposite cables lengthen and
// shorten alike, as the backbone's constant length requires).
void send_cables(int cycle) {
  const int segments = cdcr::model::kPrototypeSegmentCount;
  for (int s = 0; s < segments; ++s) {
    const double bend_mm = 3.0 * std::sin(0.05 * cycle + 0.7 * s);
    const double twist_mm = 2.0 * std::cos(0.03 * cycle + 1.1 * s);
    const double length_mm = cdcr::model::kPrototypeBackboneLengthMm;
    const protocol::CableFeedback feedback{
        s, {length_mm + bend_mm, length_mm + twist_mm, length_mm - bend_mm, length_mm - twist_mm}};
    cdcr::hal::CanFrame frame;
    check(protocol::encode(feedback, frame), "a cable frame encodes");
    check(drives.transmit(frame) == cdcr::hal::CanStatus::ok, "the drives' controller sends a cable frame");
  }
}

// The largest differences between the pose on the bus and the runtime's.
struct Deviation {
  double position_mm = 0;
  double rotation = 0;
};

void compare(const BusView& bus, Deviation& worst) {
  const cdcr::model::Pose<float>& pose = runtime.latest_pose().pose;
  for (int i = 0; i < 3; ++i) {
    const double d = std::fabs(bus.position_mm[i] - static_cast<double>(pose.position_mm[i]));
    if (!(d <= worst.position_mm)) worst.position_mm = d;
  }
  const double* q = bus.quaternion;
  const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  const Eigen::Matrix3d rotation =
      Eigen::Quaterniond(q[0] / n, q[1] / n, q[2] / n, q[3] / n).toRotationMatrix();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      const double d = std::fabs(rotation(r, c) - static_cast<double>(pose.rotation(r, c)));
      if (!(d <= worst.rotation)) worst.rotation = d;
    }
  }
}

void write_micro(double value) {
  zynqmp::console_write_int(static_cast<std::int32_t>(value * 1e6 + 0.5));
}

}  // namespace

int main() {
  zynqmp::console_write("zynqmp forward path: the runtime on can0, the drives on can1\n");
  check(board.start_can(), "can0 starts at 1 Mbit/s");
  check(drives.start(cdcr::boards::zcu102_r5f::kCanTiming), "can1 starts at 1 Mbit/s");

  const RuntimeState state = runtime.init();
  print("boot: state ", cdcr::firmware::to_string(state), ", fault ", cdcr::firmware::to_string(runtime.boot_fault()),
        "\n");
  check(state == RuntimeState::degraded, "no image linked: DEGRADED");
  check(runtime.boot_fault() == FaultCode::image_missing, "no image linked: image missing");
  check(runtime.can_filters_accepted(), "the controller takes the runtime's acceptance filters");

  board.timer.start(cdcr::boards::zcu102_r5f::kCyclePeriodNs);
  BusView bus;
  Deviation worst;
  int poses_compared = 0;
  std::uint64_t worst_cycle_counts = 0;
  for (int cycle = 0; cycle < kCycles; ++cycle) {
    const cdcr::hal::TimerTick tick = board.timer.wait_next();
    send_cables(cycle);
    const std::uint64_t cycle_counts = counted_run_cycle(board.timer, runtime, tick);
    if (cycle_counts > worst_cycle_counts) worst_cycle_counts = cycle_counts;
    const int pose_frames_before = bus.pose_frames;
    drain(bus);
    check(bus.pose_frames == pose_frames_before + 3, "a pose on the bus for every complete cable set");
    check(runtime.has_pose() && !runtime.latest_pose().compensated, "a nominal pose in DEGRADED");
    compare(bus, worst);
    poses_compared += 1;
  }
  print("poses: ", poses_compared, " cycles; largest difference bus - runtime: ");
  write_micro(worst.position_mm);
  zynqmp::console_write(" nm position, ");
  write_micro(worst.rotation);
  print(" ppm rotation\n", "worst cycle: ", worst_cycle_counts, " instructions over ", kCycles, " cycles\n");
  check(worst_cycle_counts < static_cast<std::uint64_t>(cdcr::boards::zcu102_r5f::kCyclePeriodNs),
        "every cycle within its 1 ms period");
  check(board.timer.overruns() == 0, "no release missed");
  check(worst.position_mm <= kBusPositionToleranceMm, "the pose's position on the bus is the runtime's");
  check(worst.rotation <= kBusRotationTolerance, "the pose's orientation on the bus is the runtime's");
  check(bus.status_frames >= kCycles / cdcr::firmware::kStatusEveryCycles, "STATUS every kStatusEveryCycles");
  check(bus.reported_state == static_cast<int>(RuntimeState::degraded), "STATUS reports DEGRADED");
  check(bus.reported_fault == static_cast<int>(FaultCode::image_missing), "STATUS reports the missing image");
  check(runtime.statistics().rejected_frames == 0, "no cable frame rejected");

  // The drives go silent: stale input, FAULT on the bus.
  for (int cycle = 0; cycle < 3 * cdcr::firmware::kStaleInputCycles; ++cycle) {
    runtime.run_cycle(board.timer.wait_next());
    drain(bus);
  }
  print("drives silent: STATUS state ", bus.reported_state, ", fault ", bus.reported_fault, "\n");
  check(bus.reported_state == static_cast<int>(RuntimeState::fault), "STATUS reports FAULT once the drives are silent");
  check(bus.reported_fault == static_cast<int>(FaultCode::cable_input_stale), "STATUS reports stale cable input");

  const cdcr::hal::CanErrorCounters counters = board.can.error_counters();
  print("can0: ", counters.tx_dropped, " dropped, ", counters.rx_overruns, " overruns, ", counters.bus_errors,
        " bus errors; ", board.timer.overruns(), " releases missed\n");
  check(counters.tx_dropped == 0 && counters.rx_overruns == 0 && counters.bus_errors == 0, "a clean bus");

  return verdict();
}
