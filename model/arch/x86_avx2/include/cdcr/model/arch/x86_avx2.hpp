#pragma once
// GpCorrection's loops on an x86-64 host with AVX2 and FMA: eight training
// points at a time, in the boards' arithmetic.
//
// The portable loops on such a host call the C library's expf once per
// training point and round every product and sum separately; a point then
// costs about 60 instructions, and a 700-point mean most of a forward cycle.
// Here the squared distances and the kernel values of eight points go in
// the lanes of one register (polynomial_gaussian, lane for lane), the six
// output sums in the lanes of another, and the gradient's weighted sums
// with the inputs in the lanes. Every sum still adds its terms one at a
// time in the order of the points, with the fused multiply-adds of the
// Cortex-M FPUs, so each lane performs exactly the scalar operations of
// GpCorrection's own loops built with polynomial_gaussian and std::fma
// (FusedScalar below): the same bits, which a test checks, and the bits a board
// computes for the same sums.
//
// The vector code is compiled for AVX2 and FMA by function attribute, not by
// build flags, so the rest of the program (Eigen's alignment, the trainer)
// stays plain x86-64. The build selects this architecture by default only
// when the build machine's CPU has both (model/CMakeLists.txt); a binary
// moved to a CPU without them takes the scalar loops with std::fma, which
// give the same bits, slowly.
//
// No contraction can merge two of the vector operations (the rounding to an
// integer is VROUNDPS, not the scalar's add and subtract of 1.5 * 2^23:
// the same value for the kernel's arguments, |z| <= 125).

#if !(defined(__GNUC__) && defined(__x86_64__))
#error "model/arch/x86_avx2 needs GCC or Clang targeting x86-64 (check CDCR_MODEL_ARCH)"
#endif

#include <immintrin.h>

#include <cmath>
#include <cstdint>
#include <type_traits>

#include "cdcr/model/arch/portable.hpp"
#include "cdcr/model/flash_image.hpp"
#include "cdcr/model/kernel_exp.hpp"
#include "cdcr/model/work_costs.hpp"

#define CDCR_AVX2_FMA __attribute__((target("avx2,fma")))

