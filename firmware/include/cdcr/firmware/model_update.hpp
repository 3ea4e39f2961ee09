#pragma once
// A new model image over CAN into the inactive flash slot, while the runtime
// keeps running the active one (the protocol: protocol/messages.hpp, "Model
// updates"; the slots: model_slots.hpp).
//
//   START (after the 8 digest frames)  erase the slot's metadata sector,
//                 write the transfer record, erase the image sectors;
//                 or resume the transfer the record in flash describes.
//   blocks        go-back-N with a window of kUpdateWindowBlocks: each block
//                 is checked (number, length, CRC), held in RAM, programmed,
//                 then its progress byte; UPDATE_REPORT acknowledges the
//                 blocks in flash cumulatively.
//   COMMIT        hash the slot's image (kUpdateHashBytesPerCycle a cycle,
//                 and in the same pass the parser's CRC-32 and finite
//                 payload checks, model::ImageScan), compare with the
//                 announced SHA-256, parse it (with that scan: no cycle
//                 reads the whole image) and check its
//                 geometry against the running model's, then write the slot
//                 header with a sequence one above the active slot's: the
//                 commit point. The runtime then loads it, and if it cannot,
//                 goes back to the other slot and the new header is revoked.
//   ROLLBACK      revoke the active slot's header and load the other slot's
//                 image (hashed first).
// Every flash operation is started and polled, at most one at a time, from
// step(), which the runtime calls once a cycle: a cycle never waits on the
// flash. No allocation, no exceptions.

#include <cstdint>

#include "cdcr/firmware/capacity.hpp"
#include "cdcr/firmware/model_slots.hpp"
#include "cdcr/firmware/protocol.hpp"
#include "cdcr/hal/can_bus.hpp"
#include "cdcr/hal/flash.hpp"
#include "cdcr/model/flash_image.hpp"
#include "cdcr/model/geometry.hpp"

namespace cdcr::firmware {

class ModelUpdate {
 public:
  using Geometry = model::RobotGeometry<float, kMaxSegments>;

  ModelUpdate(hal::Flash* flash, hal::CanBus& can);
  ModelUpdate(const ModelUpdate&) = delete;
  ModelUpdate& operator=(const ModelUpdate&) = delete;

  // A flash large enough for two slots, programs of a whole block.
  bool enabled() const { return enabled_; }

  // Boot: the committed images, newest first (hashed once, here).
  void boot();
  bool booted() const { return booted_; }
  int candidate_count() const { return candidate_count_; }
  const SlotImage& candidate(int index) const { return candidates_[index]; }
  // The runtime tells which candidate it runs (-1: the model storage's image).
  void set_active(int candidate_index);

  static bool carries(std::uint32_t frame_id) { return protocol::passes(protocol::kUpdateRequestFrames, frame_id); }
  void handle_frame(const hal::CanFrame& frame, std::uint32_t cycle);
  // One bounded step of flash and hash work, hashing only as much as
  // `units` allow (capacity.hpp, kUpdate*Units); `geometry` is the running
  // model's, which a new image must match. Returns the units the update
  // spent since the last step, its frames included.
  std::uint32_t step(std::uint32_t cycle, const Geometry& geometry, std::uint32_t units);
  // Hashing an image, whose pace is the units each step gets.
  bool verifying() const { return phase_ == Phase::verifying || phase_ == Phase::rollback_verifying; }
  // A committed or rolled-back-to image waits for the runtime to load it.
  bool switch_pending() const { return switch_pending_; }

  protocol::UpdateState state() const;
  protocol::UpdateReason last_reason() const { return last_reason_; }
  int active_slot() const { return active_slot_; }  // -1: model storage
  std::uint32_t active_sequence() const { return active_sequence_; }
  std::uint32_t blocks_in_flash() const { return durable_; }

 private:
  enum class Phase : std::uint8_t {
    idle,
    erase_metadata,
    write_record,
    erase_image,
    receiving,
    verifying,
    write_header,
    rollback_verifying,
    revoke,
    switching,
    committed,
    failed,
  };

  bool transferring() const;
  void start_transfer(const protocol::UpdateCommandFrame& command);
  void handle_command(const protocol::UpdateCommandFrame& command);
  void handle_block(const hal::CanFrame& frame);
  void handle_data(const hal::CanFrame& frame);
  void operation_done();
  void start_work(const Geometry& geometry, std::uint32_t units);
  void start_operation(hal::FlashStatus started);
  void finish_verification(const Geometry& geometry);
  void fail(protocol::UpdateReason reason);
  void report(protocol::UpdateReason reason);
  std::uint32_t block_length(std::uint32_t block) const;
  std::uint32_t image_sectors() const;

  hal::Flash* flash_;
  hal::CanBus& can_;
  bool enabled_ = false;
  bool booted_ = false;
  SlotImage candidates_[kModelSlots];
  int candidate_count_ = 0;
  int active_slot_ = -1;
  std::uint32_t active_sequence_ = 0;

  Phase phase_ = Phase::idle;
  protocol::UpdateReason last_reason_ = protocol::UpdateReason::none;
  bool operation_running_ = false;
  std::uint32_t last_activity_cycle_ = 0;
  std::uint32_t frames_ = 0;  // update frames since the last step
  std::uint32_t cycle_ = 0;

  // The transfer.
  int target_slot_ = 0;
  SlotGeometry target_;
  TransferRecord record_;
  bool record_in_flash_ = false;  // record_ describes the target slot's record
  std::uint32_t total_blocks_ = 0;
  std::uint32_t erase_sector_ = 0;  // within the slot
  std::uint32_t received_ = 0;      // blocks received (in RAM or flash)
  std::uint32_t durable_ = 0;       // blocks in flash, progress byte included
  std::uint32_t acknowledged_ = 0;
  std::uint8_t program_stage_ = 0;  // 0 none, 1 data, 2 progress byte
  std::uint8_t blocks_[kUpdateWindowBlocks][protocol::kUpdateBlockBytes] = {};

  // The block whose data frames are arriving.
  bool incoming_ = false;
  std::uint16_t incoming_block_ = 0;
  std::uint8_t incoming_length_ = 0;
  std::uint32_t incoming_crc_ = 0;
  std::uint8_t incoming_frames_ = 0;

  std::uint8_t announced_digest_[kSha256Bytes] = {};
  std::uint8_t digest_parts_ = 0;  // bit k: part k received

  // Verification, and what is written at the commit point.
  Sha256 hash_;
  std::uint32_t hashed_ = 0;
  std::uint32_t hash_units_spent_ = 0;
  model::ImageScan scan_;  // parse_image()'s whole-image checks, beside the hash
  std::uint32_t committed_sequence_ = 0;
  int rollback_slot_ = -1;
  SlotHeader rollback_header_;
  std::uint8_t staged_[kSlotRecordBytes] = {};
  bool switch_pending_ = false;
  int switch_slot_ = -1;
  int revoke_slot_ = -1;
};

}  // namespace cdcr::firmware
