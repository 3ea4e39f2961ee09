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

struct SignalSpec {
  const char* name;          // as in the DBC
  std::uint8_t start_bit;    // least significant bit; frame bit k is bit k % 8 of data[k / 8]
  std::uint8_t length_bits;  // 1..32
  bool is_signed;
  double factor;   // positive
  double offset;
  double minimum;  // physical range: what a receiver accepts, what an encoder saturates to
  double maximum;
  const char* unit;
  ValueTable values = {};  // names of an enum signal's values
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

inline std::int64_t read_raw(const hal::CanFrame& frame, const SignalSpec& spec) {
  const std::uint64_t bits = (data_word(frame) & signal_mask(spec)) >> spec.start_bit;
  const std::uint64_t sign_bit = std::uint64_t{1} << (spec.length_bits - 1);
  if (spec.is_signed && (bits & sign_bit) != 0) {
    return static_cast<std::int64_t>(bits) - (std::int64_t{1} << spec.length_bits);
  }
  return static_cast<std::int64_t>(bits);
}

// Writes the low length_bits of `raw` (two's complement for negative values);
// the frame's other bits are kept.
inline void write_raw(hal::CanFrame& frame, const SignalSpec& spec, std::int64_t raw) {
  const std::uint64_t mask = signal_mask(spec);
  const std::uint64_t bits = (static_cast<std::uint64_t>(raw) << spec.start_bit) & mask;
  set_data_word(frame, (data_word(frame) & ~mask) | bits);
}

// What the field can hold.
constexpr std::int64_t raw_type_minimum(const SignalSpec& spec) {
  return spec.is_signed ? -(std::int64_t{1} << (spec.length_bits - 1)) : 0;
}
constexpr std::int64_t raw_type_maximum(const SignalSpec& spec) {
  return spec.is_signed ? (std::int64_t{1} << (spec.length_bits - 1)) - 1 : (std::int64_t{1} << spec.length_bits) - 1;
}

// floor() and ceil() for the range computations below, constexpr so that a
// constant signal's range folds away; x is clamped to the field first.
constexpr std::int64_t floor_within(double x, std::int64_t low, std::int64_t high) {
  if (!(x > double(low))) return low;
  if (!(x < double(high))) return high;
  const auto truncated = static_cast<std::int64_t>(x);
  return double(truncated) > x ? truncated - 1 : truncated;
}
constexpr std::int64_t ceil_within(double x, std::int64_t low, std::int64_t high) {
  return -floor_within(-x, -high, -low);
}

// The raw values whose physical value lies within [minimum, maximum]. The
// slack absorbs the rounding of a decimal range (655.35 / 0.01).
constexpr std::int64_t raw_minimum(const SignalSpec& spec) {
  return ceil_within((spec.minimum - spec.offset) / spec.factor - 1e-6, raw_type_minimum(spec), raw_type_maximum(spec));
}
constexpr std::int64_t raw_maximum(const SignalSpec& spec) {
  return floor_within((spec.maximum - spec.offset) / spec.factor + 1e-6, raw_type_minimum(spec), raw_type_maximum(spec));
}

constexpr bool raw_in_range(const SignalSpec& spec, std::int64_t raw) {
  return raw >= raw_minimum(spec) && raw <= raw_maximum(spec);
}

inline double to_physical(const SignalSpec& spec, std::int64_t raw) { return double(raw) * spec.factor + spec.offset; }

// The nearest raw value, clamped to the signal's range. NaN goes to the top:
// the saturating signals are residuals and counters, where unknown is worst.
inline std::int64_t to_raw_saturating(const SignalSpec& spec, double physical) {
  const double scaled = (physical - spec.offset) / spec.factor;
  if (!(scaled < double(raw_maximum(spec)))) return raw_maximum(spec);
  if (!(scaled > double(raw_minimum(spec)))) return raw_minimum(spec);
  return static_cast<std::int64_t>(std::llround(scaled));
}

// The nearest raw value if it lies in the signal's range; false for NaN and
// anything outside, where a clipped value would be a wrong one.
inline bool to_raw_checked(const SignalSpec& spec, double physical, std::int64_t& raw) {
  const double scaled = (physical - spec.offset) / spec.factor;
  if (!(scaled >= double(raw_minimum(spec)) - 0.5) || !(scaled < double(raw_maximum(spec)) + 0.5)) return false;
  raw = static_cast<std::int64_t>(std::llround(scaled));
  return raw_in_range(spec, raw);
}

// Integer signals (counters, sequence numbers, enums) saturate at their range.
inline std::int64_t saturate_raw(const SignalSpec& spec, std::int64_t raw) {
  if (raw < raw_minimum(spec)) return raw_minimum(spec);
  return raw > raw_maximum(spec) ? raw_maximum(spec) : raw;
}

inline void put_saturating(hal::CanFrame& frame, const SignalSpec& spec, double physical) {
  write_raw(frame, spec, to_raw_saturating(spec, physical));
}

inline void put_integer(hal::CanFrame& frame, const SignalSpec& spec, std::int64_t value) {
  write_raw(frame, spec, saturate_raw(spec, value));
}

inline double get_physical(const hal::CanFrame& frame, const SignalSpec& spec) {
  return to_physical(spec, read_raw(frame, spec));
}

// The value a receiver decodes for `physical` after the signal's quantum and
// range: for senders that model the bus (golden data, reference checks).
inline double as_transmitted(const SignalSpec& spec, double physical) {
  return to_physical(spec, to_raw_saturating(spec, physical));
}

}  // namespace cdcr::firmware::protocol
