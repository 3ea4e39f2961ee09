// The runtime on the board, replaying the host's golden cases through the
// CAN mailbox one cycle each, as the drives would send them. With the image
// intact it must boot into RUN and publish the compensated poses the host
// computed in double; with a corrupted image (kExpectDegradedBoot) it
// must boot into DEGRADED, report the image fault on the bus and publish the
// nominal poses. Prints what it saw and PASS or FAIL; the exit status says
// the same to ctest.

#include <cdcr/cortexm/semihosting.hpp>
#include <cdcr/cortexm/stack_watermark.hpp>
#include <cdcr/firmware/runtime.hpp>

#include "board.hpp"
#include "bus_view.hpp"
#include "golden_check.hpp"
#include "program_expectation.hpp"

namespace {

namespace golden = cdcr::qemu_golden;
namespace protocol = cdcr::firmware::protocol;
namespace console = cdcr::cortexm;
using namespace cdcr::board_tests;  // BusView, record
using cdcr::firmware::FaultCode;
using cdcr::firmware::RuntimeState;

const bool kExpectDegraded = cdcr::qemu_programs::kExpectDegradedBoot;
const RuntimeState kExpectedState = kExpectDegraded ? RuntimeState::degraded : RuntimeState::run;
const FaultCode kExpectedFault = kExpectDegraded ? FaultCode::image_invalid : FaultCode::none;

// Float32 fidelity: the float path against the host's double path.
constexpr double kPositionToleranceMm = 0.01;
constexpr double kOrientationToleranceDeg = 0.001;
// What the pose frames add: 0.01 mm and 1/32767 quaternion steps.
constexpr double kBusPositionToleranceMm = kPositionToleranceMm + 0.0087;
constexpr double kBusOrientationToleranceDeg = 0.02;

cdcr::boards::mps2::Board board;
cdcr::firmware::Runtime runtime(board.hal(), cdcr::boards::mps2::golden_geometry());
cdcr::firmware::Correction correction;
// The same correction on the plain C++ loops (model/arch/portable), whatever
// architecture code the build selected for the runtime.
cdcr::model::GpCorrection<cdcr::firmware::Scalar, cdcr::firmware::Accumulator, cdcr::firmware::kMaxSegments,
                          cdcr::model::arch::Portable>
    portable_correction;

// The GP mean with the architecture code the build selected (the assembly
// loop on the Cortex-M7, block loads on the Cortex-M4F), in the forward path
// and in the gradient pass, against the portable loop: the same operations
// in the same order, so the same bits.
int selected_and_portable_mean_differences() {
  const cdcr::hal::MemoryRegion region = board.model_storage.model_region();
  cdcr::model::ImageView image{};
  if (cdcr::model::parse_image(region.data, region.size_bytes, image, cdcr::model::ImageCapacity{}) !=
          cdcr::model::ImageStatus::ok ||
      correction.bind(image) != cdcr::model::Status::ok || portable_correction.bind(image) != cdcr::model::Status::ok) {
    return -1;
  }
  int differences = 0;
  for (int c = 0; c < golden::kCases; ++c) {
    cdcr::firmware::Joints joints(2 * golden::kSegments);
    for (int k = 0; k < joints.size(); ++k) joints[k] = golden::kJoints[c][k];
    const cdcr::firmware::Joints bend = cdcr::model::bend_from_joints(joints);
    const cdcr::model::Twist<float> selected = correction.predict(bend);
    const cdcr::model::Twist<float> portable = portable_correction.predict(bend);
    cdcr::model::Twist<float> gradient_pass;
    cdcr::model::Jacobian<float> gradient;
    correction.predict_with_gradient(bend, gradient_pass, gradient);
    for (int k = 0; k < 6; ++k) differences += selected[k] != portable[k] || gradient_pass[k] != portable[k];
  }
  return differences;
}

// Every frame the runtime sent, decoded.
void drain(BusView& bus) {
  cdcr::hal::CanFrame frame;
  while (board.can.take_transmitted(frame)) record(bus, frame);
}

// The pose as decoded from the bus, for the same comparison.
cdcr::model::Pose<float> pose_from_bus(const BusView& bus) {
  cdcr::model::Pose<float> pose;
  for (int i = 0; i < 3; ++i) pose.position_mm[i] = static_cast<float>(bus.position_mm[i]);
  const double* q = bus.quaternion;
  const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  pose.rotation = Eigen::Quaternion<float>(float(q[0] / n), float(q[1] / n), float(q[2] / n), float(q[3] / n))
                      .toRotationMatrix();
  return pose;
}

bool failed = false;

void check(bool condition, const char* what) {
  if (condition) return;
  console::console_write("FAIL: ");
  console::console_write(what);
  console::console_write("\n");
  failed = true;
}

void write_deviation(const char* label, const cdcr::boards::mps2::PoseDeviation& d) {
  console::console_write(label);
  console::console_write_fixed(d.position_mm, 6);
  console::console_write(" mm, ");
  console::console_write_fixed(d.orientation_deg, 6);
  console::console_write(" deg\n");
}

}  // namespace

