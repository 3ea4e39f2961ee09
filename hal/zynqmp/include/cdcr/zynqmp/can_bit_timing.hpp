#pragma once
// CAN bit timing for the Xilinx CAN controller: a bit is 1 + tseg1 + tseg2
// time quanta of `prescaler` reference clocks each, sampled after
// 1 + tseg1 quanta. The controller takes a prescaler of 1..256, tseg1 of
// 1..16 and tseg2 of 1..8 quanta, a resynchronisation jump width of 1..4
// (UG1085, BRPR and BTR).

#include <cstdint>

namespace cdcr::zynqmp {

struct CanBitTiming {
  std::uint32_t prescaler = 0;  // reference clocks per time quantum
  std::uint32_t tseg1 = 0;      // propagation and phase segment 1, in quanta
  std::uint32_t tseg2 = 0;      // phase segment 2, in quanta
  std::uint32_t sjw = 0;        // resynchronisation jump width, in quanta
};

inline constexpr std::uint32_t kMaxPrescaler = 256;
inline constexpr std::uint32_t kMaxTseg1 = 16;
inline constexpr std::uint32_t kMaxTseg2 = 8;
inline constexpr std::uint32_t kMaxSjw = 4;

inline constexpr bool is_valid(const CanBitTiming& timing) {
  return timing.prescaler >= 1 && timing.prescaler <= kMaxPrescaler && timing.tseg1 >= 1 &&
         timing.tseg1 <= kMaxTseg1 && timing.tseg2 >= 1 && timing.tseg2 <= kMaxTseg2 && timing.sjw >= 1 &&
         timing.sjw <= kMaxSjw && timing.sjw <= timing.tseg2;
}

inline constexpr std::uint32_t quanta_per_bit(const CanBitTiming& timing) { return 1 + timing.tseg1 + timing.tseg2; }

// Bits per second the timing gives from the reference clock; 0 for a timing
// the controller cannot take.
inline constexpr std::uint32_t bitrate(const CanBitTiming& timing, std::uint32_t reference_clock_hz) {
  return is_valid(timing) ? reference_clock_hz / (timing.prescaler * quanta_per_bit(timing)) : 0;
}

// The timing with the largest number of quanta per bit (the finest sample
// point) whose bitrate is exact and whose sample point is the nearest to
// `sample_point_permille` at or before it; a prescaler of 0 when no timing
// gives the bitrate exactly.
inline constexpr CanBitTiming compute_bit_timing(std::uint32_t reference_clock_hz, std::uint32_t bitrate_bps,
                                                 std::uint32_t sample_point_permille = 875) {
  CanBitTiming best{};
  if (bitrate_bps == 0) return best;
  std::uint32_t best_error = ~0u;
  for (std::uint32_t quanta = 1 + kMaxTseg1 + kMaxTseg2; quanta >= 4; --quanta) {
    if (reference_clock_hz % (bitrate_bps * quanta) != 0) continue;
    const std::uint32_t prescaler = reference_clock_hz / (bitrate_bps * quanta);
    if (prescaler < 1 || prescaler > kMaxPrescaler) continue;
    // Quanta up to the sample point, at or before the one asked for.
    std::uint32_t before_sample = quanta * sample_point_permille / 1000;
    if (before_sample < 2) before_sample = 2;
    std::uint32_t tseg1 = before_sample - 1;
    std::uint32_t tseg2 = quanta - before_sample;
    if (tseg2 < 1) {
      tseg2 = 1;
      tseg1 = quanta - 2;
    }
    if (tseg1 > kMaxTseg1 || tseg2 > kMaxTseg2) continue;
    const std::uint32_t sample_permille = 1000 * (1 + tseg1) / quanta;
    const std::uint32_t error =
        sample_permille > sample_point_permille ? sample_permille - sample_point_permille : sample_point_permille - sample_permille;
    if (error < best_error) {
      best_error = error;
      best = CanBitTiming{prescaler, tseg1, tseg2, tseg2 < kMaxSjw ? tseg2 : kMaxSjw};
    }
  }
  return best;
}

}  // namespace cdcr::zynqmp
