#include "cdcr/firmware/model_update.hpp"

#include <cmath>
#include <cstring>

#include "cdcr/model/compensated_kinematics.hpp"
#include "cdcr/model/flash_image.hpp"

namespace cdcr::firmware {

namespace {

using protocol::UpdateReason;
using protocol::UpdateState;
constexpr std::uint32_t kBlockBytes = protocol::kUpdateBlockBytes;
constexpr std::uint8_t kAllDigestParts = 0xFF;

bool near(float value, float reference) {
  return std::fabs(value - reference) <= kUpdateGeometryTolerance * std::fabs(reference);
}

}  // namespace

ModelUpdate::ModelUpdate(hal::Flash* flash, hal::CanBus& can) : flash_(flash), can_(can) {
  enabled_ = flash_ != nullptr && slot_geometry(*flash_, 0).sectors != 0 &&
             flash_->max_program_bytes() >= kSlotRecordBytes;
}

void ModelUpdate::boot() {
  booted_ = true;
  candidate_count_ = enabled_ ? committed_slots(*flash_, candidates_) : 0;
}

void ModelUpdate::set_active(int candidate_index) {
  if (candidate_index >= 0 && candidate_index < candidate_count_) {
    active_slot_ = candidates_[candidate_index].slot;
    active_sequence_ = candidates_[candidate_index].sequence;
  } else {
    active_slot_ = -1;
    active_sequence_ = 0;
  }
  if (phase_ == Phase::switching) {
    switch_pending_ = false;
    if (active_slot_ == switch_slot_) {
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
  if (!enabled_) return;
  target_slot_ = active_slot_ == 0 ? 1 : 0;
  target_ = slot_geometry(*flash_, target_slot_);
  record_in_flash_ = decode_record(flash_->read() + target_.offset, record_);
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

std::uint32_t ModelUpdate::block_length(std::uint32_t block) const {
  const std::uint32_t start = block * kBlockBytes;
  return record_.image_size - start < kBlockBytes ? record_.image_size - start : kBlockBytes;
}

std::uint32_t ModelUpdate::image_sectors() const {
  return (record_.image_size + target_.sector_bytes - 1) / target_.sector_bytes;
}

void ModelUpdate::report(UpdateReason reason) {
  protocol::UpdateReport message;
  message.state = state();
  if (reason != UpdateReason::none) message.state = phase_ == Phase::failed ? UpdateState::failed : message.state;
  message.active_slot = static_cast<std::uint8_t>(active_slot_ + 1);
  message.reason = reason;
  message.next_block = static_cast<std::uint16_t>(durable_);
  message.window = phase_ == Phase::receiving ? kUpdateWindowBlocks : 0;
  message.transfer_id = record_.transfer_id;
  message.active_sequence = static_cast<std::uint8_t>(active_sequence_ & 0xFF);
  hal::CanFrame frame;
  protocol::encode(message, frame);
  can_.send(frame);
  acknowledged_ = durable_;
}

void ModelUpdate::fail(UpdateReason reason) {
  last_reason_ = reason;
  phase_ = Phase::failed;
  incoming_ = false;
  report(reason);
}

void ModelUpdate::handle_frame(const hal::CanFrame& frame, std::uint32_t cycle) {
  cycle_ = cycle;
  frames_ += 1;
  if (protocol::update_data::kMessage.carries(frame.id)) {
    handle_data(frame);
  } else if (protocol::update_block::kMessage.carries(frame.id)) {
    handle_block(frame);
  } else if (protocol::update_digest::kMessage.carries(frame.id)) {
    protocol::UpdateDigest part;
    if (protocol::decode(frame, part) != protocol::DecodeStatus::ok) {
      report(UpdateReason::malformed);
      return;
    }
    std::memcpy(announced_digest_ + 4 * part.part, part.bytes, 4);
    digest_parts_ = static_cast<std::uint8_t>(digest_parts_ | (1u << part.part));
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
  if (!enabled_) {
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
        incoming_ = false;
        record_in_flash_ = false;  // a new START starts over
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
      } else if (durable_ < total_blocks_) {
        report(UpdateReason::missing_block);
      } else {
        phase_ = Phase::verifying;
        last_reason_ = UpdateReason::none;
        hash_.reset();
        hashed_ = 0;
        scan_.begin(flash_->read() + target_.image_offset(), record_.image_size);
        report(UpdateReason::none);
      }
      return;
    case protocol::UpdateCommand::rollback: {
      if (transferring() || phase_ == Phase::switching || phase_ == Phase::revoke ||
          phase_ == Phase::rollback_verifying) {
        report(UpdateReason::busy);
        return;
      }
      const int other = active_slot_ == 0 ? 1 : 0;
      if (active_slot_ < 0 || !read_slot_header(*flash_, other, rollback_header_)) {
        report(UpdateReason::no_rollback_image);
        return;
      }
      rollback_slot_ = other;
      last_reason_ = UpdateReason::none;
      hash_.reset();
      hashed_ = 0;
      scan_.begin(flash_->read() + slot_geometry(*flash_, other).image_offset(), rollback_header_.image_size);
      phase_ = Phase::rollback_verifying;
      report(UpdateReason::none);
      return;
    }
  }
}

void ModelUpdate::start_transfer(const protocol::UpdateCommandFrame& command) {
  last_activity_cycle_ = cycle_;
  if (digest_parts_ != kAllDigestParts || command.image_size < model::kImageHeaderSize) {
    report(UpdateReason::malformed);
    return;
  }
  const bool same = command.transfer_id == record_.transfer_id && command.image_size == record_.image_size &&
                    std::memcmp(announced_digest_, record_.digest, kSha256Bytes) == 0;
  digest_parts_ = 0;
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
  target_slot_ = active_slot_ == 0 ? 1 : 0;
  target_ = slot_geometry(*flash_, target_slot_);
  const std::uint32_t blocks = (command.image_size + kBlockBytes - 1) / kBlockBytes;
  if (command.image_size > target_.image_capacity() || blocks > target_.progress_capacity()) {
    report(UpdateReason::too_large);
    return;
  }
  incoming_ = false;
  last_reason_ = UpdateReason::none;
  program_stage_ = 0;
  if (same && record_in_flash_) {
    // Resume: the blocks whose progress byte is 0 are in flash.
    total_blocks_ = blocks;
    const std::uint8_t* progress = flash_->read() + target_.progress_offset();
    durable_ = 0;
    while (durable_ < total_blocks_ && progress[durable_] == 0x00) ++durable_;
    received_ = durable_;
    // Erases come before any block: with none in flash they may not be done.
    erase_sector_ = 1;
    phase_ = durable_ == 0 ? Phase::erase_image : Phase::receiving;
    report(UpdateReason::none);
    return;
  }
  record_.transfer_id = command.transfer_id;
  record_.image_size = command.image_size;
  std::memcpy(record_.digest, announced_digest_, kSha256Bytes);
  record_in_flash_ = false;
  total_blocks_ = blocks;
  durable_ = received_ = 0;
  phase_ = Phase::erase_metadata;
  report(UpdateReason::none);
}

void ModelUpdate::handle_block(const hal::CanFrame& frame) {
  if (incoming_) {
    incoming_ = false;
    report(UpdateReason::missing_block);
  }
  protocol::UpdateBlock block;
  if (protocol::decode(frame, block) != protocol::DecodeStatus::ok) {
    report(UpdateReason::malformed);
    return;
  }
  if (phase_ != Phase::receiving) {
    report(UpdateReason::no_transfer);
    return;
  }
  if (block.block < received_) {
    report(UpdateReason::duplicate);
    return;
  }
  if (block.block > received_ || block.block >= total_blocks_ || received_ - durable_ >= kUpdateWindowBlocks) {
    report(UpdateReason::out_of_order);
    return;
  }
  if (block.length != block_length(block.block)) {
    report(UpdateReason::malformed);
    return;
  }
  incoming_ = true;
  incoming_block_ = block.block;
  incoming_length_ = block.length;
  incoming_crc_ = block.crc;
  incoming_frames_ = 0;
}

void ModelUpdate::handle_data(const hal::CanFrame& frame) {
  protocol::UpdateData data;
  // Data of no accepted block (after a refused header) is dropped quietly.
  if (!incoming_ || protocol::decode(frame, data) != protocol::DecodeStatus::ok) return;
  std::uint8_t* buffer = blocks_[incoming_block_ % kUpdateWindowBlocks];
  const std::uint32_t at = 8u * incoming_frames_;
  const std::uint32_t take = incoming_length_ - at < 8 ? incoming_length_ - at : 8;
  std::memcpy(buffer + at, data.bytes, take);
  incoming_frames_ += 1;
  if (at + take < incoming_length_) return;
  incoming_ = false;
  if (protocol::update_block_crc(incoming_block_, buffer, incoming_length_) != incoming_crc_) {
    report(UpdateReason::corrupted);
    return;
  }
  received_ += 1;
  last_activity_cycle_ = cycle_;
}

std::uint32_t ModelUpdate::step(std::uint32_t cycle, const Geometry& geometry, std::uint32_t units) {
  cycle_ = cycle;
  const std::uint32_t frame_units = frames_ * kUpdateFrameUnits;
  frames_ = 0;
  const bool resting = phase_ == Phase::idle || phase_ == Phase::committed || phase_ == Phase::failed;
  // An operation that outlived an abort is still polled to its end.
  if (!enabled_ || (resting && !operation_running_)) return frame_units;
  const std::uint32_t spent = frame_units + kUpdateStepUnits;
  if (operation_running_) {
    const hal::FlashStatus status = flash_->poll();
    if (status == hal::FlashStatus::busy) return spent;
    operation_running_ = false;
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
  if (operation_running_) return spent;
  const std::uint32_t hash_units = units > spent ? units - spent : 0;
  start_work(geometry, hash_units);
  return spent + hash_units_spent_;
}

void ModelUpdate::start_operation(hal::FlashStatus started) {
  if (started == hal::FlashStatus::ok) {
    operation_running_ = true;
  } else if (started != hal::FlashStatus::busy) {
    fail(UpdateReason::flash_failed);
  }
}

void ModelUpdate::operation_done() {
  switch (phase_) {
    case Phase::erase_metadata:
      phase_ = Phase::write_record;
      break;
    case Phase::write_record:
      record_in_flash_ = true;
      erase_sector_ = 1;
      phase_ = Phase::erase_image;
      break;
    case Phase::erase_image:
      erase_sector_ += 1;
      if (erase_sector_ > image_sectors()) {
        phase_ = Phase::receiving;
        report(UpdateReason::none);
      }
      break;
    case Phase::receiving:
      if (program_stage_ == 1) {
        program_stage_ = 2;
      } else if (program_stage_ == 2) {
        program_stage_ = 0;
        durable_ += 1;
        if (durable_ - acknowledged_ >= std::uint32_t(kUpdateAckEveryBlocks) || durable_ == received_) {
          report(UpdateReason::none);
        }
      }
      break;
    case Phase::write_header: {
      // The commit point: the new image first, the running one its fallback.
      SlotImage running;
      for (int i = 0; i < candidate_count_; ++i) {
        if (candidates_[i].slot == active_slot_) running = candidates_[i];
      }
      candidates_[0] = SlotImage{target_slot_, committed_sequence_,
                                 {flash_->read() + target_.image_offset(), record_.image_size},
                                 scan_};
      candidate_count_ = 1;
      if (running.slot >= 0 && running.slot == active_slot_) candidates_[candidate_count_++] = running;
      switch_slot_ = target_slot_;
      record_in_flash_ = false;
      phase_ = Phase::switching;
      switch_pending_ = true;
      break;
    }
    case Phase::revoke:
      if (rollback_slot_ >= 0) {
        // The rolled-back-to image is the only candidate now.
        candidates_[0] = SlotImage{rollback_slot_, rollback_header_.sequence,
                                   {flash_->read() + slot_geometry(*flash_, rollback_slot_).image_offset(),
                                    rollback_header_.image_size},
                                   scan_};
        candidate_count_ = 1;
        switch_slot_ = rollback_slot_;
        rollback_slot_ = -1;
        phase_ = Phase::switching;
        switch_pending_ = true;
      } else {
        // A new image that did not load: revoked, the old one runs.
        for (int i = 0; i < candidate_count_; ++i) {
          if (candidates_[i].slot == revoke_slot_) {
            candidates_[i] = candidates_[candidate_count_ - 1];
            candidate_count_ -= 1;
          }
        }
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
      start_operation(flash_->start_erase(target_.offset / target_.sector_bytes));
      return;
    case Phase::write_record:
      encode_record(record_, reinterpret_cast<std::uint8_t(&)[kSlotRecordBytes]>(staged_));
      start_operation(flash_->start_program(target_.offset, staged_, kSlotRecordBytes));
      return;
    case Phase::erase_image:
      if (erase_sector_ > image_sectors()) {
        phase_ = Phase::receiving;
        report(UpdateReason::none);
        return;
      }
      start_operation(flash_->start_erase(target_.offset / target_.sector_bytes + erase_sector_));
      return;
    case Phase::receiving:
      if (program_stage_ == 0 && durable_ < received_) {
        program_stage_ = 1;
        start_operation(flash_->start_program(target_.image_offset() + durable_ * kBlockBytes,
                                              blocks_[durable_ % kUpdateWindowBlocks], block_length(durable_)));
      } else if (program_stage_ == 2) {
        staged_[0] = 0x00;
        start_operation(flash_->start_program(target_.progress_offset() + durable_, staged_, 1));
      }
      return;
    case Phase::verifying:
    case Phase::rollback_verifying: {
      const bool rollback = phase_ == Phase::rollback_verifying;
      const int slot = rollback ? rollback_slot_ : target_slot_;
      const std::uint32_t size = rollback ? rollback_header_.image_size : record_.image_size;
      const std::uint8_t* image = flash_->read() + slot_geometry(*flash_, slot).image_offset();
      // As many 64-byte pieces as the units allow: none leaves it for the
      // next cycle.
      std::uint32_t slice = units / kUpdateHashUnitsPer64Bytes * 64;
      if (slice > kUpdateHashBytesPerCycle) slice = kUpdateHashBytesPerCycle;
      if (slice == 0) return;
      const std::uint32_t take = size - hashed_ < slice ? size - hashed_ : slice;
      hash_units_spent_ = (take + 63) / 64 * kUpdateHashUnitsPer64Bytes;
      hash_.update(image + hashed_, take);
      scan_.step(take);  // the parser's whole-image checks, on the same bytes
      hashed_ += take;
      if (hashed_ < size) return;
      std::uint8_t digest[kSha256Bytes];
      hash_.finish(digest);
      hash_.reset();
      if (rollback) {
        if (std::memcmp(digest, rollback_header_.digest, kSha256Bytes) != 0) {
          rollback_slot_ = -1;
          phase_ = Phase::idle;
          report(UpdateReason::no_rollback_image);
          return;
        }
        revoke_slot_ = active_slot_;
        phase_ = Phase::revoke;
        return;
      }
      if (std::memcmp(digest, record_.digest, kSha256Bytes) != 0) {
        fail(UpdateReason::digest_mismatch);
        return;
      }
      finish_verification(geometry);
      return;
    }
    case Phase::write_header: {
      // One above every intact header, so that it wins at boot.
      SlotHeader header;
      committed_sequence_ = active_sequence_;
      for (int i = 0; i < kModelSlots; ++i) {
        SlotHeader other;
        if (i != target_slot_ && read_slot_header(*flash_, i, other) && other.sequence > committed_sequence_) {
          committed_sequence_ = other.sequence;
        }
      }
      committed_sequence_ += 1;
      header.sequence = committed_sequence_;
      header.image_size = record_.image_size;
      std::memcpy(header.digest, record_.digest, kSha256Bytes);
      encode_header(header, reinterpret_cast<std::uint8_t(&)[kSlotHeaderBytes - 4]>(staged_));
      start_operation(flash_->start_program(target_.header_offset(), staged_, kSlotHeaderBytes - 4));
      return;
    }
    case Phase::revoke: {
      if (revoke_slot_ < 0) {
        // Rollback from the model storage's image: nothing to revoke.
        operation_done();
        return;
      }
      std::memset(staged_, 0, 4);
      start_operation(flash_->start_program(slot_geometry(*flash_, revoke_slot_).header_offset() + kSlotRevokeOffset,
                                            staged_, 4));
      return;
    }
    default:
      return;
  }
}

// The image's own checks and the robot it was made for, before it may
// become active.
void ModelUpdate::finish_verification(const Geometry& geometry) {
  const std::uint8_t* image = flash_->read() + target_.image_offset();
  model::ImageView view;
  model::ImageCapacity capacity;
  capacity.max_training_points = kMaxTrainingPoints;
  capacity.max_segments = kMaxSegments;
  capacity.max_variance_rank = model::kMaxVarianceRank;
  const model::ImageStatus parsed = model::parse_image(image, record_.image_size, view, capacity, scan_);
  if (parsed == model::ImageStatus::unsupported_version) {
    fail(UpdateReason::unsupported_version);
    return;
  }
  if (parsed != model::ImageStatus::ok) {
    fail(UpdateReason::image_invalid);
    return;
  }
  Geometry incoming;
  if (model::geometry_from_image(view, incoming) != model::Status::ok) {
    fail(UpdateReason::image_invalid);
    return;
  }
  if (incoming.segment_count != geometry.segment_count) {
    fail(UpdateReason::wrong_segment_count);
    return;
  }
  for (int s = 0; s < geometry.segment_count; ++s) {
    if (!near(incoming.segments[s].backbone_length_mm, geometry.segments[s].backbone_length_mm) ||
        !near(incoming.segments[s].anchor_radius_mm, geometry.segments[s].anchor_radius_mm)) {
      fail(UpdateReason::wrong_geometry);
      return;
    }
  }
  phase_ = Phase::write_header;
}

}  // namespace cdcr::firmware
