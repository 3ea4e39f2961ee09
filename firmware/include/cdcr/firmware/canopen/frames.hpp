#pragma once
// The CANopen frames (CiA 301) the runtime exchanges with CiA 402 drives:
// NMT, SYNC, expedited SDO, the drives' process data, heartbeat and EMCY.
// Identifiers follow the predefined connection set (CiA 301, 7.3.5): a
// function code in the top four bits, the node id (1..127) in the low
// seven. Every multi-byte value is little-endian. Decoders check the
// identifier, the length and the reserved bits, and refuse anything else:
// a frame that is not exactly what CiA 301 says is not acted on.

#include <cstdint>

#include "cdcr/hal/can_bus.hpp"

namespace cdcr::firmware::canopen {

using NodeId = std::uint8_t;
inline constexpr NodeId kMinNodeId = 1;
inline constexpr NodeId kMaxNodeId = 127;
inline constexpr bool is_valid_node(unsigned node) { return node >= kMinNodeId && node <= kMaxNodeId; }

// Function codes of the predefined connection set.
inline constexpr std::uint32_t kNmtId = 0x000;
inline constexpr std::uint32_t kSyncId = 0x080;
inline constexpr std::uint32_t kEmcyBase = 0x080;
inline constexpr std::uint32_t kTpdo1Base = 0x180;  // drive → manager
inline constexpr std::uint32_t kRpdo1Base = 0x200;  // manager → drive
inline constexpr std::uint32_t kSdoServerBase = 0x580;  // the drive's SDO replies
inline constexpr std::uint32_t kSdoClientBase = 0x600;  // requests to the drive
inline constexpr std::uint32_t kHeartbeatBase = 0x700;
inline constexpr std::uint32_t kFunctionMask = 0x780;
inline constexpr std::uint32_t kNodeMask = 0x07F;

// ---- NMT (CiA 301, 7.2.8.3.1): id 0, [command, node]; node 0 is every node.
enum class NmtCommand : std::uint8_t {
  start = 0x01,
  stop = 0x02,
  enter_pre_operational = 0x80,
  reset_node = 0x81,
  reset_communication = 0x82,
};

inline hal::CanFrame nmt_frame(NmtCommand command, NodeId node) {
  hal::CanFrame frame;
  frame.id = kNmtId;
  frame.dlc = 2;
  frame.data[0] = static_cast<std::uint8_t>(command);
  frame.data[1] = node;
  return frame;
}

// ---- SYNC (CiA 301, 7.2.5): no data (the counter is not used).
inline hal::CanFrame sync_frame() {
  hal::CanFrame frame;
  frame.id = kSyncId;
  frame.dlc = 0;
  return frame;
}

// ---- Heartbeat (CiA 301, 7.2.8.3.2.2): the producer's NMT state in one
// byte; bit 7 (the node-guarding toggle) is reserved and 0.
enum class NmtState : std::uint8_t {
  boot_up = 0x00,
  stopped = 0x04,
  operational = 0x05,
  pre_operational = 0x7F,
};

struct Heartbeat {
  NodeId node = 0;
  NmtState state = NmtState::boot_up;
};

inline hal::CanFrame heartbeat_frame(const Heartbeat& heartbeat) {
  hal::CanFrame frame;
  frame.id = kHeartbeatBase + heartbeat.node;
  frame.dlc = 1;
  frame.data[0] = static_cast<std::uint8_t>(heartbeat.state);
  return frame;
}

inline bool decode_heartbeat(const hal::CanFrame& frame, Heartbeat& heartbeat) {
  if (frame.fd() || (frame.id & kFunctionMask) != kHeartbeatBase || frame.dlc != 1) return false;
  const NodeId node = static_cast<NodeId>(frame.id & kNodeMask);
  const std::uint8_t state = frame.data[0];
  if (!is_valid_node(node)) return false;
  if (state != 0x00 && state != 0x04 && state != 0x05 && state != 0x7F) return false;
  heartbeat.node = node;
  heartbeat.state = static_cast<NmtState>(state);
  return true;
}

// ---- EMCY (CiA 301, 7.2.7): error code, error register, five bytes of
// the manufacturer's. Error code 0x0000 is "error reset or no error".
struct Emergency {
  NodeId node = 0;
  std::uint16_t error_code = 0;
  std::uint8_t error_register = 0;
  std::uint8_t manufacturer[5] = {};
  bool clears() const { return error_code == 0; }
};

inline hal::CanFrame emergency_frame(const Emergency& emergency) {
  hal::CanFrame frame;
  frame.id = kEmcyBase + emergency.node;
  frame.dlc = 8;
  frame.data[0] = static_cast<std::uint8_t>(emergency.error_code);
  frame.data[1] = static_cast<std::uint8_t>(emergency.error_code >> 8);
  frame.data[2] = emergency.error_register;
  for (int i = 0; i < 5; ++i) frame.data[3 + i] = emergency.manufacturer[i];
  return frame;
}

// The SYNC shares function code 0x080 with EMCY: node 0 is the SYNC.
inline bool decode_emergency(const hal::CanFrame& frame, Emergency& emergency) {
  if (frame.fd() || (frame.id & kFunctionMask) != kEmcyBase || frame.dlc != 8) return false;
  const NodeId node = static_cast<NodeId>(frame.id & kNodeMask);
  if (!is_valid_node(node)) return false;
  emergency.node = node;
  emergency.error_code = static_cast<std::uint16_t>(frame.data[0] | (frame.data[1] << 8));
  emergency.error_register = frame.data[2];
  for (int i = 0; i < 5; ++i) emergency.manufacturer[i] = frame.data[3 + i];
  return true;
}

// ---- Expedited SDO (CiA 301, 7.2.4.3): an object of up to four bytes
// written or read in one request and one reply. The manager is the client;
// the drive's SDO server answers on 0x580 + node.
struct ObjectAddress {
  std::uint16_t index = 0;
  std::uint8_t subindex = 0;
  friend constexpr bool operator==(ObjectAddress a, ObjectAddress b) {
    return a.index == b.index && a.subindex == b.subindex;
  }
};

namespace sdo {
// Command bytes: ccs/scs in bits 7..5; for an expedited transfer n (the
// bytes that do not hold data) in bits 3..2, e (expedited) bit 1, s (size
// indicated) bit 0.
inline constexpr std::uint8_t kInitiateDownload = 0x20;        // ccs 1
inline constexpr std::uint8_t kInitiateUpload = 0x40;          // ccs 2
inline constexpr std::uint8_t kDownloadResponse = 0x60;        // scs 3
inline constexpr std::uint8_t kUploadResponse = 0x40;          // scs 2
inline constexpr std::uint8_t kAbort = 0x80;                   // cs 4
inline constexpr std::uint8_t kExpedited = 0x02;
inline constexpr std::uint8_t kSizeIndicated = 0x01;

// Abort codes (CiA 301, table 22) the manager names in its fault detail.
inline constexpr std::uint32_t kAbortTimeout = 0x05040000;
inline constexpr std::uint32_t kAbortUnsupportedAccess = 0x06010000;
inline constexpr std::uint32_t kAbortReadOnly = 0x06010002;
inline constexpr std::uint32_t kAbortNoObject = 0x06020000;
inline constexpr std::uint32_t kAbortNotMappable = 0x06040041;
inline constexpr std::uint32_t kAbortNoSubindex = 0x06090011;
inline constexpr std::uint32_t kAbortValueRange = 0x06090030;
inline constexpr std::uint32_t kAbortGeneral = 0x08000000;
inline constexpr std::uint32_t kAbortDeviceState = 0x08000022;
}  // namespace sdo

// A write of `size` bytes (1..4) of `value` to the object.
inline bool sdo_download_frame(NodeId node, ObjectAddress object, std::uint32_t value, std::uint8_t size,
                               hal::CanFrame& frame) {
  if (!is_valid_node(node) || size < 1 || size > 4) return false;
  frame = hal::CanFrame{};
  frame.id = kSdoClientBase + node;
  frame.dlc = 8;
  frame.data[0] = static_cast<std::uint8_t>(sdo::kInitiateDownload | ((4 - size) << 2) | sdo::kExpedited |
                                            sdo::kSizeIndicated);
  frame.data[1] = static_cast<std::uint8_t>(object.index);
  frame.data[2] = static_cast<std::uint8_t>(object.index >> 8);
  frame.data[3] = object.subindex;
  for (int i = 0; i < size; ++i) frame.data[4 + i] = static_cast<std::uint8_t>(value >> (8 * i));
  return true;
}

// A read of the object.
inline bool sdo_upload_frame(NodeId node, ObjectAddress object, hal::CanFrame& frame) {
  if (!is_valid_node(node)) return false;
  frame = hal::CanFrame{};
  frame.id = kSdoClientBase + node;
  frame.dlc = 8;
  frame.data[0] = sdo::kInitiateUpload;
  frame.data[1] = static_cast<std::uint8_t>(object.index);
  frame.data[2] = static_cast<std::uint8_t>(object.index >> 8);
  frame.data[3] = object.subindex;
  return true;
}

// What the drive's SDO server answered.
struct SdoReply {
  enum class Kind : std::uint8_t {
    download_done,    // the write was taken
    upload_value,     // an expedited read: value holds `size` bytes
    abort,            // refused: abort_code says why
    not_expedited,    // a segmented or block reply, which the manager never asks for
  };
  NodeId node = 0;
  Kind kind = Kind::abort;
  ObjectAddress object{};
  std::uint32_t value = 0;
  std::uint8_t size = 0;
  std::uint32_t abort_code = 0;
};

inline bool decode_sdo_reply(const hal::CanFrame& frame, SdoReply& reply) {
  if (frame.fd() || (frame.id & kFunctionMask) != kSdoServerBase || frame.dlc != 8) return false;
  const NodeId node = static_cast<NodeId>(frame.id & kNodeMask);
  if (!is_valid_node(node)) return false;
  const std::uint8_t command = frame.data[0];
  const std::uint32_t payload = std::uint32_t(frame.data[4]) | (std::uint32_t(frame.data[5]) << 8) |
                                (std::uint32_t(frame.data[6]) << 16) | (std::uint32_t(frame.data[7]) << 24);
  SdoReply decoded;
  decoded.node = node;
  decoded.object.index = static_cast<std::uint16_t>(frame.data[1] | (frame.data[2] << 8));
  decoded.object.subindex = frame.data[3];
  if (command == sdo::kAbort) {
    decoded.kind = SdoReply::Kind::abort;
    decoded.abort_code = payload;
  } else if (command == sdo::kDownloadResponse) {
    decoded.kind = SdoReply::Kind::download_done;
  } else if ((command & 0xE0) == sdo::kUploadResponse && (command & 0x10) == 0) {
    if ((command & sdo::kExpedited) == 0) {
      decoded.kind = SdoReply::Kind::not_expedited;
    } else {
      // Without the size bit the server leaves the length unstated: all four.
      const std::uint8_t size = (command & sdo::kSizeIndicated) ? std::uint8_t(4 - ((command >> 2) & 0x3)) : 4;
      decoded.kind = SdoReply::Kind::upload_value;
      decoded.size = size;
      decoded.value = size == 4 ? payload : payload & ((std::uint32_t(1) << (8 * size)) - 1);
    }
  } else {
    return false;
  }
  reply = decoded;
  return true;
}

// ---- The drives' process data, as the manager maps it (cia402.hpp):
// RPDO1 [controlword 0x6040, target position 0x607A], TPDO1 [statusword
// 0x6041, position actual value 0x6064], both six bytes, both released by
// the SYNC.
struct DriveCommand {
  NodeId node = 0;
  std::uint16_t controlword = 0;
  std::int32_t target_position = 0;  // counts
};

struct DriveState {
  NodeId node = 0;
  std::uint16_t statusword = 0;
  std::int32_t actual_position = 0;  // counts
};

inline constexpr std::uint8_t kProcessDataBytes = 6;

namespace detail {
inline void put_u16_i32(std::uint8_t* data, std::uint16_t word, std::int32_t value) {
  const std::uint32_t raw = static_cast<std::uint32_t>(value);
  data[0] = static_cast<std::uint8_t>(word);
  data[1] = static_cast<std::uint8_t>(word >> 8);
  for (int i = 0; i < 4; ++i) data[2 + i] = static_cast<std::uint8_t>(raw >> (8 * i));
}
inline void get_u16_i32(const std::uint8_t* data, std::uint16_t& word, std::int32_t& value) {
  word = static_cast<std::uint16_t>(data[0] | (data[1] << 8));
  const std::uint32_t raw = std::uint32_t(data[2]) | (std::uint32_t(data[3]) << 8) |
                            (std::uint32_t(data[4]) << 16) | (std::uint32_t(data[5]) << 24);
  value = static_cast<std::int32_t>(raw);
}
}  // namespace detail

inline hal::CanFrame rpdo_frame(const DriveCommand& command) {
  hal::CanFrame frame;
  frame.id = kRpdo1Base + command.node;
  frame.dlc = kProcessDataBytes;
  detail::put_u16_i32(frame.data, command.controlword, command.target_position);
  return frame;
}

inline bool decode_rpdo(const hal::CanFrame& frame, DriveCommand& command) {
  if (frame.fd() || (frame.id & kFunctionMask) != kRpdo1Base || frame.dlc != kProcessDataBytes) return false;
  const NodeId node = static_cast<NodeId>(frame.id & kNodeMask);
  if (!is_valid_node(node)) return false;
  command.node = node;
  detail::get_u16_i32(frame.data, command.controlword, command.target_position);
  return true;
}

inline hal::CanFrame tpdo_frame(const DriveState& state) {
  hal::CanFrame frame;
  frame.id = kTpdo1Base + state.node;
  frame.dlc = kProcessDataBytes;
  detail::put_u16_i32(frame.data, state.statusword, state.actual_position);
  return frame;
}

inline bool decode_tpdo(const hal::CanFrame& frame, DriveState& state) {
  if (frame.fd() || (frame.id & kFunctionMask) != kTpdo1Base || frame.dlc != kProcessDataBytes) return false;
  const NodeId node = static_cast<NodeId>(frame.id & kNodeMask);
  if (!is_valid_node(node)) return false;
  state.node = node;
  detail::get_u16_i32(frame.data, state.statusword, state.actual_position);
  return true;
}

}  // namespace cdcr::firmware::canopen
