#pragma once
// A CAN frame's time on the wire (ISO 11898-1:2015), for data frames with an
// 11-bit identifier: the bits of a frame, with the stuff bits its content
// actually needs or the most any content can need, split into those sent at
// the nominal (arbitration) bit rate and those sent at the data bit rate of a
// CAN FD frame that switches its bit rate. The simulated bus times frames by
// their content; the bus budget counts the worst case.
//
// Every count includes the interframe space (3 bits of intermission): a
// frame cannot start before the one ahead of it has ended and the bus has
// had those bits, so a back-to-back bus carries one frame per count.
//
// Classical frame: SOF, identifier (11), RTR, IDE, r0, DLC (4), data (8n),
// CRC (15); then CRC delimiter, ACK slot, ACK delimiter, EOF (7), IFS (3).
// Stuffing covers SOF to the end of the CRC: after five equal bits, one of
// the opposite value, which counts in the next run. 111 bits for 8 bytes
// before stuffing, 135 at most.
//
// FD frame: SOF, identifier (11), RRS, IDE, FDF, res, BRS, ESI, DLC (4),
// data (8n), then the CRC field: a fixed stuff bit, the stuff count (4), and
// the CRC (17 bits up to 16 data bytes, 21 beyond) with a fixed stuff bit
// after every fourth bit of the field; CRC delimiter, ACK, ACK delimiter,
// EOF, IFS. Dynamic stuffing covers SOF to the end of the data only (five
// equal bits at its end take the fixed stuff bit, not a second one). With
// bit-rate switching the data rate runs from ESI to the end of the CRC (the
// switch at BRS's and the CRC delimiter's sample points is counted at the
// bit's boundary: the sample point's share of one bit each way).

#include <cstddef>
#include <cstdint>

#include "cdcr/hal/can_bus.hpp"

namespace cdcr::hal {

enum class CanFormat : std::uint8_t {
  classical = 0,
  fd = 1,                   // CAN FD, the whole frame at the nominal rate
  fd_bit_rate_switch = 2,   // CAN FD with BRS: the data phase at the data rate
};

// Bit rates of a bus (bit/s); data_bit_rate matters only to frames that
// switch their rate.
struct CanBitRates {
  std::uint32_t nominal = 1000000;
  std::uint32_t data = 0;
};

// The bits of one frame, at each rate.
struct CanFrameBits {
  std::uint32_t nominal = 0;
  std::uint32_t data = 0;
  std::uint32_t stuff = 0;  // of the counts above, the dynamic stuff bits
  std::uint32_t total() const { return nominal + data; }
};

// The data length code of an FD length (is_fd_length, can_bus.hpp); a
// classical frame's is its length.
inline constexpr std::uint8_t fd_length_code(std::size_t length) {
  if (length <= 8) return static_cast<std::uint8_t>(length);
  if (length <= 24) return static_cast<std::uint8_t>(9 + (length - 12) / 4);
  return length == 32 ? 13 : length == 48 ? 14 : 15;
}
// The smallest FD length that holds `bytes` (at most 64).
inline constexpr std::size_t fd_length_for(std::size_t bytes) {
  if (bytes <= 8) return bytes;
  for (std::size_t length : {12u, 16u, 20u, 24u, 32u, 48u}) {
    if (bytes <= length) return length;
  }
  return 64;
}

namespace detail {

// Feeds the stuffed part of a frame bit by bit: counts the stuff bits the
// transmitter inserts and keeps the classical CRC over the unstuffed bits
// (CRC-15, x^15 + x^14 + x^10 + x^8 + x^7 + x^4 + x^3 + 1, zero start).
class StuffCounter {
 public:
  void crc_and_put(bool bit) {
    const bool feedback = bit != (((crc_ >> 14) & 1u) != 0);
    crc_ = static_cast<std::uint16_t>((crc_ << 1) & 0x7FFFu);
    if (feedback) crc_ ^= 0x4599u;
    put(bit);
  }
  void put(bool bit) {
    stuffed_last_ = false;
    if (run_ > 0 && bit == last_) {
      ++run_;
    } else {
      last_ = bit;
      run_ = 1;
    }
    if (run_ == 5) {  // the stuff bit, opposite, starts the next run
      ++stuff_;
      last_ = !bit;
      run_ = 1;
      stuffed_last_ = true;
    }
  }
  template <typename Put>
  void field(std::uint32_t value, int bits, Put&& put_bit) {
    for (int i = bits - 1; i >= 0; --i) put_bit(((value >> i) & 1u) != 0);
  }
  std::uint16_t crc() const { return crc_; }
  std::uint32_t stuff() const { return stuff_; }
  // Whether the latest bit was followed by a stuff bit.
  bool stuffed_last() const { return stuffed_last_; }

