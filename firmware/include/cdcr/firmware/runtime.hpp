#pragma once
// The fixed-rate runtime: one object, statically allocated, that owns every
// buffer it needs. init() is BOOT; run_cycle() is the whole per-cycle work.
//
// States (see fault.hpp):
//   BOOT -> RUN       the model image parses and binds: compensated kinematics.
//   BOOT -> DEGRADED  no usable image: nominal kinematics on the fallback
//                     geometry, the image's fault code reported in every STATUS.
//   RUN/DEGRADED -> FAULT  a segment's cable feedback silent, or no valid cable
//                          set, for more than kStaleInputCycles cycles.
//   FAULT -> RUN/DEGRADED  as soon as a valid cable set arrives again.
// In FAULT the runtime stops publishing poses and setpoints and refuses new
// targets; the drives keep the last setpoint they received (holding position
// is the drives' own behaviour on a silent bus), and STATUS keeps coming.
//
// Per cycle: drain up to kMaxRxFramesPerCycle frames (cable feedback, target
// frames), estimate the pose from the latest cable lengths, solve a committed
// target, publish, and measure execution time and start jitter on the HAL clock.
// Every frame goes through the codec in protocol.hpp.

#include <cstdint>

#include "cdcr/firmware/capacity.hpp"
#include "cdcr/firmware/fault.hpp"
#include "cdcr/firmware/fault_detail.hpp"
#include "cdcr/firmware/model_update.hpp"
#include "cdcr/firmware/protocol.hpp"
#include "cdcr/hal/hal.hpp"
#include "cdcr/model/compensated_kinematics.hpp"
#include "cdcr/model/flash_image.hpp"
#include "cdcr/model/gp_correction.hpp"
#include "cdcr/model/gp_uncertainty.hpp"
#include "cdcr/model/inverse_kinematics.hpp"

namespace cdcr::firmware {

// float kinematics; the GP sums in double where the FPU has it (host,
// Cortex-M7), in compensated float where it is single precision only
// (Cortex-M4F), where double arithmetic would be software (see
// gp_correction.hpp; `cdcr train` reports the fidelity of both).
using Scalar = float;
#if defined(__ARM_FP) && !(__ARM_FP & 0x8)
using Accumulator = model::CompensatedFloat;
#else
using Accumulator = double;
#endif
using Geometry = model::RobotGeometry<Scalar, kMaxSegments>;
using Cables = model::CableVector<Scalar, kMaxSegments>;
using Joints = model::JointVector<Scalar, kMaxSegments>;
using Correction = model::GpCorrection<Scalar, Accumulator, kMaxSegments>;
using Uncertainty = model::GpUncertainty<Scalar, Correction::kMaxInputs>;
using Pose = model::Pose<Scalar>;
// The correction as the IK solver sees it: the GP's evaluation in slices.
// Its functions are defined in runtime.cpp, beside the forward path, so the
// GP loops are compiled as the forward path's are wherever the solver is
// compiled (firmware/CMakeLists.txt).
class SolverCorrection {
 public:
  using Evaluation = Correction::Evaluation;
  explicit SolverCorrection(const Correction& correction) : correction_(&correction) {}
  model::Status begin_evaluation(const Joints& bend, Evaluation& evaluation, bool with_gradient) const;
  std::uint32_t continue_evaluation(Evaluation& evaluation, std::uint32_t max_units) const;
  bool evaluation_finished(const Evaluation& evaluation) const;
  bool evaluation_has_gradient(const Evaluation& evaluation) const;
  void evaluation_result(const Evaluation& evaluation, model::Twist<Scalar>& eps,
                         model::Jacobian<Scalar, kMaxSegments>& d_eps_d_bend) const;

 private:
  const Correction* correction_;
};
using Solver = model::IkSolver<Scalar, kMaxSegments, SolverCorrection>;

struct CycleStatistics {
  std::uint32_t cycles = 0;
  std::uint32_t overruns = 0;  // cycles longer than the period plus releases the timer reports missed
  std::int64_t execution_max_ns = 0;
  std::int64_t execution_total_ns = 0;
  std::int64_t jitter_max_ns = 0;  // start of work after its release time
  std::uint32_t rejected_frames = 0;
  std::uint32_t rejected_cable_sets = 0;
  std::uint32_t stale_events = 0;
  std::uint32_t poses_published = 0;
  std::uint32_t targets_received = 0;

  std::int64_t execution_mean_ns() const { return cycles == 0 ? 0 : execution_total_ns / cycles; }
};

struct PoseEstimate {
  Pose pose;
  Joints joints;
  bool compensated = false;
  // Outside the input range the model was fitted on (never in DEGRADED).
  bool outside_range = false;
  // The query in the GP's kernel coordinates (compensated only), for the
  // variance of this pose.
  Scalar kernel_coordinates[Correction::kMaxInputs] = {};
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

class Runtime {
 public:
  // fallback_geometry is the robot's design geometry, used when no image is
  // usable; with an image, the image's geometry is the one it was trained on.
  Runtime(const hal::Hal& hal, const Geometry& fallback_geometry);

