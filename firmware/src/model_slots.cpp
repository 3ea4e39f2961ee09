#include "cdcr/firmware/model_slots.hpp"

#include <cstring>

#include "cdcr/model/crc32.hpp"

namespace cdcr::firmware {

namespace {

constexpr std::uint32_t kRecordMagic = 0x52544443u;  // bytes "CDTR"
constexpr std::uint32_t kHeaderMagic = 0x48534443u;  // bytes "CDSH"
constexpr std::uint32_t kNotRevoked = 0xFFFFFFFFu;

void put_u32(std::uint8_t* bytes, std::uint32_t value) {
  for (int i = 0; i < 4; ++i) bytes[i] = static_cast<std::uint8_t>(value >> (8 * i));
}
std::uint32_t get_u32(const std::uint8_t* bytes) {
  return std::uint32_t(bytes[0]) | (std::uint32_t(bytes[1]) << 8) | (std::uint32_t(bytes[2]) << 16) |
         (std::uint32_t(bytes[3]) << 24);
}

// Record: magic, id (u16) and 2 zero bytes, size, digest at 12, CRC at 60.
// Header: magic, sequence, size, digest at 12, CRC at 56, revoke word at 60.
constexpr std::uint32_t kDigestAt = 12;
constexpr std::uint32_t kRecordCrcAt = kSlotRecordBytes - 4;
constexpr std::uint32_t kHeaderCrcAt = kSlotRevokeOffset - 4;

}  // namespace

SlotGeometry slot_geometry(const hal::Flash& flash, int index) {
  SlotGeometry g;
  const std::uint32_t per_slot = flash.sector_count() / kModelSlots;
  if (per_slot < 2 || flash.sector_bytes() < 2 * (kSlotRecordBytes + kSlotHeaderBytes)) return g;
  g.sector_bytes = flash.sector_bytes();
  g.sectors = per_slot;
  g.offset = static_cast<std::uint32_t>(index) * per_slot * flash.sector_bytes();
  return g;
}

void encode_record(const TransferRecord& record, std::uint8_t (&bytes)[kSlotRecordBytes]) {
  std::memset(bytes, 0, sizeof(bytes));
  put_u32(bytes, kRecordMagic);
  bytes[4] = static_cast<std::uint8_t>(record.transfer_id & 0xFF);
  bytes[5] = static_cast<std::uint8_t>(record.transfer_id >> 8);
  put_u32(bytes + 8, record.image_size);
  std::memcpy(bytes + kDigestAt, record.digest, kSha256Bytes);
  put_u32(bytes + kRecordCrcAt, model::crc32(bytes, kRecordCrcAt));
}

bool decode_record(const std::uint8_t* bytes, TransferRecord& record) {
  if (get_u32(bytes) != kRecordMagic || get_u32(bytes + kRecordCrcAt) != model::crc32(bytes, kRecordCrcAt)) {
    return false;
  }
  record.transfer_id = static_cast<std::uint16_t>(bytes[4] | (bytes[5] << 8));
  record.image_size = get_u32(bytes + 8);
  std::memcpy(record.digest, bytes + kDigestAt, kSha256Bytes);
  return true;
}

void encode_header(const SlotHeader& header, std::uint8_t (&bytes)[kSlotHeaderBytes - 4]) {
  std::memset(bytes, 0, sizeof(bytes));
  put_u32(bytes, kHeaderMagic);
  put_u32(bytes + 4, header.sequence);
  put_u32(bytes + 8, header.image_size);
  std::memcpy(bytes + kDigestAt, header.digest, kSha256Bytes);
  put_u32(bytes + kHeaderCrcAt, model::crc32(bytes, kHeaderCrcAt));
}

bool decode_header(const std::uint8_t* bytes, SlotHeader& header) {
  if (get_u32(bytes) != kHeaderMagic || get_u32(bytes + kHeaderCrcAt) != model::crc32(bytes, kHeaderCrcAt) ||
      get_u32(bytes + kSlotRevokeOffset) != kNotRevoked) {
    return false;
  }
  header.sequence = get_u32(bytes + 4);
  header.image_size = get_u32(bytes + 8);
  std::memcpy(header.digest, bytes + kDigestAt, kSha256Bytes);
  return true;
}

bool read_slot_header(const hal::Flash& flash, int slot, SlotHeader& header) {
  const SlotGeometry g = slot_geometry(flash, slot);
  if (g.sectors == 0) return false;
  return decode_header(flash.read() + g.header_offset(), header) && header.image_size > 0 &&
         header.image_size <= g.image_capacity();
}

int committed_slots(const hal::Flash& flash, SlotImage (&out)[kModelSlots]) {
  int count = 0;
  for (int slot = 0; slot < kModelSlots; ++slot) {
    SlotHeader header;
    if (!read_slot_header(flash, slot, header)) continue;
    const std::uint8_t* image = flash.read() + slot_geometry(flash, slot).image_offset();
    std::uint8_t digest[kSha256Bytes];
    sha256(image, header.image_size, digest);
    if (std::memcmp(digest, header.digest, kSha256Bytes) != 0) continue;
    out[count] = SlotImage{slot, header.sequence, {image, header.image_size}, {}};
    out[count].scan.begin(image, header.image_size);
    out[count].scan.step(header.image_size);
    count += 1;
  }
  if (count == 2 && out[1].sequence > out[0].sequence) {
    const SlotImage newer = out[1];
    out[1] = out[0];
    out[0] = newer;
  }
  return count;
}

}  // namespace cdcr::firmware
