#include "cdcr/firmware/update/update_sender.hpp"

namespace cdcr::firmware {

namespace {

using protocol::UpdateReason;
using protocol::UpdateState;

}  // namespace

UpdateSender::UpdateSender(const std::uint8_t* image, std::uint32_t size_bytes) : image_(image), size_(size_bytes) {
  sha256(image_, size_, digest_);
  transfer_id_ = static_cast<std::uint16_t>(digest_[0] | (digest_[1] << 8));
  total_blocks_ = (size_ + protocol::kUpdateBlockBytes - 1) / protocol::kUpdateBlockBytes;
}

template <typename Message>
void UpdateSender::send(const Message& message, hal::CanBus& bus) {
  hal::CanFrame frame;
  protocol::encode(message, frame);
  bus.send(frame);
  frames_sent_ += 1;
}

void UpdateSender::start(hal::CanBus& bus, std::int64_t now) {
  for (std::uint8_t part = 0; part < 8; ++part) {
    protocol::UpdateDigest digest;
    digest.part = part;
    for (int i = 0; i < 4; ++i) digest.bytes[i] = digest_[4 * part + i];
    send(digest, bus);
  }
  protocol::UpdateCommandFrame command;
  command.command = protocol::UpdateCommand::start;
  command.transfer_id = transfer_id_;
  command.image_size = size_;
  send(command, bus);
  started_ = true;
  awaiting_start_ = true;
  window_ = 0;
  commit_sent_ = false;
  last_report_ = now;
}

void UpdateSender::restart(hal::CanBus& bus, std::int64_t now) {
  restarts_ += 1;
  start(bus, now);
}

void UpdateSender::rewind(std::uint32_t block) {
  if (block < next_) rewinds_ += 1;
  next_ = block;
}

void UpdateSender::on_report(const hal::CanFrame& frame, std::int64_t now, hal::CanBus& bus) {
  protocol::UpdateReport report;
  if (!protocol::update_report::kMessage.carries(frame.id) ||
      protocol::decode(frame, report) != protocol::DecodeStatus::ok) {
    return;
  }
  // Reports about another transfer are not ours, except those refusing
  // ours before it has an identity on the runtime.
  if (report.transfer_id != transfer_id_ && report.state != UpdateState::failed && report.reason != UpdateReason::busy &&
      report.reason != UpdateReason::too_large && report.reason != UpdateReason::no_transfer) {
    return;
  }
  if (outcome_ != Outcome::running) return;
  last_report_ = now;
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
      // The runtime restarted, timed the transfer out, or did not get all
      // of the digest before START: START again, which resumes.
      restart(bus, now);
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
    if (report.reason == UpdateReason::none) restart(bus, now);
    return;
  }
  if (report.next_block > acknowledged_) acknowledged_ = report.next_block;
  if (report.state != UpdateState::receiving) return;
  window_ = report.window;
  window_base_ = report.next_block;
  // After START, the runtime's flash says where to go on from.
  if (next_ < report.next_block || awaiting_start_) next_ = report.next_block;
  awaiting_start_ = false;
  if (acknowledged_ == total_blocks_ && !commit_sent_) {
    protocol::UpdateCommandFrame command;
    command.command = protocol::UpdateCommand::commit;
    command.transfer_id = transfer_id_;
    send(command, bus);
    commit_sent_ = true;
  }
}

void UpdateSender::receive_reports(hal::CanBus& bus, std::int64_t now) {
  hal::CanFrame frame;
  while (bus.receive(frame) == hal::CanStatus::ok) on_report(frame, now, bus);
}

void UpdateSender::pump(std::int64_t now, hal::CanBus& bus, std::uint32_t max_frames) {
  if (!started_ || outcome_ != Outcome::running) return;
  if (now - last_report_ > resend_after) {
    // Silence: ask again, and send again from the last acknowledged block.
    restart(bus, now);
    rewind(acknowledged_);
    return;
  }
  std::uint32_t frames = 0;
  while (next_ < total_blocks_ && next_ < window_base_ + window_ && frames + kFramesPerBlock <= max_frames) {
    send_block(next_, bus);
    next_ += 1;
    frames += kFramesPerBlock;
  }
}

void UpdateSender::send_block(std::uint32_t block, hal::CanBus& bus) {
  const std::uint32_t at = block * protocol::kUpdateBlockBytes;
  const std::uint32_t length = size_ - at < protocol::kUpdateBlockBytes ? size_ - at : protocol::kUpdateBlockBytes;
  protocol::UpdateBlock header;
  header.block = static_cast<std::uint16_t>(block);
  header.length = static_cast<std::uint8_t>(length);
  header.crc = protocol::update_block_crc(header.block, image_ + at, length);
  send(header, bus);
  for (std::uint32_t offset = 0; offset < length; offset += 8) {
    protocol::UpdateData data;
    for (std::uint32_t i = 0; i < 8 && offset + i < length; ++i) data.bytes[i] = image_[at + offset + i];
    send(data, bus);
  }
}

}  // namespace cdcr::firmware
