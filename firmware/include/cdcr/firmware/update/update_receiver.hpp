#pragma once
// The receiving side of a model transfer, in RAM: the announced digest, the
// block whose data frames are arriving, and the window of blocks received
// but not yet in flash (go-back-N, kUpdateWindowBlocks). What the frames
// call for is returned as reasons to report; the flash steps that make a
// block durable are the slot writer's (slot_writer.hpp).
//
// Lost, repeated or reordered frames are refused as what they look like --
// a missing, duplicate, out-of-order or corrupted block -- so that the
// sender rewinds and sends again; none of them is "malformed".

#include <cstdint>

#include "cdcr/firmware/capacity.hpp"
#include "cdcr/firmware/protocol.hpp"
#include "cdcr/firmware/sha256.hpp"
#include "cdcr/hal/can_bus.hpp"

namespace cdcr::firmware {

class UpdateReceiver {
 public:
  // The reports one frame calls for, in order.
  struct Answer {
    std::uint8_t count = 0;
    protocol::UpdateReason reasons[2] = {};
    void add(protocol::UpdateReason reason) { reasons[count++] = reason; }
  };

  // UPDATE_DIGEST: one of the eight parts START needs.
  Answer on_digest(const hal::CanFrame& frame);
  bool digest_complete() const { return digest_parts_ == kAllDigestParts; }
  const std::uint8_t (&announced_digest() const)[kSha256Bytes] { return announced_digest_; }
  // After START took the digest: the next START needs all eight parts again.
  void forget_digest() { digest_parts_ = 0; }

  // A transfer of `image_size` bytes whose first `blocks_in_flash` blocks
  // are in flash already (0, or a resumed transfer's).
  void begin(std::uint32_t image_size, std::uint32_t blocks_in_flash);
  // The block whose data was arriving is given up (abort, failure).
  void drop_incoming() { incoming_ = false; }

  // UPDATE_BLOCK, while `receiving` (the slot is prepared).
  Answer on_block(const hal::CanFrame& frame, bool receiving);
  // UPDATE_DATA; a block complete and intact counts as received.
  Answer on_data(const hal::CanFrame& frame);

  std::uint32_t total_blocks() const { return total_blocks_; }
  std::uint32_t received() const { return received_; }
  std::uint32_t durable() const { return durable_; }
  std::uint32_t block_length(std::uint32_t block) const;
  // The next block to program into flash, held in RAM.
  bool block_waiting() const { return durable_ < received_; }
  const std::uint8_t* waiting_block() const { return blocks_[durable_ % kUpdateWindowBlocks]; }
  // The waiting block and its progress byte are in flash; true when that
  // calls for a report (every kUpdateAckEveryBlocks, or the window drained).
  bool block_durable();
  // A report told the sender about every durable block.
  void acknowledged() { acknowledged_ = durable_; }

 private:
  static constexpr std::uint8_t kAllDigestParts = 0xFF;

  std::uint32_t image_size_ = 0;
  std::uint32_t total_blocks_ = 0;
  std::uint32_t received_ = 0;  // blocks received (in RAM or flash)
  std::uint32_t durable_ = 0;   // blocks in flash, progress byte included
  std::uint32_t acknowledged_ = 0;
  std::uint8_t blocks_[kUpdateWindowBlocks][protocol::kUpdateBlockBytes] = {};

  // The block whose data frames are arriving.
  bool incoming_ = false;
  std::uint16_t incoming_block_ = 0;
  std::uint8_t incoming_length_ = 0;
  std::uint32_t incoming_crc_ = 0;
  std::uint8_t incoming_frames_ = 0;

  std::uint8_t announced_digest_[kSha256Bytes] = {};
  std::uint8_t digest_parts_ = 0;  // bit k: part k received
};

}  // namespace cdcr::firmware
