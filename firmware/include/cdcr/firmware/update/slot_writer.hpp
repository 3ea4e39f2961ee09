#pragma once
// The flash side of a model update (the slots: model_slots.hpp): which
// slot runs and which images may run at boot, the slot a transfer writes
// (the one not running) with its transfer record, and every flash
// operation an update makes -- the erases, the record, each block and its
// progress byte, the header that commits an image, the word that revokes
// one. At most one operation runs at a time; each is started here and
// polled with poll(), so that no cycle waits on the flash.

#include <cstdint>

#include "cdcr/firmware/model_slots.hpp"
#include "cdcr/hal/flash.hpp"
#include "cdcr/model/flash_image.hpp"

namespace cdcr::firmware {

class SlotWriter {
 public:
  explicit SlotWriter(hal::Flash* flash);

  // A flash large enough for two slots, programs of a whole record.
  bool usable() const { return usable_; }
  const hal::Flash& flash() const { return *flash_; }

  // Boot: the committed images, newest first (hashed once, here).
  void boot();
  int candidate_count() const { return candidate_count_; }
  const SlotImage& candidate(int index) const { return candidates_[index]; }
  // The candidate that runs (-1: the model storage's image).
  void set_active(int candidate_index);
  int active_slot() const { return active_slot_; }
  std::uint32_t active_sequence() const { return active_sequence_; }

  // The slot a transfer writes: the one not running, and the transfer
  // record it holds, if any.
  void target_other_slot();
  void read_record();
  int target_slot() const { return target_slot_; }
  const std::uint8_t* target_image() const { return flash_->read() + target_.image_offset(); }
  const TransferRecord& record() const { return record_; }
  bool record_in_flash() const { return record_in_flash_; }
  void forget_record() { record_in_flash_ = false; }  // a new START starts over
  void new_record(std::uint16_t transfer_id, std::uint32_t image_size, const std::uint8_t (&digest)[kSha256Bytes]);
  bool fits(std::uint32_t image_size, std::uint32_t blocks) const;
  // The blocks whose progress byte says they are in flash, from the first.
  std::uint32_t blocks_in_flash(std::uint32_t total_blocks) const;

  // The operations. Each start_ returns what the flash said: ok (running),
  // busy (not started; try again next step) or a failure.
  bool operation_running() const { return operation_running_; }
  // busy while the running operation runs; ok once, when it ends.
  hal::FlashStatus poll();
  hal::FlashStatus start_erase_metadata();
  hal::FlashStatus start_write_record();
  void record_written() { record_in_flash_ = true; }
  // The image sectors after the record, one an operation.
  void erase_image_from_start() { erase_sector_ = 1; }
  bool image_erased() const { return erase_sector_ > image_sectors(); }
  hal::FlashStatus start_erase_image_sector();
  void image_sector_erased() { erase_sector_ += 1; }
  // A block: its data, then its progress byte.
  bool block_pending() const { return block_stage_ != BlockStage::none; }
  bool block_data_written() const { return block_stage_ == BlockStage::progress; }
  void forget_block() { block_stage_ = BlockStage::none; }
  hal::FlashStatus start_block_data(std::uint32_t block, const std::uint8_t* data, std::uint32_t length);
  hal::FlashStatus start_block_progress(std::uint32_t block);
  // The block's operation ended: true once its progress byte is written.
  bool block_step_done();
  // The commit point: the header, one above every intact header.
  hal::FlashStatus start_write_header();
  // The header is written: the new image first, the running one its
  // fallback. Returns the slot to switch to.
  int header_written(const model::ImageScan& scan);
  hal::FlashStatus start_revoke(int slot);
  // A rollback: `slot`'s image (hashed again) is the only candidate.
  void make_only_candidate(int slot, const SlotHeader& header, const model::ImageScan& scan);
  // A revoked image is no candidate any more.
  void drop_candidate(int slot);

 private:
  enum class BlockStage : std::uint8_t { none, data, progress };

  hal::FlashStatus started(hal::FlashStatus status);
  std::uint32_t image_sectors() const;

  hal::Flash* flash_;
  bool usable_ = false;
  SlotImage candidates_[kModelSlots];
  int candidate_count_ = 0;
  int active_slot_ = -1;
  std::uint32_t active_sequence_ = 0;

  int target_slot_ = 0;
  SlotGeometry target_;
  TransferRecord record_;
  bool record_in_flash_ = false;  // record_ describes the target slot's record
  std::uint32_t erase_sector_ = 0;  // within the slot
  BlockStage block_stage_ = BlockStage::none;
  bool operation_running_ = false;
  std::uint32_t committed_sequence_ = 0;
  std::uint8_t staged_[kSlotRecordBytes] = {};  // what a program writes, until it ends
};

}  // namespace cdcr::firmware
