#pragma once
// One encoder and one decoder for every typed frame, walking the message's
// signals in messages.hpp at compile time. A typed frame (frames.hpp) says
// only which of its fields each signal of its message carries, in the
// table's order, and how the field holds the value:
//
//   template <>
//   struct FrameFields<PosePositionXy>
//       : MessageFields<pose_position_xy::kMessage, field::Value<&PosePositionXy::x_mm>,
//                       field::Value<&PosePositionXy::y_mm>> {};
//
// Bits, scale, range and identifier come from the table alone, so a signal
// moved there moves in every frame; a struct that no longer matches its
// message (a signal more or less, a field too narrow for the signal's range)
// stops the build.
//
// Each field kind has put() (OR the field's signal into the data word; false
// refuses the frame), check() (what the decoder must reject beyond
// check_frame's identifier, length, reserved-bit and range checks) and get()
// (write the field from a checked word). The encoder and decoder unroll over
// the fields and inline every step, as a codec written out per message
// would: a board pays nothing for the table walk.

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <utility>

#include "cdcr/firmware/fault.hpp"
#include "cdcr/firmware/protocol/message_codec.hpp"
#include "cdcr/firmware/protocol/messages.hpp"
#include "cdcr/firmware/protocol/signal_codec.hpp"
#include "cdcr/hal/can_bus.hpp"

namespace cdcr::firmware::protocol {

// A cable length's raw value, if it survives the frame: positive after
// rounding to the 0.01 mm quantum and short of the "not available" mark
// (655.34 mm at most). Scaled once, in single precision where that gives the
// double result (a core without a double-precision FPU pays for each).
inline bool cable_length_raw(const SignalSpec& signal, double length_mm, std::int64_t& raw) {
  return to_raw_checked_single(signal, length_mm, raw) && raw != 0 && raw != kCableNotAvailableRaw;
}

namespace field {

// The struct and the type of a pointer to member.
template <typename Member>
struct MemberOf;
template <typename Frame, typename Type>
struct MemberOf<Type Frame::*> {
  using Struct = Frame;
  using Value = Type;
};

// Every raw value the signal can carry fits a field of type Field.
template <typename Field>
constexpr bool holds_raw_range(const SignalSpec& signal) {
  using Integer = std::conditional_t<std::is_enum_v<Field>, std::underlying_type<Field>, std::common_type<Field>>;
  using Limits = std::numeric_limits<typename Integer::type>;
  return signal.raw_minimum >= std::int64_t{Limits::min()} && signal.raw_maximum <= std::int64_t{Limits::max()};
}

// A plain integer: one raw step per unit, no offset.
constexpr bool is_integer(const SignalSpec& signal) { return signal.factor == 1 && signal.offset == 0; }

// A field holding the signal's value as it is: a floating-point field the
// physical value, saturated to the signal's range when sent (residuals,
// radii, positions); an integer, enum or bool field the raw value, saturated
// likewise (counters, sequence numbers, states).
template <auto Member>
struct Value {
  using Struct = typename MemberOf<decltype(Member)>::Struct;
  using Type = typename MemberOf<decltype(Member)>::Value;
  static constexpr bool refusable = false;

  static constexpr bool fits(const SignalSpec& signal) {
    if constexpr (std::is_floating_point_v<Type>) {
      return true;
    } else {
      return holds_raw_range<Type>(signal);
    }
  }
  static bool put(const SignalSpec& signal, const Struct& f, std::uint64_t& word) {
    if constexpr (std::is_floating_point_v<Type>) {
      word |= placed_saturating(signal, f.*Member);
    } else {
      word |= placed_integer(signal, static_cast<std::int64_t>(f.*Member));
    }
    return true;
  }
  static DecodeStatus check(const SignalSpec&, std::uint64_t) { return DecodeStatus::ok; }
  template <typename... Context>
  static void get(const SignalSpec& signal, std::uint64_t word, Struct& f, const Context&...) {
    if constexpr (std::is_floating_point_v<Type>) {
      f.*Member = physical_in_word(word, signal);
    } else if constexpr (std::is_same_v<Type, bool>) {
      f.*Member = raw_in_word(word, signal) != 0;
    } else {
      f.*Member = static_cast<Type>(raw_in_word(word, signal));
    }
  }
};

// A physical value the encoder refuses outside the signal's range (and NaN)
// instead of clipping it: a clipped payload would be a wrong one.
template <auto Member>
struct Refused : Value<Member> {
  using typename Value<Member>::Struct;
  static constexpr bool refusable = true;