namespace cdcr::model::arch {

namespace detail {

inline constexpr int kLanes = 8;

CDCR_AVX2_FMA inline __m256i first_lanes_mask(int count) {
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  return _mm256_cmpgt_epi32(_mm256_set1_epi32(count), lane);
}

// polynomial_gaussian (kernel_exp.hpp), lane for lane.
CDCR_AVX2_FMA inline __m256 gaussian_lanes(__m256 distance_sq) {
  using namespace gaussian_constants;
  // min(a, b) is a < b ? a : b, NaN included, as the scalar's comparison.
  const __m256 y = _mm256_min_ps(distance_sq, _mm256_set1_ps(kClamp));
  const __m256 z = _mm256_mul_ps(y, _mm256_set1_ps(kMinusHalfLog2e));
  const __m256 k = _mm256_round_ps(z, _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC);
  const __m256i k_integer = _mm256_cvttps_epi32(k);
  const __m256 v = _mm256_fmadd_ps(k, _mm256_set1_ps(kTwoLn2), y);
  const __m256 v2 = _mm256_mul_ps(v, v);
  const __m256 b = _mm256_fmadd_ps(v, _mm256_set1_ps(kB3), _mm256_set1_ps(kB2));
  __m256 c = _mm256_fmadd_ps(v, _mm256_set1_ps(kB5), _mm256_set1_ps(kB4));
  c = _mm256_fmadd_ps(v2, _mm256_set1_ps(kB6), c);
  const __m256 e = _mm256_fmadd_ps(v2, c, b);
  const __m256 d = _mm256_fmadd_ps(v, e, _mm256_set1_ps(-0.5f));
  const __m256 p = _mm256_fmadd_ps(v, d, _mm256_set1_ps(1.0f));
  return _mm256_castsi256_ps(_mm256_add_epi32(_mm256_castps_si256(p), _mm256_slli_epi32(k_integer, 23)));
}

// The kernel values of `count` (1 to 8) consecutive points of `dims` inputs
// each (the lanes past count are unused): distance_sq = fma(diff, diff,
// distance_sq) over the inputs in order, as the scalar loop adds them.
template <int Dims>
CDCR_AVX2_FMA __attribute__((noinline)) __m256 kernel_lanes(const float* query, int dims, const float* rows, int count) {
  __m256 distance_sq = _mm256_setzero_ps();
  if constexpr (Dims == 8) {
    if (count == kLanes) {
      // Eight rows of eight inputs, transposed so that lane j holds point j.
      // (Named registers: an array of rows made GCC copy them through the
      // stack in halves, and each whole-row reload waited for both stores.)
      const __m256 r0 = _mm256_loadu_ps(rows), r1 = _mm256_loadu_ps(rows + 8);
      const __m256 r2 = _mm256_loadu_ps(rows + 16), r3 = _mm256_loadu_ps(rows + 24);
      const __m256 r4 = _mm256_loadu_ps(rows + 32), r5 = _mm256_loadu_ps(rows + 40);
      const __m256 r6 = _mm256_loadu_ps(rows + 48), r7 = _mm256_loadu_ps(rows + 56);
      const __m256 t0 = _mm256_unpacklo_ps(r0, r1), t1 = _mm256_unpackhi_ps(r0, r1);
      const __m256 t2 = _mm256_unpacklo_ps(r2, r3), t3 = _mm256_unpackhi_ps(r2, r3);
      const __m256 t4 = _mm256_unpacklo_ps(r4, r5), t5 = _mm256_unpackhi_ps(r4, r5);
      const __m256 t6 = _mm256_unpacklo_ps(r6, r7), t7 = _mm256_unpackhi_ps(r6, r7);
      const __m256 u0 = _mm256_shuffle_ps(t0, t2, 0x44), u1 = _mm256_shuffle_ps(t0, t2, 0xEE);
      const __m256 u2 = _mm256_shuffle_ps(t1, t3, 0x44), u3 = _mm256_shuffle_ps(t1, t3, 0xEE);
      const __m256 u4 = _mm256_shuffle_ps(t4, t6, 0x44), u5 = _mm256_shuffle_ps(t4, t6, 0xEE);
      const __m256 u6 = _mm256_shuffle_ps(t5, t7, 0x44), u7 = _mm256_shuffle_ps(t5, t7, 0xEE);
      const __m256 column[kLanes] = {
          _mm256_permute2f128_ps(u0, u4, 0x20), _mm256_permute2f128_ps(u1, u5, 0x20),
          _mm256_permute2f128_ps(u2, u6, 0x20), _mm256_permute2f128_ps(u3, u7, 0x20),
          _mm256_permute2f128_ps(u0, u4, 0x31), _mm256_permute2f128_ps(u1, u5, 0x31),
          _mm256_permute2f128_ps(u2, u6, 0x31), _mm256_permute2f128_ps(u3, u7, 0x31)};
      for (int d = 0; d < kLanes; ++d) {
        const __m256 difference = _mm256_sub_ps(_mm256_set1_ps(query[d]), column[d]);
        distance_sq = _mm256_fmadd_ps(difference, difference, distance_sq);
      }
      return gaussian_lanes(distance_sq);
    }
  }
  const int n = Dims > 0 ? Dims : dims;
  const __m256i offsets = _mm256_mullo_epi32(_mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7), _mm256_set1_epi32(n));
  const __m256 valid = _mm256_castsi256_ps(first_lanes_mask(count));
  for (int d = 0; d < n; ++d) {
    const __m256 column = _mm256_mask_i32gather_ps(_mm256_setzero_ps(), rows + d, offsets, valid, 4);
    const __m256 difference = _mm256_sub_ps(_mm256_set1_ps(query[d]), column);
    distance_sq = _mm256_fmadd_ps(difference, difference, distance_sq);
  }
  return gaussian_lanes(distance_sq);
}

// The six double sums in the lanes of two registers (lanes 6 and 7 of the
// second unused), so that adding a block's float sums (whose lanes 6 and 7
// are zero) stays in registers: a block's sums read back from memory
// lane by lane wait for the store to retire, which stalled every block.
struct DoubleSums {
  __m256d low;
  __m256d high;
};

CDCR_AVX2_FMA inline __m256i first_two_lanes_mask_pd() { return _mm256_setr_epi64x(-1, -1, 0, 0); }

CDCR_AVX2_FMA inline DoubleSums load_sums(const double* sums) {
  return {_mm256_loadu_pd(sums), _mm256_maskload_pd(sums + 4, first_two_lanes_mask_pd())};
}

CDCR_AVX2_FMA inline void store_sums(const DoubleSums& in, double* sums) {
  _mm256_storeu_pd(sums, in.low);
  _mm256_maskstore_pd(sums + 4, first_two_lanes_mask_pd(), in.high);
}

// sums[k] += double(block[k]), lane for lane.
CDCR_AVX2_FMA inline void add_block(__m256 block, DoubleSums& sums) {
  sums.low = _mm256_add_pd(sums.low, _mm256_cvtps_pd(_mm256_castps256_ps128(block)));
  sums.high = _mm256_add_pd(sums.high, _mm256_cvtps_pd(_mm256_extractf128_ps(block, 1)));
}

CDCR_AVX2_FMA inline __m256 broadcast_lane(__m256 values, int lane) {
  return _mm256_permutevar8x32_ps(values, _mm256_set1_epi32(lane));
}

// GpCorrection::accumulate_mean: blocks of eight points summed in float,
// each block into the double sums, the ragged end as a block of its own.
template <int Dims>
CDCR_AVX2_FMA void mean_range(const float* query, int dims, const float* inputs, const float* alpha,
                              std::uint32_t count, double* sums) {
  const int n = Dims > 0 ? Dims : dims;
  const __m256i alpha_lanes = first_lanes_mask(kImageOutputs);
  DoubleSums total = load_sums(sums);
  for (std::uint32_t first = 0; first < count; first += kLanes) {
    const int points = count - first < std::uint32_t(kLanes) ? int(count - first) : kLanes;
    const __m256 r = kernel_lanes<Dims>(query, n, inputs, points);
    __m256 block = _mm256_setzero_ps();
    for (int j = 0; j < points; ++j) {
      block = _mm256_fmadd_ps(broadcast_lane(r, j), _mm256_maskload_ps(alpha, alpha_lanes), block);
      alpha += kImageOutputs;
    }
    add_block(block, total);
    inputs += std::size_t(kLanes) * std::size_t(n);
  }
  store_sums(total, sums);
}

// GpCorrection::accumulate_mean_and_gradient: the mean's blocks, and the
// weighted sums weighted[k][d] += (r alpha_k) z_d point after point, the
// inputs in the lanes (`weighted` rows are `row_stride` floats apart). Per
// chunk of points, a first pass computes the kernel values and the mean's
// blocks and keeps each point's six products r alpha_k; a second pass adds
// them to the weighted sums, one vector of inputs at a time, with the six
// sums in named registers (an array of them was stored back to memory at
// every point).
template <int Dims>
CDCR_AVX2_FMA void mean_and_gradient_range(const float* query, int dims, const float* inputs, const float* alpha,
                                           std::uint32_t count, double* sums, float* weighted, int row_stride) {
  constexpr int kChunkPoints = 64;
  const int n = Dims > 0 ? Dims : dims;
  const int vectors = (n + kLanes - 1) / kLanes;
  const __m256i alpha_lanes = first_lanes_mask(kImageOutputs);
  DoubleSums total = load_sums(sums);
  alignas(32) float r_alpha[kChunkPoints][kLanes];
  for (std::uint32_t first = 0; first < count; first += kChunkPoints) {
    const int points = count - first < std::uint32_t(kChunkPoints) ? int(count - first) : kChunkPoints;
    for (int b = 0; b < points; b += kLanes) {
      const int block_points = points - b < kLanes ? points - b : kLanes;
      const __m256 r = kernel_lanes<Dims>(query, n, inputs + std::size_t(b) * std::size_t(n), block_points);
      __m256 block = _mm256_setzero_ps();
      for (int j = 0; j < block_points; ++j) {
        const __m256 a = _mm256_maskload_ps(alpha + (b + j) * kImageOutputs, alpha_lanes);
        const __m256 rj = broadcast_lane(r, j);
        block = _mm256_fmadd_ps(rj, a, block);
        _mm256_store_ps(r_alpha[b + j], _mm256_mul_ps(rj, a));
      }
      add_block(block, total);
    }
    for (int v = 0; v < vectors; ++v) {
      const __m256i input_lanes = first_lanes_mask(n - kLanes * v);
      float* row_sums = weighted + kLanes * v;
      __m256 w0 = _mm256_maskload_ps(row_sums, input_lanes);
      __m256 w1 = _mm256_maskload_ps(row_sums + row_stride, input_lanes);
      __m256 w2 = _mm256_maskload_ps(row_sums + 2 * row_stride, input_lanes);
      __m256 w3 = _mm256_maskload_ps(row_sums + 3 * row_stride, input_lanes);
      __m256 w4 = _mm256_maskload_ps(row_sums + 4 * row_stride, input_lanes);
      __m256 w5 = _mm256_maskload_ps(row_sums + 5 * row_stride, input_lanes);
      const float* row_pointer = inputs + kLanes * v;
      for (int j = 0; j < points; ++j) {
        const __m256 row = Dims == 8 ? _mm256_loadu_ps(row_pointer) : _mm256_maskload_ps(row_pointer, input_lanes);
        row_pointer += n;
        w0 = _mm256_fmadd_ps(_mm256_broadcast_ss(&r_alpha[j][0]), row, w0);
        w1 = _mm256_fmadd_ps(_mm256_broadcast_ss(&r_alpha[j][1]), row, w1);
        w2 = _mm256_fmadd_ps(_mm256_broadcast_ss(&r_alpha[j][2]), row, w2);
        w3 = _mm256_fmadd_ps(_mm256_broadcast_ss(&r_alpha[j][3]), row, w3);
        w4 = _mm256_fmadd_ps(_mm256_broadcast_ss(&r_alpha[j][4]), row, w4);
        w5 = _mm256_fmadd_ps(_mm256_broadcast_ss(&r_alpha[j][5]), row, w5);
      }
      _mm256_maskstore_ps(row_sums, input_lanes, w0);
      _mm256_maskstore_ps(row_sums + row_stride, input_lanes, w1);
      _mm256_maskstore_ps(row_sums + 2 * row_stride, input_lanes, w2);
      _mm256_maskstore_ps(row_sums + 3 * row_stride, input_lanes, w3);
      _mm256_maskstore_ps(row_sums + 4 * row_stride, input_lanes, w4);
      _mm256_maskstore_ps(row_sums + 5 * row_stride, input_lanes, w5);
    }
    inputs += std::size_t(points) * std::size_t(n);
    alpha += std::size_t(points) * kImageOutputs;
  }
  store_sums(total, sums);
}

inline bool cpu_has_avx2_fma() {
  static const bool has = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  return has;
}

}  // namespace detail

