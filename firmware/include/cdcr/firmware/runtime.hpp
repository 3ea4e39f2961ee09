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
// Per cycle: take the inputs (up to kMaxRxFramesPerCycle frames from each
// bus, or by direct call), move the hysteresis state and estimate the pose from the latest cable
// lengths, let the scheduler share out the rest (variance slice, model update,
// IK: cycle_scheduler.hpp), publish, and measure time and jitter on the HAL
// clock. Frames go through protocol.hpp. The parts: kinematics.hpp,
// hysteresis_tracker.hpp, ik_request.hpp, model_update.hpp, outbox.hpp.

#include <cstdint>

#include "cdcr/firmware/capacity.hpp"
#include "cdcr/firmware/cycle_statistics.hpp"
#include "cdcr/firmware/cycle_scheduler.hpp"
#include "cdcr/firmware/fault.hpp"
#include "cdcr/firmware/fault_detail.hpp"
#include "cdcr/firmware/frame_inputs.hpp"
#include "cdcr/firmware/hysteresis_tracker.hpp"
#include "cdcr/firmware/ik_request.hpp"
#include "cdcr/firmware/kinematics.hpp"
#include "cdcr/firmware/model_update.hpp"
#include "cdcr/firmware/outbox.hpp"
#include "cdcr/firmware/protocol.hpp"
#include "cdcr/firmware/publish_rates.hpp"
#include "cdcr/hal/formatted_can_bus.hpp"
#include "cdcr/hal/hal.hpp"

namespace cdcr::firmware {

class Runtime;

// Inputs a caller hands over by call rather than on the bus (the C API's):
// run_cycle has them delivered first, where it takes its frames, each
// counted as the frames that would carry it against kMaxRxFramesPerCycle.
class CycleInputs {
 public:
  // Calls runtime's set_* for the inputs waiting; returns their frame count.
  virtual int deliver(Runtime& runtime) = 0;

 protected:
  ~CycleInputs() = default;
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

  // One cycle of work for the given release; `inputs` first, then the bus.
  void run_cycle(const hal::TimerTick& tick, CycleInputs* inputs = nullptr);

  // The inputs, by direct call: each acts as the frame that carries it,
  // received now (between cycles: counted in the cycle before), so the
  // values should be as the protocol carries them (protocol::as_transmitted).
  // A segment's four cable lengths; false for a segment the model lacks.
  bool set_cable_lengths(int segment, const Scalar (&lengths_mm)[4]);
  // A target, solved over the next cycles (IK_REPORT tells how it ended).
  void set_target(const TargetRequest& target);
  // The tip payload, for an image with a payload input: the image's default
  // until a valid one arrives (the PAYLOAD frame, or this call). A payload
  // that is NaN or outside the PAYLOAD signal's range is refused with
  // FaultCode::payload_invalid, and the previous one stays in use. The next
  // pose and the next IK evaluation use the new one. Without a payload input
  // a valid payload is accepted and changes nothing.
  bool set_payload_kg(Scalar payload_kg);
  // How often the runtime's own frames go out (publish_rates.hpp); kept
  // across init() and model switches. False, and the rates unchanged, for
  // rates that are not valid().
  bool set_publish_rates(const PublishRates& rates);
  const PublishRates& publish_rates() const { return publish_rates_; }
  // The format of the runtime's frames on the host's bus and the drives'
  // (formatted_can_bus.hpp), classical until set; before init() only, and
  // kept across it. On an FD bus the pose goes out as POSE_FD (the radii
  // in it instead of POSE_UNCERTAINTY) and the setpoints as
  // CABLE_SETPOINTS_FD; TARGET_FD is taken on any bus. Without a drives
  // bus (Hal::drives_can) the two are one bus and must be equal. False,
  // and nothing changed, for an FD format on a controller without FD, or
  // after init().
  bool set_can_formats(hal::CanFormat host, hal::CanFormat drives);
  hal::CanFormat host_can_format() const { return host_bus_.format(); }
  hal::CanFormat drives_can_format() const { return drives_bus_.format(); }
  bool has_drives_bus() const { return hal_.drives_can != nullptr; }
  // Drives of a hal::Drives backend: their health as of this cycle, and a
  // restart after they failed (false: no backend, or nothing to recover).
  // The runtime is in FAULT while they have failed.
  bool has_drives() const { return hal_.drives != nullptr; }
  const hal::DrivesHealth& drives_health() const { return drives_health_; }
  bool recover_drives();
  // HOMING: the homing move has just ended, the robot is at home
  // (hysteresis_tracker.hpp); without a hysteresis block, nothing.
  void set_homed() { hysteresis_.homed(model_.geometry); }
  // An input that could not be taken (a frame that does not decode):
  // counted in STATS, reported in STATUS.
  void reject_input(FaultCode code);
  Scalar payload_kg() const { return payload_kg_; }
  bool payload_received() const { return payload_received_; }

  // Where each cable last moved, for an image with the history inputs: the
  // next estimates use it. run_cycle holds the tracker's own after every
  // complete cable set; a replay of recorded rows sets each row's.
  void set_history_inputs(const Scalar* history) { model_.correction.set_history_inputs(history); }
  // The forward path run_cycle applies to the latest cable set (kinematics.hpp).
  model::Status estimate_pose(const Cables& cables_mm, PoseEstimate& estimate) const {
    return firmware::estimate_pose(model_, cables_mm, estimate);
  }
  // The radii and extrapolation flag of an estimate in one go (cycles spread it).
  model::PoseUncertainty<Scalar> estimate_uncertainty(const PoseEstimate& estimate) const {
    return firmware::estimate_uncertainty(model_, estimate);
  }

