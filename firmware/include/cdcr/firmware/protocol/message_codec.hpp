#pragma once
// One CAN message as a DBC declares it (identifier or per-segment identifier
// range, DLC, sender, signals, and the notes a DBC file carries for its
// readers) and the checks every decoder runs on a frame before it reads a
// signal.

#include <array>
#include <cstddef>
#include <cstdint>

#include "cdcr/firmware/protocol/signal_codec.hpp"
#include "cdcr/hal/can_bus.hpp"

namespace cdcr::firmware::protocol {

enum class DecodeStatus : std::uint8_t {
  ok = 0,
  wrong_id,           // the frame is another message
  wrong_dlc,          // not the message's length
  out_of_range,       // a signal outside its declared range (an unknown enum value, a zero cable length)
  reserved_bits_set,  // a bit no signal defines is not 0
  not_available,      // the sender marked a value as unavailable (cable length 0xFFFF)
};

constexpr const char* to_string(DecodeStatus status) {
  switch (status) {
    case DecodeStatus::ok: return "ok";
    case DecodeStatus::wrong_id: return "wrong identifier";
    case DecodeStatus::wrong_dlc: return "wrong DLC";
    case DecodeStatus::out_of_range: return "value out of range";
    case DecodeStatus::reserved_bits_set: return "reserved bits set";
    case DecodeStatus::not_available: return "value not available";
  }
  return "unknown decode status";
}

// A frame is accepted when (id & mask) == (filter.id & mask), as hal::CanFilter says.
constexpr bool passes(const hal::CanFilter& filter, std::uint32_t id) {
  return (id & filter.mask) == (filter.id & filter.mask);
}

// A message's signals, in bit order: iterate with for (const SignalSpec* s : list).
struct SignalList {
  const SignalSpec* const* entries = nullptr;
  std::uint8_t count = 0;

  constexpr const SignalSpec* const* begin() const { return entries; }
  constexpr const SignalSpec* const* end() const { return entries + count; }
};

template <std::size_t N>
constexpr SignalList signal_list(const SignalSpec* const (&entries)[N]) {
  return {entries, static_cast<std::uint8_t>(N)};
}

struct MessageSpec {
  const char* name;       // as in the DBC; a per-segment message is <name>_<segment> there
  std::uint32_t id;       // the identifier, or segment 0's
  std::uint8_t id_count;  // 1, or one identifier per segment slot
  std::uint8_t dlc;
  const char* sender;  // DBC node
  SignalList signals;
  hal::CanFilter group;  // acceptance filter of the frame group the message belongs to

  constexpr bool carries(std::uint32_t frame_id) const { return frame_id >= id && frame_id - id < id_count; }
};

// What the DBC file says about a message beyond its bits: the node that
// receives it, and comments for people reading the database. The DBC writer
// (firmware/protocol/write_dbc.cpp) reads them; the runtime does not, so on a
// board they take no flash.
struct SignalNote {
  const SignalSpec* signal;
  const char* text;  // CM_ SG_
};

struct SignalNotes {
  const SignalNote* entries = nullptr;
  std::uint8_t count = 0;

  constexpr const SignalNote* begin() const { return entries; }
  constexpr const SignalNote* end() const { return entries + count; }
};

template <std::size_t N>
constexpr SignalNotes signal_notes(const SignalNote (&entries)[N]) {
  return {entries, static_cast<std::uint8_t>(N)};
}

struct MessageNotes {
  const MessageSpec* message;
  const char* receiver;  // DBC node
  // CM_ BO_, or "" for none. In a per-segment message, "{segment}" stands
  // for the segment's number.
  const char* comment = "";
  SignalNotes signals = {};
};

// A CAN FD message made of classical messages: part k is a frame of its
// message, laid out as that message is, in bytes 8k to 8k + 7 (the bytes
// beyond the part's DLC are reserved, 0). One frame then carries what
// several classical frames would, each signal where its message has it, so
// the FD messages need no layouts of their own and decode with the same
// checks. A per-index FD message (id_count > 1) carries its parts' messages
// for segment `segment + index * part_count`.
struct MessagePart {
  const MessageSpec* message;
  std::uint8_t segment = 0;  // of a per-segment message; 0 otherwise
};

struct FdMessageSpec {
  const char* name;       // as in the DBC; a per-index message is <name>_<index> there
  std::uint32_t id;       // the identifier, or index 0's
  std::uint8_t id_count;  // 1, or one identifier per index
  std::uint8_t length;    // data bytes: 8 per part (an FD length, hal::is_fd_length)
  const char* sender;     // DBC node
  const MessagePart* parts;
  std::uint8_t part_count;
  hal::CanFilter group;  // acceptance filter of the frame group the message belongs to

