#pragma once
// One CAN signal as a DBC declares it, and the routines that read and write
// it: Intel byte order (DBC @1), any start bit, 1 to 32 bits, signed (two's
// complement) or unsigned, physical = raw * factor + offset. Every frame of
// the protocol is packed and unpacked here (messages.hpp holds the signals,
// frames.hpp the typed frames).

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "cdcr/hal/can_bus.hpp"

namespace cdcr::firmware::protocol {

// The only byte order the protocol uses: DBC's "@1", little-endian.
inline constexpr int kDbcIntelByteOrder = 1;

// One entry of an enum signal's value table (DBC VAL_).
struct ValueName {
  std::uint32_t value;
  const char* name;
};

struct ValueTable {
  const ValueName* entries = nullptr;
  std::uint8_t count = 0;
};

template <std::size_t N>
constexpr ValueTable value_table(const ValueName (&entries)[N]) {
  return {entries, static_cast<std::uint8_t>(N)};
}

// What a field of `length_bits` can hold.
constexpr std::int64_t raw_type_minimum(bool is_signed, int length_bits) {
  return is_signed ? -(std::int64_t{1} << (length_bits - 1)) : 0;
}
constexpr std::int64_t raw_type_maximum(bool is_signed, int length_bits) {
  return is_signed ? (std::int64_t{1} << (length_bits - 1)) - 1 : (std::int64_t{1} << length_bits) - 1;
}

// floor() and ceil() for the range computation below, constexpr so that it
// runs at compile time; x is clamped to [low, high] first.
constexpr std::int64_t floor_within(double x, std::int64_t low, std::int64_t high) {
  if (!(x > double(low))) return low;
  if (!(x < double(high))) return high;
  const auto truncated = static_cast<std::int64_t>(x);
  return double(truncated) > x ? truncated - 1 : truncated;
}
constexpr std::int64_t ceil_within(double x, std::int64_t low, std::int64_t high) {
  return -floor_within(-x, -high, -low);
}

class SignalSpec {
 public:
  constexpr SignalSpec(const char* name_, std::uint8_t start_bit_, std::uint8_t length_bits_, bool is_signed_,
                       double factor_, double offset_, double minimum_, double maximum_, const char* unit_,
                       ValueTable values_ = {})
      : name(name_),
        start_bit(start_bit_),
        length_bits(length_bits_),
        is_signed(is_signed_),
        factor(factor_),
        offset(offset_),
        minimum(minimum_),
        maximum(maximum_),
        unit(unit_),
        values(values_),
        // The slack absorbs the rounding of a decimal range (655.35 / 0.01).
        raw_minimum(ceil_within((minimum_ - offset_) / factor_ - 1e-6, raw_type_minimum(is_signed_, length_bits_),
                                raw_type_maximum(is_signed_, length_bits_))),
        raw_maximum(floor_within((maximum_ - offset_) / factor_ + 1e-6, raw_type_minimum(is_signed_, length_bits_),
                                 raw_type_maximum(is_signed_, length_bits_))) {}

