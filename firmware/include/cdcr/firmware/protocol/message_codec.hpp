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
