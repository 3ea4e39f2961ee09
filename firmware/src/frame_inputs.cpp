#include "cdcr/firmware/frame_inputs.hpp"

#include "cdcr/firmware/runtime.hpp"

namespace cdcr::firmware {

bool FrameInputs::take(const hal::CanFrame& frame, Runtime& runtime) {
  if (protocol::cable_feedback::kMessage.carries(frame.id)) {
    protocol::CableFeedback feedback;
    bool taken = protocol::decode(frame, feedback) == protocol::DecodeStatus::ok;
    if (taken) {
      Scalar lengths_mm[4];
      for (int k = 0; k < 4; ++k) lengths_mm[k] = static_cast<Scalar>(feedback.lengths_mm[k]);
      taken = runtime.set_cable_lengths(feedback.segment, lengths_mm);
    }
    if (!taken) runtime.reject_input(FaultCode::cable_frame_malformed);
  } else if (protocol::target_orientation::kMessage.carries(frame.id)) {
    // A malformed part of a target drops what was pending of that part, so
    // the commit that follows is refused rather than solved with an older part.
    has_pending_orientation_ = protocol::decode(frame, pending_orientation_) == protocol::DecodeStatus::ok;
    if (!has_pending_orientation_) runtime.reject_input(FaultCode::target_malformed);
  } else if (protocol::target_position_xy::kMessage.carries(frame.id)) {
    has_pending_position_ = protocol::decode(frame, pending_position_) == protocol::DecodeStatus::ok;
    if (!has_pending_position_) runtime.reject_input(FaultCode::target_malformed);
  } else if (protocol::target_position_z::kMessage.carries(frame.id)) {
    take_commit(frame, runtime);
  } else if (protocol::payload::kMessage.carries(frame.id)) {
    protocol::Payload payload;
    if (protocol::decode(frame, payload) != protocol::DecodeStatus::ok) {
      runtime.reject_input(FaultCode::payload_invalid);
    } else {
      runtime.set_payload_kg(static_cast<Scalar>(payload.payload_kg));
    }
  } else if (protocol::homing::kMessage.carries(frame.id)) {
    protocol::Homing homing;
    if (protocol::decode(frame, homing) != protocol::DecodeStatus::ok) {
      runtime.reject_input(FaultCode::homing_malformed);
    } else {
      runtime.set_homed();
    }
  } else {
    return false;
  }
  return true;
}

void FrameInputs::take_commit(const hal::CanFrame& frame, Runtime& runtime) {
  protocol::TargetPositionZ commit;
  TargetRequest target;
  const bool well_formed = protocol::decode(frame, commit) == protocol::DecodeStatus::ok;
  // Even a malformed commit is answered with its sequence, if it has one.
  target.sequence = well_formed ? commit.sequence : protocol::commit_sequence(frame);
  target.well_formed = well_formed && has_pending_position_ &&
                       (commit.mode != protocol::TargetMode::pose || has_pending_orientation_);
  if (target.well_formed) {
    target.position_mm[0] = pending_position_.x_mm;
    target.position_mm[1] = pending_position_.y_mm;
    target.position_mm[2] = commit.z_mm;
    target.mode = commit.mode;
    target.tracking = commit.tracking;
    target.refuse_extrapolating = commit.refuse_extrapolating;
    if (commit.mode == protocol::TargetMode::pose) {
      const protocol::TargetOrientation& q = pending_orientation_;
      target.quaternion[0] = q.qw;
      target.quaternion[1] = q.qx;
      target.quaternion[2] = q.qy;
      target.quaternion[3] = q.qz;
    }
  }
  runtime.set_target(target);  // drops the parts
}

}  // namespace cdcr::firmware