  static bool put(const SignalSpec& signal, const Struct& f, std::uint64_t& word) {
    std::int64_t raw = 0;
    if (!to_raw_checked(signal, f.*Member, raw)) return false;
    word |= placed(signal, raw);
    return true;
  }
};

// A segment's cable lengths, one signal each: a field that carries a run of
// signals, as many as the array has elements, so that the encoder and the
// decoder loop over them as one would by hand (four inlined copies of the
// rounding would not fit a board's flash as well). Each length is refused
// unless cable_length_raw takes it; a receiver tells "not available" apart
// from a malformed zero.
template <auto Member>
struct CableLengths {
  using Struct = typename MemberOf<decltype(Member)>::Struct;
  static constexpr bool refusable = true;
  static constexpr std::size_t signal_count = std::extent_v<typename MemberOf<decltype(Member)>::Value>;

  static constexpr bool fits(SignalList signals) {
    for (const SignalSpec* signal : signals) {
      if (signal->is_signed || signal->raw_maximum < kCableNotAvailableRaw) return false;
    }
    return true;
  }
  // The last signal of a segment of three cables is "not available" both
  // ways: NaN in the struct, kCableNotAvailableRaw on the wire (the
  // receiver knows the segment's cables; a four-cable segment's NaN is its
  // to refuse).
  static bool put(SignalList signals, const Struct& f, std::uint64_t& word) {
    std::size_t k = 0;
    for (const SignalSpec* signal : signals) {
      const double length_mm = (f.*Member)[k++];
      std::int64_t raw = kCableNotAvailableRaw;
      if (!(k == signal_count && std::isnan(length_mm)) && !cable_length_raw(*signal, length_mm, raw)) return false;
      word |= placed(*signal, raw);
    }
    return true;
  }
  static DecodeStatus check(SignalList signals, std::uint64_t word) {
    std::size_t k = 0;
    for (const SignalSpec* signal : signals) {
      const std::int64_t raw = raw_in_word(word, *signal);
      const bool last = ++k == signal_count;
      if (raw == kCableNotAvailableRaw && !last) return DecodeStatus::not_available;
      if (raw == 0) return DecodeStatus::out_of_range;  // a cable has a length
    }
    return DecodeStatus::ok;
  }
  template <typename... Context>
  static void get(SignalList signals, std::uint64_t word, Struct& f, const Context&...) {
    int k = 0;
    for (const SignalSpec* signal : signals) {
      const bool absent = raw_in_word(word, *signal) == kCableNotAvailableRaw;
      (f.*Member)[k++] = absent ? std::numeric_limits<double>::quiet_NaN() : physical_in_word(word, *signal);
    }
  }
};

// One bit of a flags signal, held in a bool.
template <std::int64_t Bit, auto Member>
struct Flag {
  using Struct = typename MemberOf<decltype(Member)>::Struct;
  static constexpr std::int64_t bit = Bit;
  static constexpr auto member = Member;
};

// A flags signal whose defined bits are Flags...; the decoder rejects a
// frame with any other bit set, as it does reserved bits outside a signal.
template <typename... Flags>
struct FlagSet {
  using Struct = std::common_type_t<typename Flags::Struct...>;
  static constexpr bool refusable = false;
  static constexpr std::int64_t defined = (Flags::bit | ...);