 private:
  std::uint16_t crc_ = 0;
  std::uint32_t stuff_ = 0;
  std::uint32_t run_ = 0;
  bool last_ = false;
  bool stuffed_last_ = false;
};

inline constexpr std::uint32_t kTrailerBits = 1 + 1 + 1 + 7 + 3;  // CRC delimiter, ACK, ACK delimiter, EOF, IFS
inline constexpr std::uint32_t kClassicalHeaderBits = 1 + 11 + 1 + 1 + 1 + 4;
inline constexpr std::uint32_t kFdArbitrationBits = 1 + 11 + 1 + 1 + 1 + 1 + 1;  // SOF through BRS
inline constexpr std::uint32_t kFdControlBits = 1 + 4;                           // ESI, DLC

inline constexpr std::uint32_t fd_crc_field_bits(std::size_t length) {
  const std::uint32_t crc = length <= 16 ? 17 : 21;
  return 4 + crc + 1 + (4 + crc) / 4;  // stuff count, CRC, the fixed stuff bits
}

}  // namespace detail

// The bits of the frame (id, data[0..length)) as sent, its stuff bits
// counted from its content. `length` must suit the format (0..8 classical,
// is_fd_length for FD); the identifier's low 11 bits are sent.
inline CanFrameBits can_frame_bits(std::uint32_t id, const std::uint8_t* data, std::size_t length,
                                   CanFormat format) {
  detail::StuffCounter s;
  CanFrameBits bits;
  if (format == CanFormat::classical) {
    const auto put = [&s](bool b) { s.crc_and_put(b); };
    put(false);                     // SOF
    s.field(id & 0x7FFu, 11, put);  // identifier
    s.field(0, 3, put);             // RTR, IDE, r0: a data frame, 11-bit identifier
    s.field(static_cast<std::uint32_t>(length), 4, put);
    for (std::size_t i = 0; i < length; ++i) s.field(data[i], 8, put);
    const std::uint16_t crc = s.crc();
    const auto put_unchanged = [&s](bool b) { s.put(b); };
    s.field(crc, 15, put_unchanged);
    bits.stuff = s.stuff();
    bits.nominal = detail::kClassicalHeaderBits + 8u * static_cast<std::uint32_t>(length) + 15 + bits.stuff +
                   detail::kTrailerBits;
    return bits;
  }
  const bool switches = format == CanFormat::fd_bit_rate_switch;
  const auto put = [&s](bool b) { s.put(b); };
  put(false);
  s.field(id & 0x7FFu, 11, put);
  s.field(0b0010u | (switches ? 1u : 0u), 5, put);  // RRS 0, IDE 0, FDF 1, res 0, BRS
  const std::uint32_t arbitration_stuff = s.stuff();
  put(false);  // ESI: error active
  s.field(fd_length_code(length), 4, put);
  for (std::size_t i = 0; i < length; ++i) s.field(data[i], 8, put);
  // Five equal bits at the end of the data are followed by the CRC field's
  // fixed stuff bit alone, never by two stuff bits.
  bits.stuff = s.stuff() - (s.stuffed_last() ? 1u : 0u);
  const std::uint32_t data_phase = detail::kFdControlBits + 8u * static_cast<std::uint32_t>(length) +
                                   (bits.stuff - arbitration_stuff) + detail::fd_crc_field_bits(length);
  bits.nominal = detail::kFdArbitrationBits + arbitration_stuff + detail::kTrailerBits;
  if (switches) {
    bits.data = data_phase;
  } else {
    bits.nominal += data_phase;
  }
  return bits;
}

// The format a frame is sent in, from its flags.
inline constexpr CanFormat format_of(const CanFrame& frame) {
  if (!frame.fd()) return CanFormat::classical;
  return frame.bit_rate_switch() ? CanFormat::fd_bit_rate_switch : CanFormat::fd;
}

inline CanFrameBits can_frame_bits(const CanFrame& frame) {
  return can_frame_bits(frame.id, frame.data, frame.dlc, format_of(frame));
}

// The most bits a frame of `length` data bytes can take: the stuffed part
// of n bits holds at most (n - 1) / 4 stuff bits (five equal bits, then
// four after each stuff bit).
inline constexpr CanFrameBits can_frame_bits_worst_case(std::size_t length, CanFormat format) {
  CanFrameBits bits;
  const std::uint32_t data_bits = 8u * static_cast<std::uint32_t>(length);
  if (format == CanFormat::classical) {
    const std::uint32_t stuffed = detail::kClassicalHeaderBits + data_bits + 15;
    bits.stuff = (stuffed - 1) / 4;
    bits.nominal = stuffed + bits.stuff + detail::kTrailerBits;
    return bits;
  }
  const std::uint32_t stuffed = detail::kFdArbitrationBits + detail::kFdControlBits + data_bits;
  bits.stuff = (stuffed - 1) / 4;
  // Where the worst case puts them: the arbitration phase holds at most its
  // own share; the rest are at the data rate.
  const std::uint32_t arbitration_stuff = (detail::kFdArbitrationBits - 1) / 4;
  const std::uint32_t data_phase = detail::kFdControlBits + data_bits + (bits.stuff - arbitration_stuff) +
                                   detail::fd_crc_field_bits(length);
  bits.nominal = detail::kFdArbitrationBits + arbitration_stuff + detail::kTrailerBits;
  if (format == CanFormat::fd_bit_rate_switch) {
    bits.data = data_phase;
  } else {
    bits.nominal += data_phase;
  }
  return bits;
}

// The fewest bits a frame of `length` data bytes takes: no stuff bit at all.
inline constexpr CanFrameBits can_frame_bits_without_stuffing(std::size_t length, CanFormat format) {
  CanFrameBits bits = can_frame_bits_worst_case(length, format);
  const std::uint32_t arbitration_stuff = format == CanFormat::classical ? 0 : (detail::kFdArbitrationBits - 1) / 4;
  if (format == CanFormat::fd_bit_rate_switch) {
    bits.nominal -= arbitration_stuff;
    bits.data -= bits.stuff - arbitration_stuff;
  } else {
    bits.nominal -= bits.stuff;
  }
  bits.stuff = 0;
  return bits;
}

// The frame's time on the wire (ns, rounded up); 0 for a rate of 0.
inline constexpr std::int64_t can_frame_time_ns(const CanFrameBits& bits, const CanBitRates& rates) {
  if (rates.nominal == 0 || (bits.data > 0 && rates.data == 0)) return 0;
  // In units of 1 / (nominal x data) s, so that the sum is exact.
  const std::uint64_t data_rate = bits.data > 0 ? rates.data : 1u;
  const std::uint64_t numerator = (static_cast<std::uint64_t>(bits.nominal) * data_rate +
                                   static_cast<std::uint64_t>(bits.data) * rates.nominal) *
                                  1000000000ull;
  const std::uint64_t denominator = static_cast<std::uint64_t>(rates.nominal) * data_rate;
  return static_cast<std::int64_t>((numerator + denominator - 1) / denominator);
}

}  // namespace cdcr::hal