  constexpr bool carries(std::uint32_t frame_id) const { return frame_id >= id && frame_id - id < id_count; }
  // The segment part k of the frame at `index` is of (per-segment parts).
  constexpr int part_segment(int part, int index) const { return parts[part].segment + index * part_count; }
};

inline constexpr int kPartBytes = 8;

template <std::size_t N>
constexpr FdMessageSpec fd_message(const char* name, std::uint32_t id, std::uint8_t id_count, const char* sender,
                                   const MessagePart (&parts)[N], hal::CanFilter group) {
  return {name, id, id_count, static_cast<std::uint8_t>(N * kPartBytes), sender, parts, static_cast<std::uint8_t>(N),
          group};
}

struct FdMessageNotes {
  const FdMessageSpec* message;
  const char* receiver;  // DBC node
  const char* comment = "";
};

// The messages of a list of notes, in its order.
template <std::size_t N>
constexpr std::array<const MessageSpec*, N> messages_of(const MessageNotes* const (&notes)[N]) {
  std::array<const MessageSpec*, N> messages{};
  for (std::size_t i = 0; i < N; ++i) messages[i] = notes[i]->message;
  return messages;
}

// The data bits the message's signals define.
constexpr std::uint64_t defined_bits(const MessageSpec& message) {
  std::uint64_t bits = 0;
  for (const SignalSpec* signal : message.signals) bits |= signal_mask(*signal);
  return bits;
}

// The data bits a frame of the message has: 8 per byte of its DLC.
constexpr std::uint64_t length_bits(const MessageSpec& message) {
  return message.dlc >= 8 ? ~std::uint64_t{0} : (std::uint64_t{1} << (8 * message.dlc)) - 1;
}

// A frame of the message with every bit 0; `index` picks the segment of a
// per-segment message.
inline hal::CanFrame empty_frame(const MessageSpec& message, int index = 0) {
  hal::CanFrame frame;
  frame.id = message.id + static_cast<std::uint32_t>(index);
  frame.dlc = message.dlc;
  return frame;
}

// Part k of an FD frame of `message` (at `index`) as the classical frame of
// its message: the identifier it has as a classical frame, its DLC, its bytes.
inline hal::CanFrame part_frame(const FdMessageSpec& message, const hal::CanFrame& frame, int part, int index = 0) {
  const MessagePart& p = message.parts[part];
  hal::CanFrame classical;
  classical.id = p.message->id + static_cast<std::uint32_t>(p.message->id_count > 1 ? message.part_segment(part, index) : 0);
  classical.dlc = p.message->dlc;
  for (int i = 0; i < p.message->dlc; ++i) classical.data[i] = frame.data[part * kPartBytes + i];
  return classical;
}

// An FD frame of `message` at `index` with every bit 0 (flags: FD; the
// sender's bus adds bit-rate switching).
inline hal::CanFrame empty_frame(const FdMessageSpec& message, int index = 0) {
  hal::CanFrame frame;
  frame.id = message.id + static_cast<std::uint32_t>(index);
  frame.dlc = message.length;
  frame.flags = hal::kCanFdFrame;
  return frame;
}

// Puts a classical frame's bytes into part k of an FD frame.
inline void put_part(hal::CanFrame& frame, int part, const hal::CanFrame& classical) {
  for (int i = 0; i < kPartBytes; ++i) frame.data[part * kPartBytes + i] = i < classical.dlc ? classical.data[i] : 0;
}

// What a decoder of an FD message checks before its parts: the identifier,
// an FD frame of the message's length, the reserved bytes after each part's
// DLC. Each part is then checked as its classical message (check_frame).
inline DecodeStatus check_fd_frame(const FdMessageSpec& message, const hal::CanFrame& frame) {
  if (!message.carries(frame.id)) return DecodeStatus::wrong_id;
  if (!frame.fd() || frame.dlc != message.length) return DecodeStatus::wrong_dlc;
  for (int k = 0; k < message.part_count; ++k) {
    for (int i = message.parts[k].message->dlc; i < kPartBytes; ++i) {
      if (frame.data[k * kPartBytes + i] != 0) return DecodeStatus::reserved_bits_set;
    }
  }
  return DecodeStatus::ok;
}

// What every decoder checks first: identifier, length, reserved bits and the
// range of every signal.
inline DecodeStatus check_frame(const MessageSpec& message, const hal::CanFrame& frame) {
  if (!message.carries(frame.id)) return DecodeStatus::wrong_id;
  if (frame.dlc != message.dlc) return DecodeStatus::wrong_dlc;
  const std::uint64_t word = data_word(frame);
  if ((word & length_bits(message) & ~defined_bits(message)) != 0) return DecodeStatus::reserved_bits_set;
  for (const SignalSpec* signal : message.signals) {
    if (!raw_in_range(*signal, raw_in_word(word, *signal))) return DecodeStatus::out_of_range;
  }
  return DecodeStatus::ok;
}

}  // namespace cdcr::firmware::protocol