  const char* name;          // as in the DBC
  std::uint8_t start_bit;    // least significant bit; frame bit k is bit k % 8 of data[k / 8]
  std::uint8_t length_bits;  // 1..32
  bool is_signed;
  double factor;   // positive
  double offset;
  double minimum;  // physical range: what a receiver accepts, what an encoder saturates to
  double maximum;
  const char* unit;
  ValueTable values;  // names of an enum signal's values
  // The raw values whose physical value lies within [minimum, maximum],
  // worked out once: a board decodes several frames a cycle, and on a core
  // without a double-precision FPU each division here costs hundreds of
  // instructions.
  std::int64_t raw_minimum;
  std::int64_t raw_maximum;
};

// The bits a signal occupies, as a mask over the frame's 64 data bits.
constexpr std::uint64_t signal_mask(const SignalSpec& spec) {
  return ((std::uint64_t{1} << spec.length_bits) - 1) << spec.start_bit;
}

// The frame's eight data bytes as one little-endian word.
inline std::uint64_t data_word(const hal::CanFrame& frame) {
  std::uint64_t word = 0;
  for (int i = 7; i >= 0; --i) word = (word << 8) | frame.data[i];
  return word;
}

inline void set_data_word(hal::CanFrame& frame, std::uint64_t word) {
  for (int i = 0; i < 8; ++i) frame.data[i] = static_cast<std::uint8_t>(word >> (8 * i));
}

// The signal's raw value in a frame's data word.
constexpr std::int64_t raw_in_word(std::uint64_t word, const SignalSpec& spec) {
  const std::uint64_t bits = (word & signal_mask(spec)) >> spec.start_bit;
  const std::uint64_t sign_bit = std::uint64_t{1} << (spec.length_bits - 1);
  if (spec.is_signed && (bits & sign_bit) != 0) {
    return static_cast<std::int64_t>(bits) - (std::int64_t{1} << spec.length_bits);
  }
  return static_cast<std::int64_t>(bits);
}

inline std::int64_t read_raw(const hal::CanFrame& frame, const SignalSpec& spec) {
  return raw_in_word(data_word(frame), spec);
}

// The low length_bits of `raw` (two's complement for negative values), in
// the signal's place in a data word. Encoders OR a frame's signals together
// and store the word once.
constexpr std::uint64_t placed(const SignalSpec& spec, std::int64_t raw) {
  return (static_cast<std::uint64_t>(raw) << spec.start_bit) & signal_mask(spec);
}

// Writes one signal; the frame's other bits are kept.
inline void write_raw(hal::CanFrame& frame, const SignalSpec& spec, std::int64_t raw) {
  set_data_word(frame, (data_word(frame) & ~signal_mask(spec)) | placed(spec, raw));
}

constexpr std::int64_t raw_minimum(const SignalSpec& spec) { return spec.raw_minimum; }
constexpr std::int64_t raw_maximum(const SignalSpec& spec) { return spec.raw_maximum; }

constexpr bool raw_in_range(const SignalSpec& spec, std::int64_t raw) {
  return raw >= spec.raw_minimum && raw <= spec.raw_maximum;
}

inline double to_physical(const SignalSpec& spec, std::int64_t raw) { return double(raw) * spec.factor + spec.offset; }

// The nearest raw value, clamped to the signal's range. NaN goes to the top:
// the saturating signals are residuals and counters, where unknown is worst.
inline std::int64_t to_raw_saturating(const SignalSpec& spec, double physical) {
  const double scaled = (physical - spec.offset) / spec.factor;
  if (!(scaled < double(spec.raw_maximum))) return spec.raw_maximum;
  if (!(scaled > double(spec.raw_minimum))) return spec.raw_minimum;
  return static_cast<std::int64_t>(std::llround(scaled));
}

// The nearest raw value if it lies in the signal's range; false for NaN and
// anything outside, where a clipped value would be a wrong one.
inline bool to_raw_checked(const SignalSpec& spec, double physical, std::int64_t& raw) {
  const double scaled = (physical - spec.offset) / spec.factor;
  if (!(scaled >= double(spec.raw_minimum) - 0.5) || !(scaled < double(spec.raw_maximum) + 0.5)) return false;
  raw = static_cast<std::int64_t>(std::llround(scaled));
  return raw_in_range(spec, raw);
}

// to_raw_checked's result, bit for bit, mostly in single precision: when the
// value is a float (the runtime's cable lengths are), the signal has no
// offset, and the quotient lies clear of a half-way point by more than
// single precision's rounding of it (under 0.012 below 1e5: two roundings of
// at most 2^-24 each, for the division and for the factor), the rounding is
// decided in single precision; otherwise the double computation runs. On a
// core without a double-precision FPU that is a division, a rounding and
// the range checks done in software saved per signal.
inline bool to_raw_checked_single(const SignalSpec& spec, double physical, std::int64_t& raw) {
  const float single = static_cast<float>(physical);
  if (spec.offset == 0 && static_cast<double>(single) == physical) {
    const float scaled = single / static_cast<float>(spec.factor);
    if (scaled > -1e5f && scaled < 1e5f) {  // false for NaN as well
      const float below = std::floor(scaled);
      const float fraction = scaled - below;
      if (std::fabs(fraction - 0.5f) > 0.02f) {
        raw = static_cast<std::int64_t>(below) + (fraction > 0.5f ? 1 : 0);
        return raw_in_range(spec, raw);
      }
    }
  }
  return to_raw_checked(spec, physical, raw);
}

// Integer signals (counters, sequence numbers, enums) saturate at their range.
constexpr std::int64_t saturate_raw(const SignalSpec& spec, std::int64_t raw) {
  if (raw < spec.raw_minimum) return spec.raw_minimum;
  return raw > spec.raw_maximum ? spec.raw_maximum : raw;
}

inline std::uint64_t placed_saturating(const SignalSpec& spec, double physical) {
  return placed(spec, to_raw_saturating(spec, physical));
}

constexpr std::uint64_t placed_integer(const SignalSpec& spec, std::int64_t value) {
  return placed(spec, saturate_raw(spec, value));
}

inline double physical_in_word(std::uint64_t word, const SignalSpec& spec) {
  return to_physical(spec, raw_in_word(word, spec));
}

// The value a receiver decodes for `physical` after the signal's quantum and
// range: for senders that model the bus (golden data, reference checks).
inline double as_transmitted(const SignalSpec& spec, double physical) {
  return to_physical(spec, to_raw_saturating(spec, physical));
}

}  // namespace cdcr::firmware::protocol