// The scalar loops in the boards' arithmetic: GpCorrection's own loops with
// polynomial_gaussian and fused multiply-adds in float (double is the
// trainer's, and keeps the portable arithmetic). X86Avx2 falls back to them
// on a CPU without AVX2 and FMA, and tests compare it with them.
struct FusedScalar : Portable {
  template <typename S>
  static S multiply_add(S a, S b, S c) {
    if constexpr (std::is_same_v<S, float>) {
      return std::fma(a, b, c);
    } else {
      return Portable::multiply_add(a, b, c);
    }
  }
  template <typename S>
  static S gaussian(S distance_sq) {
    if constexpr (std::is_same_v<S, float>) {
      return polynomial_gaussian(distance_sq);
    } else {
      return Portable::gaussian(distance_sq);
    }
  }
};

struct X86Avx2 : FusedScalar {
  // Portable's figures (inherited) steer the IK work here too. With the
  // demo's 700-point model on the AMD EPYC host of the README's runtime
  // benchmark a mean point took 1.8 ns and a cycle's IK slice of 958 units
  // about 1.7 us, the same 1.8 ns a unit: the faster points made the unit
  // about as dear as the IK steps charged in it.

  template <typename S, typename Accumulator>
  static constexpr bool has_vector_loops() {
    return std::is_same_v<S, float> && std::is_same_v<Accumulator, double>;
  }
  static bool vector_loops_available() { return detail::cpu_has_avx2_fma(); }

  // `count` points from `inputs` and `alpha` (which do not advance).
  template <int Dims>
  static void mean_range(const float* query, int dims, const float* inputs, const float* alpha, std::uint32_t count,
                         double* sums) {
    detail::mean_range<Dims>(query, dims, inputs, alpha, count, sums);
  }
  template <int Dims>
  static void mean_and_gradient_range(const float* query, int dims, const float* inputs, const float* alpha,
                                      std::uint32_t count, double* sums, float* weighted, int row_stride) {
    detail::mean_and_gradient_range<Dims>(query, dims, inputs, alpha, count, sums, weighted, row_stride);
  }
};

}  // namespace cdcr::model::arch

#undef CDCR_AVX2_FMA
