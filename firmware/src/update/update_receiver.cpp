#include "cdcr/firmware/update/update_receiver.hpp"

#include <cstring>

namespace cdcr::firmware {

namespace {

using protocol::UpdateReason;

}  // namespace

UpdateReceiver::Answer UpdateReceiver::on_digest(const hal::CanFrame& frame) {
  Answer answer;
  protocol::UpdateDigest part;
  if (protocol::decode(frame, part) != protocol::DecodeStatus::ok) {
    answer.add(UpdateReason::malformed);
    return answer;
  }
  // A part repeated or out of order lands where it belongs.
  std::memcpy(announced_digest_ + 4 * part.part, part.bytes, 4);
  digest_parts_ = static_cast<std::uint8_t>(digest_parts_ | (1u << part.part));
  return answer;
}

void UpdateReceiver::begin(std::uint32_t image_size, std::uint32_t blocks_in_flash) {
  image_size_ = image_size;
  total_blocks_ = (image_size + protocol::kUpdateBlockBytes - 1) / protocol::kUpdateBlockBytes;
  durable_ = received_ = blocks_in_flash;
  incoming_ = false;
}

std::uint32_t UpdateReceiver::block_length(std::uint32_t block) const {
  const std::uint32_t start = block * protocol::kUpdateBlockBytes;
  return image_size_ - start < protocol::kUpdateBlockBytes ? image_size_ - start : protocol::kUpdateBlockBytes;
}

UpdateReceiver::Answer UpdateReceiver::on_block(const hal::CanFrame& frame, bool receiving) {
  Answer answer;
  protocol::UpdateBlock block;
  const bool decoded = protocol::decode(frame, block) == protocol::DecodeStatus::ok;
  if (incoming_) {
    // The same header again before any of its data: nothing was lost.
    if (decoded && block.block == incoming_block_ && block.length == incoming_length_ &&
        block.crc == incoming_crc_ && incoming_frames_ == 0) {
      return answer;
    }
    incoming_ = false;
    answer.add(UpdateReason::missing_block);
  }
  if (!decoded) {
    answer.add(UpdateReason::malformed);
    return answer;
  }
  if (!receiving) {
    answer.add(UpdateReason::no_transfer);
    return answer;
  }
  if (block.block < received_) {
    answer.add(UpdateReason::duplicate);
    return answer;
  }
  if (block.block > received_ || block.block >= total_blocks_ || received_ - durable_ >= kUpdateWindowBlocks) {
    answer.add(UpdateReason::out_of_order);
    return answer;
  }
  if (block.length != block_length(block.block)) {
    answer.add(UpdateReason::malformed);
    return answer;
  }
  incoming_ = true;
  incoming_block_ = block.block;
  incoming_length_ = block.length;
  incoming_crc_ = block.crc;
  incoming_frames_ = 0;
  return answer;
}

UpdateReceiver::Answer UpdateReceiver::on_data(const hal::CanFrame& frame) {
  Answer answer;
  protocol::UpdateData data;
  // Data of no accepted block (after a refused header) is dropped quietly.
  if (!incoming_ || protocol::decode(frame, data) != protocol::DecodeStatus::ok) return answer;
  std::uint8_t* buffer = blocks_[incoming_block_ % kUpdateWindowBlocks];
  const std::uint32_t at = 8u * incoming_frames_;
  const std::uint32_t take = incoming_length_ - at < 8 ? incoming_length_ - at : 8;
  std::memcpy(buffer + at, data.bytes, take);
  incoming_frames_ += 1;
  if (at + take < incoming_length_) return answer;
  incoming_ = false;
  // A data frame lost, repeated or reordered shows here.
  if (protocol::update_block_crc(incoming_block_, buffer, incoming_length_) != incoming_crc_) {
    answer.add(UpdateReason::corrupted);
    return answer;
  }
  received_ += 1;
  return answer;
}

bool UpdateReceiver::block_durable() {
  durable_ += 1;
  return durable_ - acknowledged_ >= std::uint32_t(kUpdateAckEveryBlocks) || durable_ == received_;
}

}  // namespace cdcr::firmware