  Runtime(const Runtime&) = delete;
  Runtime& operator=(const Runtime&) = delete;

  // BOOT: validates the image with the shared parser and sets the CAN filters.
  // A controller that refuses the filters is a standing fault
  // (can_filters_refused), not a stop: the runtime ignores the foreign frames
  // it then receives, and kMaxRxFramesPerCycle bounds that work.
  RuntimeState init();

  // One cycle of work for the given release.
  void run_cycle(const hal::TimerTick& tick);

  // The forward path run_cycle applies to the latest cable set: nominal or
  // compensated by state. Writes `estimate` only on success.
  model::Status estimate_pose(const Cables& cables_mm, PoseEstimate& estimate) const;
  // The radii and extrapolation flag of an estimate, in one go (a cycle
  // spreads the same steps over a few cycles); zero radii without a
  // variance block or in DEGRADED.
  model::PoseUncertainty<Scalar> estimate_uncertainty(const PoseEstimate& estimate) const;

  RuntimeState state() const { return state_; }
  // What STATUS reports: stale input in FAULT, else the last rejection since
  // the previous STATUS, else the boot fault (image), else refused filters,
  // else none.
  FaultCode active_fault() const;
  // What STATS reports with it (fault_detail.hpp).
  FaultDetail active_fault_detail() const;
  FaultCode boot_fault() const { return boot_fault_; }
  FaultDetail boot_fault_detail() const { return boot_fault_detail_; }
  bool can_filters_accepted() const { return can_filters_accepted_; }
  FaultCode last_event() const { return last_event_; }
  const CycleStatistics& statistics() const { return statistics_; }
  const Geometry& geometry() const { return geometry_; }
  // The correction the image bound (unbound in DEGRADED).
  const Correction& correction() const { return correction_; }
  const IkReport& last_ik_report() const { return last_ik_report_; }
  // A target being solved, and the IK work units a cycle may spend on it
  // (the last cycle's; after init, a cycle's that also runs a slice of the
  // variance, the smaller).
  bool ik_running() const { return solving_; }
  std::uint32_t ik_units_per_cycle() const { return ik_units_per_cycle_; }
  // Units the IK solver spent in the last cycle.
  std::uint32_t ik_units_last_cycle() const { return ik_units_last_cycle_; }
  // Setpoint frames sent, final and best-so-far.
  std::uint32_t setpoints_published() const { return setpoints_published_; }
  // The joints of the last setpoints sent (valid once one was sent).
  const Joints& setpoint_joints() const { return setpoint_joints_; }
  bool has_setpoints() const { return has_setpoints_; }
  const Cables& setpoints_mm() const { return setpoints_mm_; }
  bool has_pose() const { return has_pose_; }
  const PoseEstimate& latest_pose() const { return latest_pose_; }
  // The last radii sent (POSE_UNCERTAINTY), for the pose of cycle
  // latest_uncertainty_sequence().
  bool has_uncertainty() const { return has_uncertainty_; }
  const model::PoseUncertainty<Scalar>& latest_uncertainty() const { return latest_uncertainty_; }
  std::uint8_t latest_uncertainty_sequence() const { return uncertainty_sequence_; }
  // Whether the latest pose extrapolates: outside the fitted range, or the
  // last radii said so.
  bool extrapolating() const;
  // Model updates over CAN into the HAL's flash (model_update.hpp).
  const ModelUpdate& model_update() const { return update_; }

  // The tip payload, for an image with a payload input: the image's default
  // until a valid one arrives (the PAYLOAD frame, or this call). A payload
  // that is NaN or outside the PAYLOAD signal's range is refused with
  // FaultCode::payload_invalid, and the previous one stays in use. The next
  // pose and the next IK evaluation use the new one. Without a payload input
  // a valid payload is accepted and changes nothing.
  bool set_payload_kg(Scalar payload_kg);
  Scalar payload_kg() const { return payload_kg_; }
  bool payload_received() const { return payload_received_; }

