#pragma once
// The two model slots (A and B) in the HAL's flash, and what decides at boot
// which one runs: the slot whose header is intact, not revoked and whose
// image hashes to the header's SHA-256, with the higher sequence number, in
// the manner of MCUboot. Written once for every backend.
//
// The flash's sectors are split in two halves, slot A then slot B. Each slot:
//   sector 0 (metadata):
//     0 ..  63   transfer record: the transfer being written into the slot
//                (its id, size and SHA-256), CRC-protected; written once,
//                after the erase that starts a transfer.
//     64 ..      progress: one byte per block, programmed to 0x00 once the
//                block's data is in flash; a torn byte reads as not done.
//     last 64    slot header: magic, sequence, image size, SHA-256 and a
//                CRC over those, written last, when the image is committed;
//                then the revoke word, programmed to 0 by a rollback (any
//                value but 0xFFFFFFFF revokes, so a torn revoke revokes).
//   sectors 1 ..: the image, read in place.
// A torn header fails its CRC, a torn image its SHA-256: neither is ever
// chosen, and the other slot (or the model storage) runs.

#include <cstdint>

#include "cdcr/firmware/sha256.hpp"
#include "cdcr/hal/flash.hpp"
#include "cdcr/hal/model_storage.hpp"
#include "cdcr/model/flash_image.hpp"

namespace cdcr::firmware {

inline constexpr int kModelSlots = 2;
inline constexpr std::uint32_t kSlotRecordBytes = 64;
inline constexpr std::uint32_t kSlotHeaderBytes = 64;

struct SlotGeometry {
  std::uint32_t offset = 0;          // of the slot's metadata sector
  std::uint32_t sector_bytes = 0;
  std::uint32_t sectors = 0;         // metadata included
  std::uint32_t image_offset() const { return offset + sector_bytes; }
  std::uint32_t image_capacity() const { return (sectors - 1) * sector_bytes; }
  std::uint32_t progress_offset() const { return offset + kSlotRecordBytes; }
  std::uint32_t progress_capacity() const { return sector_bytes - kSlotRecordBytes - kSlotHeaderBytes; }
  std::uint32_t header_offset() const { return offset + sector_bytes - kSlotHeaderBytes; }
};

// Slot `index` (0: A, 1: B) of `flash`; sectors == 0 when the flash is too
// small for two slots of a metadata sector and an image sector each.
SlotGeometry slot_geometry(const hal::Flash& flash, int index);

struct TransferRecord {
  std::uint16_t transfer_id = 0;
  std::uint32_t image_size = 0;
  std::uint8_t digest[kSha256Bytes] = {};
};

struct SlotHeader {
  std::uint32_t sequence = 0;
  std::uint32_t image_size = 0;
  std::uint8_t digest[kSha256Bytes] = {};
};

// The bytes to program, and the check of what is in flash.
void encode_record(const TransferRecord& record, std::uint8_t (&bytes)[kSlotRecordBytes]);
bool decode_record(const std::uint8_t* bytes, TransferRecord& record);
// The header without its revoke word (kSlotHeaderBytes - 4 bytes are written).
void encode_header(const SlotHeader& header, std::uint8_t (&bytes)[kSlotHeaderBytes - 4]);
// Intact (magic and CRC) and not revoked.
bool decode_header(const std::uint8_t* bytes, SlotHeader& header);
inline constexpr std::uint32_t kSlotRevokeOffset = kSlotHeaderBytes - 4;

// A slot holding a committed image.
struct SlotImage {
  int slot = -1;  // 0: A, 1: B
  std::uint32_t sequence = 0;
  hal::MemoryRegion region;
  // The image's CRC-32 and finite payload, checked when it was hashed
  // (boot, commit, rollback) so that loading it reads no whole image in one
  // cycle; not done(): not scanned.
  model::ImageScan scan;
};

// The slots whose header is intact and unrevoked and whose image matches
// its SHA-256, newest first. Hashes (and scans) every candidate: boot time
// only.
int committed_slots(const hal::Flash& flash, SlotImage (&out)[kModelSlots]);
// The same without the hash: what a header says (for the running system,
// whose images were hashed when they were committed or at boot).
bool read_slot_header(const hal::Flash& flash, int slot, SlotHeader& header);

}  // namespace cdcr::firmware