  static constexpr bool fits(const SignalSpec& signal) {
    return is_integer(signal) && !signal.is_signed && defined <= signal.raw_maximum;
  }
  static bool put(const SignalSpec& signal, const Struct& f, std::uint64_t& word) {
    word |= placed_integer(signal, ((f.*Flags::member ? Flags::bit : 0) | ...));
    return true;
  }
  static DecodeStatus check(const SignalSpec& signal, std::uint64_t word) {
    return (raw_in_word(word, signal) & ~defined) != 0 ? DecodeStatus::reserved_bits_set : DecodeStatus::ok;
  }
  template <typename... Context>
  static void get(const SignalSpec& signal, std::uint64_t word, Struct& f, const Context&...) {
    const std::int64_t flags = raw_in_word(word, signal);
    ((f.*Flags::member = (flags & Flags::bit) != 0), ...);
  }
};

// Bytes First.. of a byte array, little-endian, as many as the signal holds:
// digests and image data travel as they are.
template <auto Member, std::size_t First>
struct Bytes {
  using Struct = typename MemberOf<decltype(Member)>::Struct;
  using Array = typename MemberOf<decltype(Member)>::Value;
  static constexpr bool refusable = false;

  static constexpr bool fits(const SignalSpec& signal) {
    return std::is_same_v<std::remove_extent_t<Array>, std::uint8_t> && is_integer(signal) && !signal.is_signed &&
           signal.length_bits % 8 == 0 && First + signal.length_bits / 8 <= std::extent_v<Array>;
  }
  static bool put(const SignalSpec& signal, const Struct& f, std::uint64_t& word) {
    std::uint64_t value = 0;
    for (int i = signal.length_bits / 8 - 1; i >= 0; --i) value = (value << 8) | (f.*Member)[First + i];
    word |= placed_integer(signal, static_cast<std::int64_t>(value));
    return true;
  }
  static DecodeStatus check(const SignalSpec&, std::uint64_t) { return DecodeStatus::ok; }
  template <typename... Context>
  static void get(const SignalSpec& signal, std::uint64_t word, Struct& f, const Context&...) {
    const auto value = static_cast<std::uint64_t>(raw_in_word(word, signal));
    for (int i = 0; i < signal.length_bits / 8; ++i) {
      (f.*Member)[First + i] = static_cast<std::uint8_t>(value >> (8 * i));
    }
  }
};

// A FaultDetail: one byte on the bus, typed on receipt by the FAULT it
// details, which the decoder is given (the STATUS frame sent with it).
template <auto Member>
struct Detail {
  using Struct = typename MemberOf<decltype(Member)>::Struct;
  using Type = typename MemberOf<decltype(Member)>::Value;
  static constexpr bool refusable = false;

  static constexpr bool fits(const SignalSpec& signal) { return holds_raw_range<std::uint8_t>(signal); }
  static bool put(const SignalSpec& signal, const Struct& f, std::uint64_t& word) {
    word |= placed_integer(signal, (f.*Member).wire_value());
    return true;
  }
  static DecodeStatus check(const SignalSpec&, std::uint64_t) { return DecodeStatus::ok; }
  static void get(const SignalSpec& signal, std::uint64_t word, Struct& f, FaultCode reported_fault) {
    f.*Member = Type::from_wire(reported_fault, static_cast<std::uint8_t>(raw_in_word(word, signal)));
  }
};

}  // namespace field

// The fields of a typed frame: specialized per struct in frames.hpp. A
// struct without a specialization has no encode() or decode() here.
template <typename Frame>
struct FrameFields {};

// How many of the message's signals a field carries: one, or the run a
// field such as CableLengths declares.
template <typename Field, typename = void>
inline constexpr std::size_t kSignalCount = 1;
template <typename Field>
inline constexpr std::size_t kSignalCount<Field, std::void_t<decltype(Field::signal_count)>> = Field::signal_count;

// Where each field's signals start in the message's list, and (last) where
// the signals of all of them end.
template <typename... Fields>
constexpr std::array<std::size_t, sizeof...(Fields) + 1> first_signals() {
  std::array<std::size_t, sizeof...(Fields) + 1> first{};
  std::size_t field = 0;
  std::size_t next = 0;
  ((first[field++] = next, next += kSignalCount<Fields>), ...);
  first[field] = next;
  return first;
}

// What a field is given: its signal, or its run of signals.
template <const MessageSpec& Message, std::size_t First, std::size_t Count>
constexpr decltype(auto) field_signals() {
  if constexpr (Count == 1) {
    return (*Message.signals.entries[First]);
  } else {
    return SignalList{Message.signals.entries + First, static_cast<std::uint8_t>(Count)};
  }
}

template <const MessageSpec& Message, typename... Fields, std::size_t... I>
constexpr bool fields_fit(std::index_sequence<I...>) {
  constexpr auto first = first_signals<Fields...>();
  return (Fields::fits(field_signals<Message, first[I], kSignalCount<Fields>>()) && ...);
}

// Fields... carry the message's signals, in the table's order.
// Segment is the struct's segment number for a per-segment message (the
// frame's identifier is the message's plus it), nullptr otherwise.
template <const MessageSpec& Message, auto Segment, typename... Fields>
struct SegmentFields {
  static constexpr const MessageSpec& message = Message;
  using Struct = std::common_type_t<typename Fields::Struct...>;
  static constexpr bool segmented = !std::is_null_pointer_v<decltype(Segment)>;
  // An encoder that may refuse a frame returns whether it wrote one.
  static constexpr bool refusable = segmented || (Fields::refusable || ...);