  RuntimeState state() const { return state_; }
  // What STATUS reports: stale input in FAULT, else the last rejection since the
  // previous STATUS, else the boot fault (image), else refused filters, else none.
  FaultCode active_fault() const;
  // What STATS reports with it (fault_detail.hpp).
  FaultDetail active_fault_detail() const;
  FaultCode boot_fault() const { return boot_fault_; }
  FaultDetail boot_fault_detail() const { return boot_fault_detail_; }
  bool can_filters_accepted() const { return can_filters_accepted_; }
  FaultCode last_event() const { return outbox_.last_event(); }
  const CycleStatistics& statistics() const { return statistics_; }
  const Geometry& geometry() const { return model_.geometry; }
  // The correction the image bound (unbound in DEGRADED).
  const Correction& correction() const { return model_.correction; }
  const IkReport& last_ik_report() const { return ik_.report(); }
  // A target being solved, and the IK work units a cycle may spend on it (the last
  // cycle's; after init, a cycle's that also runs a variance slice, the smaller).
  bool ik_running() const { return ik_.running(); }
  std::uint32_t ik_units_per_cycle() const { return scheduler_.ik_units(); }
  // Units the IK solver spent in the last cycle.
  std::uint32_t ik_units_last_cycle() const { return ik_units_last_cycle_; }
  // Setpoint frames sent, final and best-so-far; the joints and lengths of
  // the last ones (valid once one was sent).
  std::uint32_t setpoints_published() const { return ik_.setpoints_published(); }
  const Joints& setpoint_joints() const { return ik_.setpoint_joints(); }
  bool has_setpoints() const { return ik_.has_setpoints(); }
  const Cables& setpoints_mm() const { return ik_.setpoints_mm(); }
  bool has_pose() const { return has_pose_; }
  const PoseEstimate& latest_pose() const { return latest_pose_; }
  // The last radii sent (POSE_UNCERTAINTY), for latest_uncertainty_sequence()'s pose.
  bool has_uncertainty() const { return variance_.has_result(); }
  const model::PoseUncertainty<Scalar>& latest_uncertainty() const { return variance_.result(); }
  std::uint8_t latest_uncertainty_sequence() const { return variance_.result_sequence(); }
  // Whether the latest pose extrapolates: outside the fitted range, or radii say so.
  bool extrapolating() const;
  // Model updates over CAN into the HAL's flash (model_update.hpp).
  const ModelUpdate& model_update() const { return update_; }
  // The cables' hysteresis state (an image with a hysteresis block).
  const HysteresisTracker& hysteresis() const { return hysteresis_; }
  // The bound image's compliance block (empty without one).
  const Compliance& compliance() const { return model_.compliance; }

 private:
  // The switch to a newly committed image (model_loader.hpp).
  void reload_model();
  RuntimeState mode() const { return model_.compensated ? RuntimeState::run : RuntimeState::degraded; }
  void handle_frame(const hal::CanFrame& frame);
  bool input_stale() const;
  void update_pose();
  void publish_pose();
  void publish_fd_pose();
  void receive_frames(hal::CanBus& bus, int frames);
  void receive_drive_lengths();
  void report_drives_fault() const;
  bool drives_failed() const { return hal_.drives != nullptr && drives_health_.failed(); }
  void publish_uncertainty();
  protocol::PoseUncertainty uncertainty_frame() const;
  void publish_status();
  void enter(RuntimeState next);

  hal::Hal hal_;
  Geometry fallback_geometry_;
  RobotModel model_;
  RuntimeState state_ = RuntimeState::boot;
  FaultCode boot_fault_ = FaultCode::none;
  FaultDetail boot_fault_detail_;
  bool can_filters_accepted_ = false;
  // The HAL's buses as the runtime sends on them (the drives' is the host's
  // without a second bus).
  hal::FormattedCanBus host_bus_;
  hal::FormattedCanBus drives_bus_;
  Outbox outbox_;

  std::uint32_t cycle_ = 0;
  Cables latest_cables_mm_;
  std::uint32_t segment_updated_cycle_[kMaxSegments] = {};
  bool segment_seen_[kMaxSegments] = {};
  bool fresh_cables_ = false;
  std::uint32_t last_valid_cycle_ = 0;

  PublishRates publish_rates_{};
  // Cycles still to run before the next pose may go out and the next
  // variance begin (0: now); counted down at the start of every cycle.
  std::uint32_t pose_wait_ = 0;
  std::uint32_t variance_wait_ = 0;

  PoseEstimate latest_pose_;
  bool has_pose_ = false;
  Scalar payload_kg_ = 0;
  bool payload_received_ = false;
  PoseVariance variance_;
  HysteresisTracker hysteresis_;

  hal::DrivesHealth drives_health_;
  FrameInputs frame_inputs_;
  IkRequest ik_{model_, outbox_, &hysteresis_};
  CycleScheduler scheduler_;
  std::uint32_t ik_units_last_cycle_ = 0;

  CycleStatistics statistics_;
  ModelUpdate update_;
};

}  // namespace cdcr::firmware