int main() {
  console::paint_stack();
  cdcr::cortexm::attach_systick(board.timer);
  board.timer.start(cdcr::boards::mps2::kCyclePeriodNs);

  const RuntimeState state = runtime.init();
  console::console_write("boot: state ");
  console::console_write(cdcr::firmware::to_string(state));
  console::console_write(", fault ");
  console::console_write_int(static_cast<int>(runtime.boot_fault()));
  console::console_write(" (");
  console::console_write(cdcr::firmware::to_string(runtime.boot_fault()));
  console::console_write("), detail ");
  console::console_write_int(runtime.boot_fault_detail().wire_value());
  console::console_write("\n");
  check(state == kExpectedState, "unexpected state after boot");
  check(runtime.boot_fault() == kExpectedFault, "unexpected boot fault");
  if (kExpectDegraded) {
    check(runtime.boot_fault_detail() == cdcr::firmware::FaultDetail(cdcr::model::ImageStatus::checksum_mismatch),
          "the flipped byte was not caught by the checksum");
  }

  if (!kExpectDegraded) {
    const int differences = selected_and_portable_mean_differences();
    console::console_write("GP mean, the selected architecture code against the portable loop: ");
    console::console_write_int(differences);
    console::console_write(" differing outputs of ");
    console::console_write_int(6 * golden::kCases);
    console::console_write("\n");
    check(differences == 0, "the selected GP loop and the portable one disagree");
  }

  cdcr::boards::mps2::PoseDeviation worst, worst_bus;
  BusView bus;
  // Enough cycles for a STATUS frame to report the state on the bus.
  const int cycles = golden::kCases > cdcr::firmware::kStatusEveryCycles ? golden::kCases
                                                                         : cdcr::firmware::kStatusEveryCycles;
  for (int cycle = 0; cycle < cycles; ++cycle) {
    const int c = cycle % golden::kCases;
    const cdcr::hal::TimerTick tick = board.timer.wait_next();
    cdcr::boards::mps2::deliver_cables(board.can, c);
    runtime.run_cycle(tick);
    const int pose_frames_before = bus.pose_frames;
    drain(bus);
    check(bus.pose_frames == pose_frames_before + 3, "no pose published for a complete cable set");
    check(runtime.has_pose() && runtime.latest_pose().compensated == !kExpectDegraded,
          "pose missing or compensated in the wrong state");
    check(bus.compensated_flag == !kExpectDegraded, "pose frame's compensated flag is wrong");

    const cdcr::model::Pose<double> expected =
        kExpectDegraded
            ? cdcr::boards::mps2::golden_pose<double>(golden::kNominalPositionMm[c], golden::kNominalRotation[c])
            : cdcr::boards::mps2::golden_pose<double>(golden::kCompensatedPositionMm[c], golden::kCompensatedRotation[c]);
    const auto d = cdcr::boards::mps2::deviation(runtime.latest_pose().pose, expected);
    const auto b = cdcr::boards::mps2::deviation(pose_from_bus(bus), expected);
    if (!(d.position_mm <= worst.position_mm)) worst.position_mm = d.position_mm;
    if (!(d.orientation_deg <= worst.orientation_deg)) worst.orientation_deg = d.orientation_deg;
    if (!(b.position_mm <= worst_bus.position_mm)) worst_bus.position_mm = b.position_mm;
    if (!(b.orientation_deg <= worst_bus.orientation_deg)) worst_bus.orientation_deg = b.orientation_deg;
  }

  console::console_write(kExpectDegraded ? "nominal" : "compensated");
  console::console_write(" poses, ");
  console::console_write_int(cycles);
  console::console_write(" cycles over ");
  console::console_write_int(golden::kCases);
  console::console_write(" golden cases\n");
  write_deviation("  largest deviation from the host, runtime pose: ", worst);
  write_deviation("  largest deviation from the host, decoded from the bus: ", worst_bus);
  check(worst.position_mm <= kPositionToleranceMm, "position beyond the float32 fidelity target");
  check(worst.orientation_deg <= kOrientationToleranceDeg, "orientation beyond the float32 fidelity target");
  check(worst_bus.position_mm <= kBusPositionToleranceMm, "position on the bus beyond tolerance");
  check(worst_bus.orientation_deg <= kBusOrientationToleranceDeg, "orientation on the bus beyond tolerance");

  console::console_write("bus: STATUS state ");
  console::console_write_int(bus.reported_state);
  console::console_write(", fault ");
  console::console_write_int(bus.reported_fault);
  console::console_write(", detail ");
  console::console_write_int(bus.reported_detail.wire_value());
  console::console_write("\n");
  check(bus.status_frames > 0, "no STATUS frame");
  check(bus.reported_state == static_cast<int>(kExpectedState), "STATUS reports the wrong state");
  check(bus.reported_fault == static_cast<int>(kExpectedFault), "STATUS reports the wrong fault");
  check(bus.reported_detail == runtime.boot_fault_detail(), "STATS reports the wrong fault detail");
  check(runtime.statistics().rejected_frames == 0, "frames were rejected");

  console::console_write("stack: ");
  console::console_write_int(static_cast<int>(console::stack_used_bytes()));
  console::console_write(" of ");
  console::console_write_int(static_cast<int>(console::stack_reserved_bytes()));
  console::console_write(" bytes used\n");
  check(console::stack_used_bytes() < console::stack_reserved_bytes(), "stack reservation exhausted");

  console::console_write(failed ? "FAIL\n" : "PASS\n");
  return failed ? 1 : 0;
}
