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
  } else if (protocol::target_fd::kMessage.carries(frame.id)) {
    take_fd_target(frame, runtime);
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
  } else if (protocol::drives_command::kMessage.carries(frame.id)) {
    protocol::DrivesCommand command;
    if (protocol::decode(frame, command) != protocol::DecodeStatus::ok) {
      runtime.reject_input(FaultCode::drives_command_malformed);
    } else {
      runtime.recover_drives();
    }
  } else {
    return false;
  }
  return true;
}

namespace {

// The request of a commit and the parts it found (null: not received, or malformed).
TargetRequest target_request(const protocol::TargetPositionZ* commit, std::uint8_t sequence,
                             const protocol::TargetPositionXy* position, const protocol::TargetOrientation* orientation) {
  TargetRequest target;
  target.sequence = sequence;
  target.well_formed = commit != nullptr && position != nullptr &&
                       (commit->mode != protocol::TargetMode::pose || orientation != nullptr);
  if (target.well_formed) {
    target.position_mm[0] = position->x_mm;
    target.position_mm[1] = position->y_mm;
    target.position_mm[2] = commit->z_mm;
    target.mode = commit->mode;
    target.tracking = commit->tracking;
    target.refuse_extrapolating = commit->refuse_extrapolating;
    if (commit->mode == protocol::TargetMode::pose) {
      target.quaternion[0] = orientation->qw;
      target.quaternion[1] = orientation->qx;
      target.quaternion[2] = orientation->qy;
      target.quaternion[3] = orientation->qz;
    }
  }
  return target;
}

}  // namespace

void FrameInputs::take_commit(const hal::CanFrame& frame, Runtime& runtime) {
  protocol::TargetPositionZ commit;
  const bool well_formed = protocol::decode(frame, commit) == protocol::DecodeStatus::ok;
  // Even a malformed commit is answered with its sequence, if it has one.
  const std::uint8_t sequence = well_formed ? commit.sequence : protocol::commit_sequence(frame);
  runtime.set_target(target_request(well_formed ? &commit : nullptr, sequence,
                                    has_pending_position_ ? &pending_position_ : nullptr,
                                    has_pending_orientation_ ? &pending_orientation_ : nullptr));  // drops the parts
}

// TARGET_FD carries its parts with it: the parts received in classical
// frames before it are not used (and are dropped, as by any commit).
// The orientation part counts only for a pose target.
void FrameInputs::take_fd_target(const hal::CanFrame& frame, Runtime& runtime) {
  const protocol::FdMessageSpec& message = protocol::target_fd::kMessage;
  const bool checked = protocol::check_fd_frame(message, frame) == protocol::DecodeStatus::ok;
  protocol::TargetFd target;
  const bool commit_ok = checked && protocol::decode_part(message, frame, 2, target.position_z) == protocol::DecodeStatus::ok;
  const bool position_ok =
      checked && protocol::decode_part(message, frame, 1, target.position_xy) == protocol::DecodeStatus::ok;
  const bool orientation_ok =
      checked && protocol::decode_part(message, frame, 0, target.orientation) == protocol::DecodeStatus::ok;
  const std::uint8_t sequence =
      commit_ok ? target.position_z.sequence : protocol::commit_sequence(protocol::part_frame(message, frame, 2));
  runtime.set_target(target_request(commit_ok ? &target.position_z : nullptr, sequence,
                                    position_ok ? &target.position_xy : nullptr,
                                    orientation_ok ? &target.orientation : nullptr));
}

}  // namespace cdcr::firmware
