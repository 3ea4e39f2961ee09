#include "cdcr/firmware/model_update.hpp"

namespace cdcr::firmware {

namespace {

using protocol::UpdateReason;
using protocol::UpdateState;

bool failed(hal::FlashStatus status) { return status != hal::FlashStatus::ok && status != hal::FlashStatus::busy; }

}  // namespace

ModelUpdate::ModelUpdate(hal::Flash* flash, hal::CanBus& can) : can_(can), writer_(flash) {}

void ModelUpdate::boot() {
  booted_ = true;
  writer_.boot();
}

void ModelUpdate::set_active(int candidate_index) {
  writer_.set_active(candidate_index);
  if (phase_ == Phase::switching) {
    switch_pending_ = false;
    if (writer_.active_slot() == switch_slot_) {
      phase_ = Phase::committed;
      report(UpdateReason::none);
    } else {
      // The new image did not load: the runtime went back to the other
      // one, and the header that made it active is revoked.
      revoke_slot_ = switch_slot_;
      rollback_slot_ = -1;
      last_reason_ = UpdateReason::image_invalid;
      phase_ = Phase::revoke;
    }
    return;
  }
  // Boot: a transfer into the other slot may be resumed.
  if (!enabled()) return;
  writer_.target_other_slot();
  writer_.read_record();
}

bool ModelUpdate::transferring() const {
  switch (phase_) {
    case Phase::erase_metadata:
    case Phase::write_record:
    case Phase::erase_image:
    case Phase::receiving:
    case Phase::verifying:
    case Phase::write_header:
      return true;
    default:
      return false;
  }
}

UpdateState ModelUpdate::state() const {
  switch (phase_) {
    case Phase::erase_metadata:
    case Phase::write_record:
    case Phase::erase_image:
      return UpdateState::preparing;
    case Phase::receiving:
      return UpdateState::receiving;
    case Phase::verifying:
    case Phase::write_header:
    case Phase::rollback_verifying:
    case Phase::revoke:
    case Phase::switching:
      return last_reason_ == UpdateReason::none ? UpdateState::verifying : UpdateState::failed;
    case Phase::committed:
      return UpdateState::committed;
    case Phase::failed:
      return UpdateState::failed;
    case Phase::idle:
      break;
  }
  return UpdateState::idle;
}

void ModelUpdate::report(UpdateReason reason) {
  protocol::UpdateReport message;
  message.state = state();
  if (reason != UpdateReason::none) message.state = phase_ == Phase::failed ? UpdateState::failed : message.state;
  message.active_slot = static_cast<std::uint8_t>(writer_.active_slot() + 1);
  message.reason = reason;
  message.next_block = static_cast<std::uint16_t>(receiver_.durable());
  message.window = phase_ == Phase::receiving ? kUpdateWindowBlocks : 0;
  message.transfer_id = writer_.record().transfer_id;
  message.active_sequence = static_cast<std::uint8_t>(writer_.active_sequence() & 0xFF);
  hal::CanFrame frame;
  protocol::encode(message, frame);
  can_.send(frame);
  receiver_.acknowledged();
}

void ModelUpdate::fail(UpdateReason reason) {
  last_reason_ = reason;
  phase_ = Phase::failed;
  receiver_.drop_incoming();
  report(reason);
}

std::uint32_t ModelUpdate::step(std::uint32_t cycle, const Geometry& geometry, std::uint32_t units) {
  cycle_ = cycle;
  const std::uint32_t frame_units = frames_ * kUpdateFrameUnits;
  frames_ = 0;
  const bool resting = phase_ == Phase::idle || phase_ == Phase::committed || phase_ == Phase::failed;
  // An operation that outlived an abort is still polled to its end.
  if (!enabled() || (resting && !writer_.operation_running())) return frame_units;
  const std::uint32_t spent = frame_units + kUpdateStepUnits;
  if (writer_.operation_running()) {
    const hal::FlashStatus status = writer_.poll();
    if (status == hal::FlashStatus::busy) return spent;
    if (status != hal::FlashStatus::ok) {
      fail(UpdateReason::flash_failed);
      return spent;
    }
    operation_done();
  }
  if ((phase_ == Phase::receiving || phase_ == Phase::erase_image || phase_ == Phase::erase_metadata ||
       phase_ == Phase::write_record) &&
      cycle_ - last_activity_cycle_ > kUpdateTimeoutCycles) {
    fail(UpdateReason::timeout);
    return spent;
  }
  if (writer_.operation_running()) return spent;
  const std::uint32_t hash_units = units > spent ? units - spent : 0;
  start_work(geometry, hash_units);
  return spent + hash_units_spent_;
}

void ModelUpdate::started(hal::FlashStatus status) {
  if (failed(status)) fail(UpdateReason::flash_failed);
}

void ModelUpdate::operation_done() {
  switch (phase_) {
    case Phase::erase_metadata:
      phase_ = Phase::write_record;
      break;
    case Phase::write_record:
      writer_.record_written();
      writer_.erase_image_from_start();
      phase_ = Phase::erase_image;
      break;
    case Phase::erase_image:
      writer_.image_sector_erased();
      if (writer_.image_erased()) {
        phase_ = Phase::receiving;
        report(UpdateReason::none);
      }
      break;
    case Phase::receiving:
      if (writer_.block_step_done() && receiver_.block_durable()) report(UpdateReason::none);
      break;
    case Phase::write_header:
      // The commit point: the new image first, the running one its fallback.
      switch_slot_ = writer_.header_written(verifier_.scan());
      phase_ = Phase::switching;
      switch_pending_ = true;
      break;
    case Phase::revoke:
      if (rollback_slot_ >= 0) {
        // The rolled-back-to image is the only candidate now.
        writer_.make_only_candidate(rollback_slot_, rollback_header_, verifier_.scan());
        switch_slot_ = rollback_slot_;
        rollback_slot_ = -1;
        phase_ = Phase::switching;
        switch_pending_ = true;
      } else {
        // A new image that did not load: revoked, the old one runs.
        writer_.drop_candidate(revoke_slot_);
        revoke_slot_ = -1;
        phase_ = Phase::failed;
        report(last_reason_);
      }
      break;
    default:
      break;  // an operation that outlived an abort
  }
}

void ModelUpdate::start_work(const Geometry& geometry, std::uint32_t units) {
  hash_units_spent_ = 0;
  switch (phase_) {
    case Phase::erase_metadata:
      started(writer_.start_erase_metadata());
      return;
    case Phase::write_record:
      started(writer_.start_write_record());
      return;
    case Phase::erase_image:
      if (writer_.image_erased()) {
        phase_ = Phase::receiving;
        report(UpdateReason::none);
        return;
      }
      started(writer_.start_erase_image_sector());
      return;
    case Phase::receiving:
      if (!writer_.block_pending() && receiver_.block_waiting()) {
        const std::uint32_t block = receiver_.durable();
        started(writer_.start_block_data(block, receiver_.waiting_block(), receiver_.block_length(block)));
      } else if (writer_.block_data_written()) {
        started(writer_.start_block_progress(receiver_.durable()));
      }
      return;
    case Phase::verifying:
    case Phase::rollback_verifying: {
      hash_units_spent_ = verifier_.step(units);
      if (!verifier_.hashed()) return;
      if (phase_ == Phase::rollback_verifying) {
        if (!verifier_.digest_matches(rollback_header_.digest)) {
          rollback_slot_ = -1;
          phase_ = Phase::idle;
          report(UpdateReason::no_rollback_image);
          return;
        }
        revoke_slot_ = writer_.active_slot();
        phase_ = Phase::revoke;
        return;
      }
      if (!verifier_.digest_matches(writer_.record().digest)) {
        fail(UpdateReason::digest_mismatch);
        return;
      }
      // The image's own checks and the robot it was made for, before it
      // may become active.
      const UpdateReason refused = verifier_.check(geometry);
      if (refused != UpdateReason::none) {
        fail(refused);
        return;
      }
      phase_ = Phase::write_header;
      return;
    }
    case Phase::write_header:
      started(writer_.start_write_header());
      return;
    case Phase::revoke:
      if (revoke_slot_ < 0) {
        // Rollback from the model storage's image: nothing to revoke.
        operation_done();
        return;
      }
      started(writer_.start_revoke(revoke_slot_));
      return;
    default:
      return;
  }
}

}  // namespace cdcr::firmware
