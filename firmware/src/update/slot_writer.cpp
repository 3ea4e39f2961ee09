#include "cdcr/firmware/update/slot_writer.hpp"

#include <cstring>

#include "cdcr/firmware/protocol.hpp"

namespace cdcr::firmware {

SlotWriter::SlotWriter(hal::Flash* flash) : flash_(flash) {
  usable_ = flash_ != nullptr && slot_geometry(*flash_, 0).sectors != 0 &&
            flash_->max_program_bytes() >= kSlotRecordBytes;
}

void SlotWriter::boot() { candidate_count_ = usable_ ? committed_slots(*flash_, candidates_) : 0; }

void SlotWriter::set_active(int candidate_index) {
  if (candidate_index >= 0 && candidate_index < candidate_count_) {
    active_slot_ = candidates_[candidate_index].slot;
    active_sequence_ = candidates_[candidate_index].sequence;
  } else {
    active_slot_ = -1;
    active_sequence_ = 0;
  }
}

void SlotWriter::target_other_slot() {
  target_slot_ = active_slot_ == 0 ? 1 : 0;
  target_ = slot_geometry(*flash_, target_slot_);
}

void SlotWriter::read_record() { record_in_flash_ = decode_record(flash_->read() + target_.offset, record_); }

void SlotWriter::new_record(std::uint16_t transfer_id, std::uint32_t image_size,
                            const std::uint8_t (&digest)[kSha256Bytes]) {
  record_.transfer_id = transfer_id;
  record_.image_size = image_size;
  std::memcpy(record_.digest, digest, kSha256Bytes);
  record_in_flash_ = false;
}

bool SlotWriter::fits(std::uint32_t image_size, std::uint32_t blocks) const {
  return image_size <= target_.image_capacity() && blocks <= target_.progress_capacity();
}

std::uint32_t SlotWriter::blocks_in_flash(std::uint32_t total_blocks) const {
  const std::uint8_t* progress = flash_->read() + target_.progress_offset();
  std::uint32_t blocks = 0;
  while (blocks < total_blocks && progress[blocks] == 0x00) ++blocks;
  return blocks;
}

std::uint32_t SlotWriter::image_sectors() const {
  return (record_.image_size + target_.sector_bytes - 1) / target_.sector_bytes;
}

hal::FlashStatus SlotWriter::started(hal::FlashStatus status) {
  if (status == hal::FlashStatus::ok) operation_running_ = true;
  return status;
}

hal::FlashStatus SlotWriter::poll() {
  const hal::FlashStatus status = flash_->poll();
  if (status != hal::FlashStatus::busy) operation_running_ = false;
  return status;
}

hal::FlashStatus SlotWriter::start_erase_metadata() {
  return started(flash_->start_erase(target_.offset / target_.sector_bytes));
}

hal::FlashStatus SlotWriter::start_write_record() {
  encode_record(record_, staged_);
  return started(flash_->start_program(target_.offset, staged_, kSlotRecordBytes));
}

hal::FlashStatus SlotWriter::start_erase_image_sector() {
  return started(flash_->start_erase(target_.offset / target_.sector_bytes + erase_sector_));
}

hal::FlashStatus SlotWriter::start_block_data(std::uint32_t block, const std::uint8_t* data, std::uint32_t length) {
  block_stage_ = BlockStage::data;
  return started(flash_->start_program(target_.image_offset() + block * protocol::kUpdateBlockBytes, data, length));
}

hal::FlashStatus SlotWriter::start_block_progress(std::uint32_t block) {
  staged_[0] = 0x00;
  return started(flash_->start_program(target_.progress_offset() + block, staged_, 1));
}

bool SlotWriter::block_step_done() {
  if (block_stage_ == BlockStage::data) {
    block_stage_ = BlockStage::progress;
    return false;
  }
  if (block_stage_ == BlockStage::progress) {
    block_stage_ = BlockStage::none;
    return true;
  }
  return false;
}

hal::FlashStatus SlotWriter::start_write_header() {
  committed_sequence_ = active_sequence_;
  for (int i = 0; i < kModelSlots; ++i) {
    SlotHeader other;
    if (i != target_slot_ && read_slot_header(*flash_, i, other) && other.sequence > committed_sequence_) {
      committed_sequence_ = other.sequence;
    }
  }
  committed_sequence_ += 1;
  SlotHeader header;
  header.sequence = committed_sequence_;
  header.image_size = record_.image_size;
  std::memcpy(header.digest, record_.digest, kSha256Bytes);
  encode_header(header, reinterpret_cast<std::uint8_t(&)[kSlotHeaderBytes - 4]>(staged_));
  return started(flash_->start_program(target_.header_offset(), staged_, kSlotHeaderBytes - 4));
}

int SlotWriter::header_written(const model::ImageScan& scan) {
  SlotImage running;
  for (int i = 0; i < candidate_count_; ++i) {
    if (candidates_[i].slot == active_slot_) running = candidates_[i];
  }
  candidates_[0] = SlotImage{target_slot_, committed_sequence_, {target_image(), record_.image_size}, scan};
  candidate_count_ = 1;
  if (running.slot >= 0 && running.slot == active_slot_) candidates_[candidate_count_++] = running;
  record_in_flash_ = false;
  return target_slot_;
}

hal::FlashStatus SlotWriter::start_revoke(int slot) {
  std::memset(staged_, 0, 4);
  return started(
      flash_->start_program(slot_geometry(*flash_, slot).header_offset() + kSlotRevokeOffset, staged_, 4));
}

void SlotWriter::make_only_candidate(int slot, const SlotHeader& header, const model::ImageScan& scan) {
  candidates_[0] = SlotImage{
      slot, header.sequence, {flash_->read() + slot_geometry(*flash_, slot).image_offset(), header.image_size}, scan};
  candidate_count_ = 1;
}

void SlotWriter::drop_candidate(int slot) {
  for (int i = 0; i < candidate_count_; ++i) {
    if (candidates_[i].slot == slot) {
      candidates_[i] = candidates_[candidate_count_ - 1];
      candidate_count_ -= 1;
    }
  }
}

}  // namespace cdcr::firmware