  static_assert(first_signals<Fields...>()[sizeof...(Fields)] == Message.signals.count,
                "a field for every signal of the message");
  static_assert(segmented == (Message.id_count > 1), "a segment number exactly for a per-segment message");
  static_assert(fields_fit<Message, Fields...>(std::index_sequence_for<Fields...>{}),
                "every field holds its signal's range");

  // Writes the frame, or leaves it alone and returns false when a field is refused.
  static bool encode(const Struct& f, hal::CanFrame& frame) {
    return encode(f, frame, std::index_sequence_for<Fields...>{});
  }

  // Checks everything first and writes the struct only for a well-formed frame.
  template <typename... Context>
  static DecodeStatus decode(const hal::CanFrame& frame, Struct& f, const Context&... context) {
    return decode(frame, f, std::index_sequence_for<Fields...>{}, context...);
  }

 private:
  static constexpr auto kFirst = first_signals<Fields...>();

  template <std::size_t I, typename Field>
  static constexpr decltype(auto) signals_of() {
    return field_signals<Message, kFirst[I], kSignalCount<Field>>();
  }

  static int segment_of(const Struct& f) {
    if constexpr (segmented) {
      return f.*Segment;
    } else {
      return 0;
    }
  }

  template <std::size_t... I>
  static bool encode(const Struct& f, hal::CanFrame& frame, std::index_sequence<I...>) {
    const int segment = segment_of(f);
    if (segment < 0 || segment >= Message.id_count) return false;
    std::uint64_t word = 0;
    if (!(Fields::put(signals_of<I, Fields>(), f, word) && ...)) return false;
    frame = empty_frame(Message, segment);
    set_data_word(frame, word);
    return true;
  }

  template <std::size_t... I, typename... Context>
  static DecodeStatus decode(const hal::CanFrame& frame, Struct& f, std::index_sequence<I...>,
                             const Context&... context) {
    if (const DecodeStatus s = check_frame(Message, frame); s != DecodeStatus::ok) return s;
    const std::uint64_t word = data_word(frame);
    DecodeStatus status = DecodeStatus::ok;
    // The first field that fails, in signal order.
    (void)((status = Fields::check(signals_of<I, Fields>(), word), status == DecodeStatus::ok) && ...);
    if (status != DecodeStatus::ok) return status;
    if constexpr (segmented) f.*Segment = static_cast<int>(frame.id - Message.id);
    (Fields::get(signals_of<I, Fields>(), word, f, context...), ...);
    return DecodeStatus::ok;
  }
};

template <const MessageSpec& Message, typename... Fields>
using MessageFields = SegmentFields<Message, nullptr, Fields...>;

// The frame of a typed message. Returns whether it was written when the
// message has fields an encoder refuses (cable lengths, payloads), nothing
// otherwise.
template <typename Frame, typename Fields = FrameFields<Frame>>
std::conditional_t<Fields::refusable, bool, void> encode(const Frame& f, hal::CanFrame& frame) {
  if constexpr (Fields::refusable) {
    return Fields::encode(f, frame);
  } else {
    Fields::encode(f, frame);
  }
}

// Decodes a typed message: ok and the struct written, or why not and the
// struct untouched.
template <typename Frame, typename Fields = FrameFields<Frame>>
DecodeStatus decode(const hal::CanFrame& frame, Frame& f) {
  return Fields::decode(frame, f);
}

}  // namespace cdcr::firmware::protocol
