#pragma once
// A target's inverse kinematics over cycles: the request's start (from the
// last setpoints, the latest pose or the straight start; a streamed target
// warm, or continuing the streamed request before it), each cycle's slice of
// solver work, the extrapolation check of a solution and its one retry, the
// best points a streamed request sends on the way, and the end with its
// setpoints and IK_REPORT. All of it in static memory; the solver works on
// the compensated model in RUN, the nominal one in DEGRADED.

#include <cstdint>

#include "cdcr/firmware/hysteresis_tracker.hpp"
#include "cdcr/firmware/kinematics.hpp"
#include "cdcr/firmware/outbox.hpp"
#include "cdcr/firmware/protocol.hpp"
#include "cdcr/hal/drives.hpp"

namespace cdcr::firmware {

// A target as the runtime takes it, in the values the protocol carries
// (TARGET_ORIENTATION, TARGET_POSITION_XY, TARGET_POSITION_Z).
struct TargetRequest {
  double position_mm[3] = {};
  double quaternion[4] = {1, 0, 0, 0};  // w, x, y, z; pose mode only, normalised by the runtime
  protocol::TargetMode mode = protocol::TargetMode::position;
  bool tracking = false;
  bool refuse_extrapolating = false;
  std::uint8_t sequence = 0;
  // False: the commit frame, or a part the mode needs, did not decode; the
  // target is refused as malformed, answered with `sequence`.
  bool well_formed = true;
};

// The outcome of the last committed target, as IK_REPORT carries it.
struct IkReport {
  std::uint8_t sequence = 0;
  protocol::IkOutcome outcome = protocol::IkOutcome::converged;
  // Not on the bus: for an unreachable target, STATS FAULT_DETAIL carries it.
  model::Status model_status = model::Status::ok;
  int iterations = 0;
  int cycles = 0;  // cycles spent on the target, the one it arrived in included
  Scalar position_error_mm = 0;
  Scalar orientation_error_rad = 0;  // 0 for a position target
};

class IkRequest {
 public:
  // With `hysteresis` (an image with a hysteresis block) the solver finds
  // the effective cable lengths that reach the target, and the setpoints are
  // the commanded lengths that produce them from the cables' current state.
  IkRequest(const RobotModel& model, Outbox& outbox, const HysteresisTracker* hysteresis = nullptr)
      : model_(model), outbox_(outbox), hysteresis_(hysteresis) {}
  IkRequest(const IkRequest&) = delete;
  IkRequest& operator=(const IkRequest&) = delete;
  // Setpoints to a hal::Drives backend instead of CABLE_SETPOINT frames.
  void set_drives(hal::Drives* drives) { drives_ = drives; }

  // After the model is bound: the solver on it, within kMaxIk* bounds.
  void configure();

  // A target to solve, replacing the one in progress (superseded). Starts
  // from the last setpoints, else from `latest_pose` (may be null), else
  // straight. A start the solver refuses is reported unreachable at once.
  void start(const Pose& target, const TargetRequest& request, const PoseEstimate* latest_pose);
  // A target answered without solving it (malformed, wrong state).
  void refuse(std::uint8_t sequence, protocol::IkOutcome outcome);
  // A cycle's slice of at most `units` work units; returns those spent.
  std::uint32_t continue_slice(std::uint32_t units);
  // Ends the request in progress with `outcome` (superseded, aborted_fault).
  void end(protocol::IkOutcome outcome);

  bool running() const { return solving_; }
  const IkReport& report() const { return report_; }

  // Setpoint frames sent, final and best-so-far; the joints and lengths of
  // the last ones (valid once one was sent). With a compliance model the
  // joints are the solver's, of the sagged bends; the lengths those of the
  // commanded bends (commanded_joints).
  std::uint32_t setpoints_published() const { return setpoints_published_; }
  bool has_setpoints() const { return has_setpoints_; }
  const Joints& setpoint_joints() const { return setpoint_joints_; }
  const Cables& setpoints_mm() const { return setpoints_mm_; }

 private:
  void finish(model::IkSolveState end);
  bool begin_solution_check(const Joints& joints);
  std::uint32_t continue_solution_check(std::uint32_t units);
  void retry_or_refuse(const Joints& refused);
  void straight_start(Joints& joints) const;
  void conclude(bool reached, const Joints& joints);
  bool set_setpoints(const Joints& joints);
  bool publish_tracking_point(Solver& solver);
  void fill_report(protocol::IkOutcome outcome);
  void publish_setpoints();
  void publish_report();

  const RobotModel& model_;
  Outbox& outbox_;
  const HysteresisTracker* hysteresis_;
  hal::Drives* drives_ = nullptr;
  SolverCorrection solver_correction_{model_.correction, &model_.compliance, &model_.geometry};
  Solver solver_;
  // Where a target that refuses extrapolation prefers its solution
  // (ik_preference(); the others have none: see configure()).
  model::IkPreference<Scalar, kMaxSegments> preference_{};
  IkReport report_;
  bool solving_ = false;
  bool tracking_ = false;
  // The target refuses a solution where the model extrapolates: a solution
  // found is checked (input range, then the variance over a few cycles'
  // IK slices) before its setpoints go out.
  bool refuses_extrapolation_ = false;
  bool checking_solution_ = false;
  // Searches made since a solution was refused as extrapolating
  // (retry_or_refuse).
  int solution_retries_ = 0;
  Pose target_;
  Uncertainty::Evaluation solution_check_;
  Joints checked_joints_;
  protocol::TargetMode mode_ = protocol::TargetMode::position;
  std::uint8_t sequence_ = 0;
  int cycles_ = 0;
  // How the solver ended, when its end did not fit in that cycle's slice.
  model::IkSolveState end_ = model::IkSolveState::running;

  std::uint32_t setpoints_published_ = 0;
  bool has_setpoints_ = false;
  Cables setpoints_mm_;
  Joints setpoint_joints_;
  hal::CanFrame setpoint_frames_[kMaxSegments] = {};
  int setpoint_frame_count_ = 0;
};

}  // namespace cdcr::firmware
