#pragma once
// A new model image over CAN into the inactive flash slot, while the runtime
// keeps running the active one (the protocol: protocol/messages.hpp, "Model
// updates"; the slots: model_slots.hpp). ModelUpdate is the coordinator the
// runtime calls; the work is in three parts under update/:
//   update_receiver.hpp  the digest, the blocks and their window, in RAM
//   slot_writer.hpp      the flash operations, the commit and the revoke,
//                        and which slot runs at boot
//   image_verifier.hpp   the hash, the image scan, the parse, the geometry
//
//   START (after the 8 digest frames)  erase the slot's metadata sector,
//                 write the transfer record, erase the image sectors;
//                 or resume the transfer the record in flash describes.
//                 A START without all of its digest goes on with the
//                 transfer under way if it names it, and is otherwise
//                 answered NO_TRANSFER: the sender sends both again.
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
#include "cdcr/firmware/update/image_verifier.hpp"
#include "cdcr/firmware/update/slot_writer.hpp"
#include "cdcr/firmware/update/update_receiver.hpp"
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
  bool enabled() const { return writer_.usable(); }

  // Boot: the committed images, newest first (hashed once, here).
  void boot();
  bool booted() const { return booted_; }
  int candidate_count() const { return writer_.candidate_count(); }
  const SlotImage& candidate(int index) const { return writer_.candidate(index); }
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
  int active_slot() const { return writer_.active_slot(); }  // -1: model storage
  std::uint32_t active_sequence() const { return writer_.active_sequence(); }
  std::uint32_t blocks_in_flash() const { return receiver_.durable(); }

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
  void answer(const UpdateReceiver::Answer& answer);
  void operation_done();
  void start_work(const Geometry& geometry, std::uint32_t units);
  void started(hal::FlashStatus status);
  void fail(protocol::UpdateReason reason);
  void report(protocol::UpdateReason reason);

  hal::CanBus& can_;
  UpdateReceiver receiver_;
  SlotWriter writer_;
  ImageVerifier verifier_;
  bool booted_ = false;

  Phase phase_ = Phase::idle;
  protocol::UpdateReason last_reason_ = protocol::UpdateReason::none;
  std::uint32_t last_activity_cycle_ = 0;
  std::uint32_t frames_ = 0;  // update frames since the last step
  std::uint32_t cycle_ = 0;
  std::uint32_t hash_units_spent_ = 0;

  // A rollback, and the switch the runtime makes after a commit or one.
  int rollback_slot_ = -1;
  SlotHeader rollback_header_;
  bool switch_pending_ = false;
  int switch_slot_ = -1;
  int revoke_slot_ = -1;
};

}  // namespace cdcr::firmware
