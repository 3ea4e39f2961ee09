#pragma once
// The runtime's frames as a peer on the bus sees them: the latest pose, its
// uncertainty, STATUS, STATS and IK_REPORT, decoded with the one codec. Shared by the board programs
// that check what the runtime sent (replay_main.cpp on the Cortex-M boards'
// mailbox bus, host_tests/zynqmp/programs/forward_path_main.cpp on the R5F's
// CAN controller).

#include <cdcr/firmware/fault.hpp>
#include <cdcr/firmware/fault_detail.hpp>
#include <cdcr/firmware/protocol.hpp>
#include <cdcr/hal/can_bus.hpp>

namespace cdcr::board_tests {

struct BusView {
  double position_mm[3] = {};
  double quaternion[4] = {1, 0, 0, 0};
  int pose_frames = 0;
  bool compensated_flag = false;
  int status_frames = 0;
  int reported_state = -1;
  int reported_fault = -1;
  firmware::FaultDetail reported_detail;
  int uncertainty_frames = 0;
  firmware::protocol::PoseUncertainty uncertainty;
  int ik_reports = 0;  // final ones; in-progress reports are counted apart
  int ik_progress_reports = 0;
  firmware::protocol::IkReport ik_report;  // the latest final one
};

// One frame the runtime sent; STATS follows the STATUS whose FAULT types its
// detail.
inline void record(BusView& bus, const hal::CanFrame& frame) {
  namespace protocol = firmware::protocol;
  protocol::PosePositionXy xy;
  protocol::PosePositionZ z;
  protocol::PoseOrientation orientation;
  protocol::Status status;
  protocol::Stats stats;
  protocol::PoseUncertainty uncertainty;
  protocol::IkReport ik_report;
  constexpr protocol::DecodeStatus ok = protocol::DecodeStatus::ok;
  if (protocol::decode(frame, xy) == ok) {
    bus.position_mm[0] = xy.x_mm;
    bus.position_mm[1] = xy.y_mm;
    bus.pose_frames += 1;
  } else if (protocol::decode(frame, z) == ok) {
    bus.position_mm[2] = z.z_mm;
    bus.compensated_flag = z.compensated;
    bus.pose_frames += 1;
  } else if (protocol::decode(frame, orientation) == ok) {
    bus.quaternion[0] = orientation.qw;
    bus.quaternion[1] = orientation.qx;
    bus.quaternion[2] = orientation.qy;
    bus.quaternion[3] = orientation.qz;
    bus.pose_frames += 1;
  } else if (protocol::decode(frame, status) == ok) {
    bus.reported_state = static_cast<int>(status.state);
    bus.reported_fault = static_cast<int>(status.fault);
    bus.status_frames += 1;
  } else if (protocol::decode(frame, uncertainty) == ok) {
    bus.uncertainty = uncertainty;
    bus.uncertainty_frames += 1;
  } else if (protocol::decode(frame, ik_report) == ok) {
    if (ik_report.outcome == protocol::IkOutcome::in_progress) {
      bus.ik_progress_reports += 1;
    } else {
      bus.ik_report = ik_report;
      bus.ik_reports += 1;
    }
  } else if (protocol::decode(frame, static_cast<firmware::FaultCode>(bus.reported_fault), stats) == ok) {
    bus.reported_detail = stats.fault_detail;
  }
}

}  // namespace cdcr::board_tests
