#pragma once
// The host's side of a model update (firmware/protocol/messages.hpp, "Model
// updates"), independent of the bus: feed it the runtime's UPDATE_REPORT
// frames and the time, take the frames it wants sent. `cdcr deploy` drives
// it on SocketCAN; the tests drive it on the simulated bus.
//
// Go-back-N: blocks go out up to the window the last report granted from
// its NEXT_BLOCK; a report refusing a block (corrupted, out of order,
// missing data) rewinds to NEXT_BLOCK; silence for resend_after_ms rewinds
// too. Restarting the sender (or the runtime) resumes: START with the same
// image resumes from the blocks the runtime has in flash.

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include <cdcr/firmware/protocol.hpp>
#include <cdcr/firmware/sha256.hpp>

namespace cdcr::deploy {

class UpdateSender {
 public:
  enum class Outcome { running, committed, refused };

  explicit UpdateSender(std::vector<std::uint8_t> image) : image_(std::move(image)) {
    firmware::sha256(image_.data(), image_.size(), digest_);
    transfer_id_ = static_cast<std::uint16_t>(digest_[0] | (digest_[1] << 8));
    total_blocks_ = static_cast<std::uint32_t>((image_.size() + kBlock - 1) / kBlock);
  }

  std::uint32_t total_blocks() const { return total_blocks_; }
  std::uint32_t acknowledged_blocks() const { return acknowledged_; }
  Outcome outcome() const { return outcome_; }
  firmware::protocol::UpdateReason refusal() const { return refusal_; }
  std::uint32_t frames_sent() const { return frames_sent_; }
  std::uint32_t rewinds() const { return rewinds_; }
  std::uint16_t transfer_id() const { return transfer_id_; }
  const std::uint8_t (&digest() const)[firmware::kSha256Bytes] { return digest_; }

  // The digest and START: first, and again whenever the sender restarts.
  void start(std::vector<hal::CanFrame>& out) {
    for (std::uint8_t part = 0; part < 8; ++part) {
      firmware::protocol::UpdateDigest digest;
      digest.part = part;
      for (int i = 0; i < 4; ++i) digest.bytes[i] = digest_[4 * part + i];
      push(digest, out);
    }
    firmware::protocol::UpdateCommandFrame command;
    command.command = firmware::protocol::UpdateCommand::start;
    command.transfer_id = transfer_id_;
    command.image_size = static_cast<std::uint32_t>(image_.size());
    push(command, out);
    started_ = true;
    awaiting_start_ = true;
    window_ = 0;
    commit_sent_ = false;
  }

  void on_report(const hal::CanFrame& frame, std::int64_t now_ms, std::vector<hal::CanFrame>& out) {
    using firmware::protocol::UpdateReason;
    using firmware::protocol::UpdateState;
    firmware::protocol::UpdateReport report;
    if (firmware::protocol::decode(frame, report) != firmware::protocol::DecodeStatus::ok) return;
    if (report.transfer_id != transfer_id_ && report.state != UpdateState::failed &&
        report.reason != UpdateReason::busy && report.reason != UpdateReason::too_large) {
      return;  // about another transfer
    }
    last_report_ms_ = now_ms;
    switch (report.reason) {
      case UpdateReason::none:
      case UpdateReason::duplicate:
        break;
      case UpdateReason::corrupted:
      case UpdateReason::out_of_order:
      case UpdateReason::missing_block:
        rewind(report.next_block);
        break;
      case UpdateReason::no_transfer:
        // The runtime restarted (or timed the transfer out): START resumes.
        start(out);
        return;
      default:
        outcome_ = Outcome::refused;
        refusal_ = report.reason;
        return;
    }
    if (report.state == UpdateState::committed) {
      outcome_ = Outcome::committed;
      acknowledged_ = total_blocks_;
      return;
    }
    if (report.state == UpdateState::failed) {
      // A failed transfer after a restart of ours: start again.
      if (report.reason == UpdateReason::none) start(out);
      return;
    }
    acknowledged_ = std::max<std::uint32_t>(acknowledged_, report.next_block);
    if (report.state == UpdateState::receiving) {
      window_ = report.window;
      window_base_ = report.next_block;
      // After START, the runtime's flash says where to go on from.
      if (next_ < report.next_block || awaiting_start_) next_ = report.next_block;
      awaiting_start_ = false;
    }
    if (report.state == UpdateState::receiving && acknowledged_ == total_blocks_ && !commit_sent_) {
      firmware::protocol::UpdateCommandFrame command;
      command.command = firmware::protocol::UpdateCommand::commit;
      command.transfer_id = transfer_id_;
      push(command, out);
      commit_sent_ = true;
    }
  }

  // Blocks the window allows, at most max_frames frames.
  void pump(std::int64_t now_ms, std::vector<hal::CanFrame>& out, std::size_t max_frames) {
    if (!started_ || outcome_ != Outcome::running) return;
    if (now_ms - last_report_ms_ > resend_after_ms) {
      // Silence: ask again, and send again from the last acknowledged block.
      last_report_ms_ = now_ms;
      if (commit_sent_) {
        commit_sent_ = false;
      }
      start(out);
      rewind(acknowledged_);
      return;
    }
    while (next_ < total_blocks_ && next_ < window_base_ + window_ && out.size() + kFramesPerBlock + 1 <= max_frames) {
      send_block(next_, out);
      next_ += 1;
    }
  }

  // For tests: the frames of one block, as sent.
  void send_block(std::uint32_t block, std::vector<hal::CanFrame>& out) {
    const std::size_t at = std::size_t(block) * kBlock;
    const std::size_t length = std::min<std::size_t>(kBlock, image_.size() - at);
    firmware::protocol::UpdateBlock header;
    header.block = static_cast<std::uint16_t>(block);
    header.length = static_cast<std::uint8_t>(length);
    header.crc = firmware::protocol::update_block_crc(header.block, image_.data() + at, length);
    push(header, out);
    for (std::size_t offset = 0; offset < length; offset += 8) {
      firmware::protocol::UpdateData data;
      for (std::size_t i = 0; i < 8 && offset + i < length; ++i) data.bytes[i] = image_[at + offset + i];
      push(data, out);
    }
  }

  std::int64_t resend_after_ms = 200;

 private:
  static constexpr std::size_t kBlock = firmware::protocol::kUpdateBlockBytes;
  static constexpr std::size_t kFramesPerBlock = 1 + firmware::protocol::kUpdateDataFramesPerBlock;

  template <typename Frame>
  void push(const Frame& message, std::vector<hal::CanFrame>& out) {
    hal::CanFrame frame;
    firmware::protocol::encode(message, frame);
    out.push_back(frame);
    frames_sent_ += 1;
  }

  void rewind(std::uint32_t block) {
    if (block < next_) rewinds_ += 1;
    next_ = block;
  }

  std::vector<std::uint8_t> image_;
  std::uint8_t digest_[firmware::kSha256Bytes] = {};
  std::uint16_t transfer_id_ = 0;
  std::uint32_t total_blocks_ = 0;
  std::uint32_t next_ = 0;
  std::uint32_t acknowledged_ = 0;
  std::uint32_t window_base_ = 0;
  std::uint32_t window_ = 0;
  bool started_ = false;
  bool awaiting_start_ = false;
  bool commit_sent_ = false;
  std::int64_t last_report_ms_ = 0;
  std::uint32_t frames_sent_ = 0;
  std::uint32_t rewinds_ = 0;
  Outcome outcome_ = Outcome::running;
  firmware::protocol::UpdateReason refusal_ = firmware::protocol::UpdateReason::none;
};

}  // namespace cdcr::deploy
