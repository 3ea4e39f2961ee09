// ModelUpdate's side of the frames: the commands (START, STATUS, ABORT,
// COMMIT, ROLLBACK) and where the transfer's frames go. The phases they
// start are run by step() (model_update.cpp).

#include <cstring>

#include "cdcr/firmware/model_update.hpp"

namespace cdcr::firmware {

namespace {

using protocol::UpdateReason;

}  // namespace

void ModelUpdate::answer(const UpdateReceiver::Answer& answer) {
  for (std::uint8_t i = 0; i < answer.count; ++i) report(answer.reasons[i]);
}

void ModelUpdate::handle_frame(const hal::CanFrame& frame, std::uint32_t cycle) {
  cycle_ = cycle;
  frames_ += 1;
  if (protocol::update_data::kMessage.carries(frame.id)) {
    const std::uint32_t received = receiver_.received();
    answer(receiver_.on_data(frame));
    if (receiver_.received() != received) last_activity_cycle_ = cycle_;
  } else if (protocol::update_block::kMessage.carries(frame.id)) {
    answer(receiver_.on_block(frame, phase_ == Phase::receiving));
  } else if (protocol::update_digest::kMessage.carries(frame.id)) {
    answer(receiver_.on_digest(frame));
  } else if (protocol::update_command::kMessage.carries(frame.id)) {
    protocol::UpdateCommandFrame command;
    if (protocol::decode(frame, command) != protocol::DecodeStatus::ok) {
      report(UpdateReason::malformed);
      return;
    }
    handle_command(command);
  }
}

void ModelUpdate::handle_command(const protocol::UpdateCommandFrame& command) {
  if (!enabled()) {
    report(UpdateReason::flash_failed);
    return;
  }
  switch (command.command) {
    case protocol::UpdateCommand::start:
      start_transfer(command);
      return;
    case protocol::UpdateCommand::status:
      report(phase_ == Phase::failed ? last_reason_ : UpdateReason::none);
      return;
    case protocol::UpdateCommand::abort:
      if (phase_ == Phase::write_header) {
        report(UpdateReason::busy);  // past the commit point's start: it finishes
        return;
      }
      if (transferring() || phase_ == Phase::failed || phase_ == Phase::committed) {
        phase_ = Phase::idle;
        receiver_.drop_incoming();
        writer_.forget_record();  // a new START starts over
      }
      report(UpdateReason::none);
      return;
    case protocol::UpdateCommand::commit:
      last_activity_cycle_ = cycle_;
      if (phase_ == Phase::verifying || phase_ == Phase::write_header || phase_ == Phase::switching ||
          phase_ == Phase::committed) {
        report(UpdateReason::none);
      } else if (phase_ != Phase::receiving) {
        report(UpdateReason::no_transfer);
      } else if (receiver_.durable() < receiver_.total_blocks()) {
        report(UpdateReason::missing_block);
      } else {
        phase_ = Phase::verifying;
        last_reason_ = UpdateReason::none;
        verifier_.begin(writer_.target_image(), writer_.record().image_size);
        report(UpdateReason::none);
      }
      return;
    case protocol::UpdateCommand::rollback: {
      if (transferring() || phase_ == Phase::switching || phase_ == Phase::revoke ||
          phase_ == Phase::rollback_verifying) {
        report(UpdateReason::busy);
        return;
      }
      const int other = writer_.active_slot() == 0 ? 1 : 0;
      if (writer_.active_slot() < 0 || !read_slot_header(writer_.flash(), other, rollback_header_)) {
        report(UpdateReason::no_rollback_image);
        return;
      }
      rollback_slot_ = other;
      last_reason_ = UpdateReason::none;
      verifier_.begin(writer_.flash().read() + slot_geometry(writer_.flash(), other).image_offset(),
                      rollback_header_.image_size);
      phase_ = Phase::rollback_verifying;
      report(UpdateReason::none);
      return;
    }
  }
}

void ModelUpdate::start_transfer(const protocol::UpdateCommandFrame& command) {
  last_activity_cycle_ = cycle_;
  const TransferRecord& record = writer_.record();
  const bool named = command.transfer_id == record.transfer_id && command.image_size == record.image_size;
  if (!receiver_.digest_complete()) {
    // A digest frame lost, or START repeated or ahead of its digest: not a
    // malformed image. The transfer under way goes on if this names it
    // (its digest is in the record); anything else, a committed image
    // included, needs the digest and START again to be told apart.
    report(named && transferring() ? UpdateReason::none : UpdateReason::no_transfer);
    return;
  }
  if (command.image_size < model::kImageHeaderSize) {
    report(UpdateReason::malformed);
    return;
  }
  const bool same = named && std::memcmp(receiver_.announced_digest(), record.digest, kSha256Bytes) == 0;
  receiver_.forget_digest();
  if (transferring()) {
    report(same ? UpdateReason::none : UpdateReason::busy);
    return;
  }
  if (phase_ == Phase::switching || phase_ == Phase::revoke || phase_ == Phase::rollback_verifying) {
    report(UpdateReason::busy);
    return;
  }
  if (phase_ == Phase::committed && same) {
    report(UpdateReason::none);
    return;
  }
  writer_.target_other_slot();
  const std::uint32_t blocks = (command.image_size + protocol::kUpdateBlockBytes - 1) / protocol::kUpdateBlockBytes;
  if (!writer_.fits(command.image_size, blocks)) {
    report(UpdateReason::too_large);
    return;
  }
  last_reason_ = UpdateReason::none;
  writer_.forget_block();
  if (same && writer_.record_in_flash()) {
    // Resume: the blocks whose progress byte is 0 are in flash.
    receiver_.begin(command.image_size, writer_.blocks_in_flash(blocks));
    // Erases come before any block: with none in flash they may not be done.
    writer_.erase_image_from_start();
    phase_ = receiver_.durable() == 0 ? Phase::erase_image : Phase::receiving;
    report(UpdateReason::none);
    return;
  }
  writer_.new_record(command.transfer_id, command.image_size, receiver_.announced_digest());
  receiver_.begin(command.image_size, 0);
  phase_ = Phase::erase_metadata;
  report(UpdateReason::none);
}

}  // namespace cdcr::firmware
