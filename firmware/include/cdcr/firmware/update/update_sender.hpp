#pragma once
// The sending side of a model update (protocol/messages.hpp, "Model
// updates"): the eight digest frames and START, the blocks the runtime's
// window allows, COMMIT, and the runtime's UPDATE_REPORT frames read back.
// `cdcr deploy` drives it on SocketCAN, the QEMU update budget program on
// the board's mailbox bus, the tests on the simulated bus.
//
// Go-back-N: blocks go out up to the window the last report granted from
// its NEXT_BLOCK; a report refusing a block (corrupted, out of order,
// missing data) rewinds to NEXT_BLOCK. Lost frames in either direction are
// resent: a report saying the runtime has no transfer (it restarted, timed
// out, or START came without all of its digest) and silence for
// `resend_after` both send the digest and START again, which resumes from
// the blocks the runtime has in flash. A restarted sender resumes the same
// way.
//
// Time is whatever unit the caller counts in, as long as `now` and
// `resend_after` share it: milliseconds for `cdcr deploy`, cycles on the
// board. The image stays the caller's; no allocation, no exceptions.

#include <cstdint>

#include "cdcr/firmware/protocol.hpp"
#include "cdcr/firmware/sha256.hpp"
#include "cdcr/hal/can_bus.hpp"

namespace cdcr::firmware {

class UpdateSender {
 public:
  enum class Outcome : std::uint8_t { running, committed, refused };
  static constexpr std::uint32_t kFramesPerBlock = 1 + protocol::kUpdateDataFramesPerBlock;

  // `image` must outlive the sender.
  UpdateSender(const std::uint8_t* image, std::uint32_t size_bytes);

  // The digest frames and START: first, and again whenever the sender
  // restarts.
  void start(hal::CanBus& bus, std::int64_t now);
  // One frame the runtime sent; frames other than UPDATE_REPORT are ignored.
  void on_report(const hal::CanFrame& frame, std::int64_t now, hal::CanBus& bus);
  // Every frame waiting on `bus`, through on_report().
  void receive_reports(hal::CanBus& bus, std::int64_t now);
  // The blocks the window allows, whole blocks of at most `max_frames`
  // frames together; after silence, a restart instead.
  void pump(std::int64_t now, hal::CanBus& bus, std::uint32_t max_frames);
  // One block's header and data frames, as pump() sends them.
  void send_block(std::uint32_t block, hal::CanBus& bus);

  Outcome outcome() const { return outcome_; }
  protocol::UpdateReason refusal() const { return refusal_; }
  std::uint32_t total_blocks() const { return total_blocks_; }
  std::uint32_t acknowledged_blocks() const { return acknowledged_; }
  std::uint16_t transfer_id() const { return transfer_id_; }
  const std::uint8_t (&digest() const)[kSha256Bytes] { return digest_; }
  // Figures: frames handed to the bus, rewinds of the next block to send,
  // and restarts (digest and START again) after the first START.
  std::uint32_t frames_sent() const { return frames_sent_; }
  std::uint32_t rewinds() const { return rewinds_; }
  std::uint32_t restarts() const { return restarts_; }

  std::int64_t resend_after = 200;

 private:
  template <typename Message>
  void send(const Message& message, hal::CanBus& bus);
  void restart(hal::CanBus& bus, std::int64_t now);
  void rewind(std::uint32_t block);

  const std::uint8_t* image_;
  std::uint32_t size_;
  std::uint8_t digest_[kSha256Bytes] = {};
  std::uint16_t transfer_id_ = 0;
  std::uint32_t total_blocks_ = 0;
  std::uint32_t next_ = 0;  // the next block to send
  std::uint32_t acknowledged_ = 0;
  std::uint32_t window_base_ = 0;
  std::uint32_t window_ = 0;
  bool started_ = false;
  bool awaiting_start_ = false;  // the next receiving report says where to go on from
  bool commit_sent_ = false;
  std::int64_t last_report_ = 0;
  std::uint32_t frames_sent_ = 0;
  std::uint32_t rewinds_ = 0;
  std::uint32_t restarts_ = 0;
  Outcome outcome_ = Outcome::running;
  protocol::UpdateReason refusal_ = protocol::UpdateReason::none;
};

}  // namespace cdcr::firmware