 private:
  // runtime_update.cpp: the image init() loads, and the switch to a new one.
  SlotImage model_source();
  model::ImageStatus parse_model(const SlotImage& source, model::ImageView& view) const;
  bool image_loads(const SlotImage& source);
  void reload_model();
  void handle_frame(const hal::CanFrame& frame);
  void handle_cable_frame(const hal::CanFrame& frame);
  void handle_target_orientation(const hal::CanFrame& frame);
  void handle_target_position(const hal::CanFrame& frame);
  void handle_target_commit(const hal::CanFrame& frame);
  void handle_payload(const hal::CanFrame& frame);
  void start_solve(const Pose& target, const protocol::TargetPositionZ& commit);
  void continue_solve();
  void finish_solve(model::IkSolveState end);
  bool begin_solution_check(const Joints& joints);
  void continue_solution_check();
  void retry_or_refuse();
  void straight_start(Joints& joints) const;
  void conclude_solve(bool reached, const Joints& joints);
  void end_solve(protocol::IkOutcome outcome);
  bool set_setpoints(const Joints& joints);
  bool publish_tracking_point(Solver& solver);
  void fill_ik_report(protocol::IkOutcome outcome);
  bool segment_current(int segment) const;
  bool input_stale() const;
  void update_pose();
  void publish_pose();
  void continue_uncertainty();
  void publish_setpoints();
  void publish_ik_report();
  void publish_status();
  void send(const hal::CanFrame& frame);
  void record_event(FaultCode code, FaultDetail detail = FaultDetail());
  void reject_frame(FaultCode code);
  void enter(RuntimeState next);

  hal::Hal hal_;
  Geometry fallback_geometry_;
  Geometry geometry_;
  model::ImageView image_{};
  Correction correction_;
  RuntimeState state_ = RuntimeState::boot;
  RuntimeState mode_ = RuntimeState::boot;  // RUN or DEGRADED: where FAULT returns to
  FaultCode boot_fault_ = FaultCode::none;
  FaultDetail boot_fault_detail_;
  bool can_filters_accepted_ = false;
  FaultCode last_event_ = FaultCode::none;
  FaultCode unreported_event_ = FaultCode::none;
  FaultDetail last_event_detail_;

  std::uint32_t cycle_ = 0;
  Cables latest_cables_mm_;
  std::uint32_t segment_updated_cycle_[kMaxSegments] = {};
  bool segment_seen_[kMaxSegments] = {};
  bool fresh_cables_ = false;
  std::uint32_t last_valid_cycle_ = 0;

  PoseEstimate latest_pose_;
  bool has_pose_ = false;
  Scalar payload_kg_ = 0;
  bool payload_received_ = false;

  // The variance of a recent pose, a few cycles' work.
  Uncertainty uncertainty_;
  Uncertainty::Evaluation uncertainty_evaluation_;
  bool uncertainty_running_ = false;
  std::uint8_t uncertainty_running_sequence_ = 0;
  model::PoseUncertainty<Scalar> latest_uncertainty_;
  bool has_uncertainty_ = false;
  std::uint8_t uncertainty_sequence_ = 0;

  // The parts of a target received before its commit frame.
  bool has_pending_position_ = false;
  bool has_pending_orientation_ = false;
  protocol::TargetPositionXy pending_position_;
  protocol::TargetOrientation pending_orientation_;
  IkReport last_ik_report_;
  // The IK request in progress, its whole state in static memory; the
  // solver works on the compensated model in RUN, the nominal in DEGRADED.
  SolverCorrection solver_correction_{correction_};
  Solver solver_;
  bool solving_ = false;
  bool solving_tracking_ = false;
  // The target refuses a solution where the model extrapolates: a solution
  // found is checked (input range, then the variance over a few cycles'
  // IK slices) before its setpoints go out.
  bool solving_refuses_extrapolation_ = false;
  bool checking_solution_ = false;
  // A refused solution is looked for once more from the slightly bent
  // straight start, near the middle of any training data.
  bool solution_retried_ = false;
  Pose solving_target_;
  Uncertainty::Evaluation solution_check_;
  Joints checked_joints_;
  protocol::TargetMode solving_mode_ = protocol::TargetMode::position;
  std::uint8_t solving_sequence_ = 0;
  int solving_cycles_ = 0;
  // How the solver ended, when its end did not fit in that cycle's slice.
  model::IkSolveState solving_end_ = model::IkSolveState::running;
  Joints published_best_bend_;
  std::uint32_t ik_units_per_cycle_ = kMinIkUnitsPerCycle;
  std::uint32_t ik_units_alone_ = kMinIkUnitsPerCycle;             // in a cycle without a variance slice
  std::uint32_t ik_units_beside_variance_ = kMinIkUnitsPerCycle;  // in a cycle with one
  bool variance_beside_ik_ = false;  // a slice fits beside IK's smallest step
  std::uint32_t ik_units_last_cycle_ = 0;
  std::uint32_t setpoints_published_ = 0;
  bool has_setpoints_ = false;
  Cables setpoints_mm_;
  Joints setpoint_joints_;
  hal::CanFrame setpoint_frames_[kMaxSegments] = {};

  CycleStatistics statistics_;
  ModelUpdate update_;
};

}  // namespace cdcr::firmware
