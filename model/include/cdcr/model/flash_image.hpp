#pragma once
// Flash image format v2: the trained compensation model as the firmware reads
// it. The full specification is model/flash-image-v2.md (v1, which this
// parser still reads, is model/flash-image-v1.md); this header is its only
// parser and its only validator, shared by the host tools and the firmware.
//
// parse_image() validates everything before anything is used, and returns a
// view whose arrays point into the caller's bytes (zero-copy: on a board the
// bytes are the flash region itself). Given an ImageCheckSink it also reports
// the outcome of every check it can evaluate, which is how `cdcr inspect`
// shows all that is wrong with an image rather than only the first thing.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "cdcr/model/crc32.hpp"
#include "cdcr/model/input_encoding.hpp"
#include "cdcr/model/limits.hpp"

#if !defined(__BYTE_ORDER__) || __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "The flash image is little-endian and read in place; big-endian targets need a converting parser."
#endif

namespace cdcr::model {

inline constexpr std::uint32_t kImageMagic = 0x50474443u;  // bytes "CDGP"
inline constexpr std::uint16_t kImageVersionMajor = 2;      // what the exporter writes
inline constexpr std::uint16_t kImageVersionMinor = 1;  // 2.1: the predictive-variance block
// 2.2: the cables' hysteresis block. The exporter writes 2.2 only for a model
// with one, so an image without it stays byte for byte a 2.1 image.
inline constexpr std::uint16_t kImageVersionMinorHysteresis = 2;
// 2.3: the segments' compliance under the tip load (payload_compliance.hpp),
// in an image with the payload input. Written only for a model with one.
inline constexpr std::uint16_t kImageVersionMinorCompliance = 3;
inline constexpr std::uint16_t kImageOldestVersionMajor = 1;  // still read: deployed boards carry v1 images
inline constexpr std::uint32_t kImageHeaderSize = 64;
inline constexpr std::uint32_t kImageBlockAlignment = 8;
inline constexpr std::uint32_t kImageTrailerSize = 4;  // CRC-32
inline constexpr std::uint32_t kImageMetadataSize = 88;
inline constexpr int kImageOutputs = 6;                 // an error twist, (v, omega)

enum class ImageScalar : std::uint8_t { float32 = 1 };
// Squared exponential with ARD length scales shared by all outputs, and a
// signal and noise variance per output.
enum class ImageKernel : std::uint8_t { squared_exponential_ard = 1 };

// What the points and weights are. The board's mean is the same sum over the
// points for both: sum_i w_i k(x, p_i).
enum class ImageModelKind : std::uint8_t {
  exact_gp = 1,   // the N training inputs, weights alpha = (K + noise I)^-1 y
  sparse_gp = 2,  // M inducing inputs (Titsias VFE), weights the sparse posterior mean's beta
};

constexpr bool is_known(ImageModelKind kind) {
  return kind == ImageModelKind::exact_gp || kind == ImageModelKind::sparse_gp;
}

constexpr const char* to_string(ImageModelKind kind) {
  switch (kind) {
    case ImageModelKind::exact_gp: return "exact-gp";
    case ImageModelKind::sparse_gp: return "sparse-gp";
  }
  return "unknown";
}

enum class ImageStatus : std::uint8_t {
  ok = 0,
  truncated,            // fewer bytes than the header, or than its total_size
  bad_magic,
  unsupported_version,  // unknown major version
  bad_header,           // header_size, reserved fields or dims inconsistent
  size_mismatch,        // total_size disagrees with the size the dims imply
  misaligned,           // buffer not 4-byte aligned, or a block offset not 8-byte aligned
  checksum_mismatch,
  unsupported_kind,     // scalar type, kernel, input encoding, model kind or extra inputs this parser does not know
  over_capacity,        // dims beyond the caller's compile-time capacity
  non_finite_payload,   // NaN or Inf anywhere in the float payload
  invalid_parameters,   // non-positive scale, variance or geometry; inverted input range; bad fitted_rows
};

constexpr const char* to_string(ImageStatus status) {
  switch (status) {
    case ImageStatus::ok: return "ok";
    case ImageStatus::truncated: return "image is truncated";
    case ImageStatus::bad_magic: return "not a CDCR model image (bad magic)";
    case ImageStatus::unsupported_version: return "unsupported image format major version";
    case ImageStatus::bad_header: return "image header is inconsistent";
    case ImageStatus::size_mismatch: return "image size does not match its dimensions";
    case ImageStatus::misaligned: return "image or one of its blocks is misaligned";
    case ImageStatus::checksum_mismatch: return "image checksum mismatch (corrupted)";
    case ImageStatus::unsupported_kind: return "unsupported scalar type, kernel, input encoding or model kind";
    case ImageStatus::over_capacity: return "image dimensions exceed this build's capacity";
    case ImageStatus::non_finite_payload: return "image payload contains NaN or Inf";
    case ImageStatus::invalid_parameters:
      return "image holds a non-positive scale, variance or geometry value, an inverted input range or a bad row count";
  }
  return "unknown image status";
}

struct ImageCapacity {
  std::uint32_t max_training_points = kMaxTrainingPoints;
  std::uint32_t max_segments = kMaxSegments;
  std::uint32_t max_variance_rank = kMaxVarianceRank;
  std::uint32_t max_extra_inputs = kMaxExtraInputs;
};

// The predictive-variance block (v2.1): a few calibration values, then the
// variance points and two packed lower-triangular factors (see
// model/flash-image-v2.md, "Variance").
namespace image_variance_field {
inline constexpr std::uint32_t position_scale = 0;          // f32, r95_mm = position_scale * the Gaussian radius
inline constexpr std::uint32_t orientation_scale = 1;       // f32, likewise for r95_deg
inline constexpr std::uint32_t extrapolation_variance = 2;  // f32, latent variance / signal variance that flags a query
inline constexpr std::uint32_t reserved = 3;                // f32, zero
inline constexpr std::uint32_t points = 4;                  // R x D kernel coordinates, then the two factors
}  // namespace image_variance_field

// The hysteresis block (v2.2): per cable c and operator k, row-major
// [c][k], float32: the play operators' widths (mm), their weights, then the
// lags the homing move leaves (mm); see hysteresis.hpp. The counts are the
// header's hysteresis_cables and hysteresis_operators.
namespace image_hysteresis_field {
inline constexpr std::uint32_t widths = 0;  // then weights, then homing lags, cables x operators each
}  // namespace image_hysteresis_field

constexpr std::uint32_t image_hysteresis_floats(std::uint32_t cables, std::uint32_t operators) {
  return 3 * cables * operators;
}

// The compliance block (v2.3), float32: the weight of a kilogram times
// segment 0's compliance in the base frame (3, rad per kg mm), the ratio of
// each segment's compliance to segment 0's (segments), the softening (per
// rad) and the unloaded tip mass (kg). The count is the header's
// compliance_segments, the image's segment count.
namespace image_compliance_field {
inline constexpr std::uint32_t weighted_gravity = 0;  // 3 floats
inline constexpr std::uint32_t ratios = 3;            // then the softening and the unloaded mass
}  // namespace image_compliance_field

constexpr std::uint32_t image_compliance_floats(std::uint32_t segments) {
  return segments == 0 ? 0 : image_compliance_field::ratios + segments + 2;
}

constexpr std::uint32_t packed_triangle_floats(std::uint32_t rank) { return rank * (rank + 1) / 2; }

// In 64 bits: a damaged header's rank (up to 65535) must not wrap the count.
constexpr std::uint64_t image_variance_floats(std::uint32_t rank, std::uint32_t input_dims) {
  const std::uint64_t r = rank;
  return r == 0 ? 0 : image_variance_field::points + r * input_dims + r * (r + 1);
}

// Byte offsets of the header fields (all little-endian).
namespace image_field {
inline constexpr std::size_t magic = 0;             // u32
inline constexpr std::size_t version_major = 4;     // u16
inline constexpr std::size_t version_minor = 6;     // u16
inline constexpr std::size_t header_size = 8;       // u32
inline constexpr std::size_t total_size = 12;       // u32, including the CRC trailer
inline constexpr std::size_t training_points = 16;  // u32, the points: N training inputs or M inducing inputs
inline constexpr std::size_t input_dims = 20;       // u16, D = 2 * segments + extra_inputs
inline constexpr std::size_t output_dims = 22;      // u16, always 6
inline constexpr std::size_t segment_count = 24;    // u16
inline constexpr std::size_t scalar_type = 26;      // u8, ImageScalar
inline constexpr std::size_t kernel_kind = 27;      // u8, ImageKernel
inline constexpr std::size_t input_encoding = 28;   // u8, InputEncoding
inline constexpr std::size_t model_kind = 29;       // u8, ImageModelKind (v1: reserved, zero)
inline constexpr std::size_t extra_inputs = 30;     // u8, inputs after the joint encoding: 0, or 1 the payload (v1: reserved)
inline constexpr std::size_t reserved_a = 31;       // 1 byte, zero before v2.3 (v1: bytes 29..31)
inline constexpr std::size_t compliance_segments = 31;  // u8, v2.3: segments of the compliance block; zero without
inline constexpr std::size_t geometry_offset = 32;  // u32
inline constexpr std::size_t parameters_offset = 36;
inline constexpr std::size_t inputs_offset = 40;
inline constexpr std::size_t alpha_offset = 44;
inline constexpr std::size_t metadata_offset = 48;
inline constexpr std::size_t metadata_size = 52;    // u32, kImageMetadataSize
inline constexpr std::size_t variance_offset = 56;  // u32, the variance block; zero without one (v1: reserved)
inline constexpr std::size_t variance_rank = 60;    // u16, R, the variance points; zero without (v1: reserved)
inline constexpr std::size_t reserved_b = 62;       // 2 bytes, zero before v2.2 (v1: bytes 56..63)
inline constexpr std::size_t hysteresis_cables = 62;     // u8, v2.2: cables of the hysteresis block; zero without
inline constexpr std::size_t hysteresis_operators = 63;  // u8, v2.2: play operators per cable; zero without
}  // namespace image_field

// Byte offsets inside the metadata block.
namespace image_metadata_field {
inline constexpr std::size_t dataset_hash = 0;        // u64, FNV-1a of the training data file
inline constexpr std::size_t created_unix_s = 8;      // i64
inline constexpr std::size_t validation_samples = 16; // u32
inline constexpr std::size_t fitted_rows = 20;        // u32, data rows the model was fitted on (v1: reserved, zero)
inline constexpr std::size_t metrics = 24;            // 8 x f32, ImageMetrics order
inline constexpr std::size_t trainer = 56;            // 32 bytes, NUL-padded text
}  // namespace image_metadata_field

struct ImageMetrics {
  float initial_position_mm;
  float initial_orientation_deg;
  float compensated_position_mm;
  float compensated_orientation_deg;
  float float32_max_position_diff_mm;   // float32 path vs double trainer, held-out data
  float float32_mean_position_diff_mm;
  float float32_max_orientation_diff_deg;
  float float32_mean_orientation_diff_deg;
};

// The validated image. Arrays point into the parsed bytes.
struct ImageView {
  std::uint16_t version_major;
  std::uint16_t version_minor;
  std::uint32_t total_size;
  ImageModelKind model_kind;      // exact_gp for a v1 image
  std::uint32_t training_points;  // the points: N training inputs (exact) or M inducing inputs (sparse)
  std::uint32_t fitted_rows;      // data rows behind the model; N for an exact model and for every v1 image
  int input_dims;                 // D = 2 segment_count + extra_inputs
  int segment_count;
  int extra_inputs;               // 0, or 1: input D - 1 is the tip payload, kg
  InputEncoding encoding;
  const float* geometry;        // segment_count x {backbone_length_mm, anchor_radius_mm, theta_max_rad}
  const float* input_mean;      // D
  const float* input_scale;     // D
  const float* length_scale;    // D, in normalised input units
  const float* output_mean;     // 6
  const float* output_scale;    // 6
  const float* signal_variance; // 6, normalised output units
  const float* noise_variance;  // 6, normalised output units
  const float* input_min;       // D, raw input units, the fitted data's range; nullptr for a v1 image
  const float* input_max;       // D, likewise
  const float* extra_input_default;  // extra_inputs: the value used until one arrives (the payload, kg); null without
  const float* inputs;          // points x D row-major, kernel coordinates: (x - mean) / (scale * length_scale)
  const float* alpha;           // points x 6 row-major: the weights (alpha or beta) per normalised output
  // The predictive variance (v2.1; rank 0 and null pointers without it).
  std::uint32_t variance_rank;                // R
  const float* variance_calibration;          // 4: image_variance_field order
  const float* variance_points;               // R x D row-major, kernel coordinates
  const float* variance_inducing_factor;      // packed lower triangle L_u, R (R + 1) / 2: chol(K_uu / signal_variance)
  const float* variance_posterior_factor;     // packed lower triangle L_c: chol(I + L_u^-1 K_uf K_fu L_u^-T / (signal noise))
  // The cables' hysteresis (v2.2; zero counts and null pointers without it),
  // cables x operators each, row-major per cable (image_hysteresis.hpp
  // makes a model::HysteresisModel of it).
  int hysteresis_cables;
  int hysteresis_operators;
  const float* hysteresis_widths;      // mm, finite, in [0, kMaxHysteresisWidthMm]
  const float* hysteresis_weights;     // finite, >= 0, summing to <= 1 per cable
  const float* hysteresis_homing_lags; // mm, within +-width
  // The segments' compliance under the tip load (v2.3; zero and null
  // pointers without it; image_compliance.hpp makes a
  // model::PayloadCompliance of it). Only in an image with the payload input.
  int compliance_segments;
  const float* compliance_weighted_gravity;  // 3, rad per kg mm, finite
  const float* compliance_ratios;            // compliance_segments, finite, > 0
  const float* compliance_softening;         // 1, per rad, finite, keeps 1 + s |b| > 0 to a quarter turn
  const float* compliance_unloaded_mass;     // 1, kg, finite, >= 0
  std::uint64_t dataset_hash;
  std::int64_t created_unix_s;
  std::uint32_t validation_samples;
  ImageMetrics metrics;
  const char* trainer;  // up to 32 bytes, not necessarily NUL-terminated
};

// Layout that the dims imply: where each block starts and the total size.
struct ImageLayout {
  std::uint32_t geometry_offset;
  std::uint32_t parameters_offset;
  std::uint32_t inputs_offset;
  std::uint32_t alpha_offset;
  std::uint32_t variance_offset;  // 0 without a variance block
  std::uint32_t hysteresis_offset;  // 0 without a hysteresis block
  std::uint32_t compliance_offset;  // 0 without a compliance block
  std::uint32_t metadata_offset;
  std::uint32_t total_size;
};

constexpr std::uint32_t align_up(std::uint32_t value, std::uint32_t alignment) {
  return (value + alignment - 1) / alignment * alignment;
}

// v2 appends input_min and input_max (D each) to v1's parameters, and a
// default per extra input. A major version this parser does not know is laid
// out as the newest it does.
constexpr std::uint32_t image_parameter_floats(std::uint32_t input_dims,
                                               std::uint16_t version_major = kImageVersionMajor,
                                               std::uint32_t extra_inputs = 0) {
  return version_major == 1 ? 3 * input_dims + 4 * kImageOutputs
                            : 5 * input_dims + 4 * kImageOutputs + extra_inputs;
}

// Blocks follow the header in this order, each 8-byte aligned, then the CRC.
constexpr ImageLayout image_layout(std::uint32_t training_points, std::uint32_t input_dims,
                                   std::uint32_t segment_count, std::uint16_t version_major = kImageVersionMajor,
                                   std::uint32_t variance_rank = 0, std::uint32_t extra_inputs = 0,
                                   std::uint32_t hysteresis_floats = 0, std::uint32_t compliance_floats = 0) {
  ImageLayout layout{};
  std::uint32_t at = kImageHeaderSize;
  layout.geometry_offset = at;
  at = align_up(at + 4 * 3 * segment_count, kImageBlockAlignment);
  layout.parameters_offset = at;
  at = align_up(at + 4 * image_parameter_floats(input_dims, version_major, extra_inputs), kImageBlockAlignment);
  layout.inputs_offset = at;
  at = align_up(at + 4 * training_points * input_dims, kImageBlockAlignment);
  layout.alpha_offset = at;
  at = align_up(at + 4 * training_points * kImageOutputs, kImageBlockAlignment);
  if (variance_rank > 0) {
    layout.variance_offset = at;
    at = align_up(at + 4 * static_cast<std::uint32_t>(image_variance_floats(variance_rank, input_dims)),
                  kImageBlockAlignment);
  }
  if (hysteresis_floats > 0) {
    layout.hysteresis_offset = at;
    at = align_up(at + 4 * hysteresis_floats, kImageBlockAlignment);
  }
  if (compliance_floats > 0) {
    layout.compliance_offset = at;
    at = align_up(at + 4 * compliance_floats, kImageBlockAlignment);
  }
  layout.metadata_offset = at;
  at = align_up(at + kImageMetadataSize, kImageBlockAlignment);
  layout.total_size = at + kImageTrailerSize;
  return layout;
}

// --- reporting every check -----------------------------------------------------

// The checks, in the order parse_image() first evaluates them. Each maps to
// one ImageStatus, except that several checks share invalid_parameters.
enum class ImageCheckId : std::uint8_t {
  size,         // truncated
  magic,        // bad_magic
  version,      // unsupported_version
  header,       // bad_header
  alignment,    // misaligned
  checksum,     // checksum_mismatch
  kind,         // unsupported_kind
  capacity,     // over_capacity
  layout,       // size_mismatch
  finite,       // non_finite_payload
  positive,     // invalid_parameters
  ranges,       // invalid_parameters, v2: input_min <= input_max
  fitted_rows,  // invalid_parameters, v2: the metadata's fitted_rows
  variance,     // invalid_parameters, v2.1: what the variance block requires of the model
  hysteresis,   // invalid_parameters, v2.2: the hysteresis block's widths, weights and homing lags
  compliance,   // invalid_parameters, v2.3: the compliance block's values
};
inline constexpr int kImageCheckCount = static_cast<int>(ImageCheckId::compliance) + 1;

constexpr const char* to_string(ImageCheckId check) {
  switch (check) {
    case ImageCheckId::size: return "size";
    case ImageCheckId::magic: return "magic";
    case ImageCheckId::version: return "version";
    case ImageCheckId::header: return "header";
    case ImageCheckId::alignment: return "alignment";
    case ImageCheckId::checksum: return "checksum";
    case ImageCheckId::kind: return "kind";
    case ImageCheckId::capacity: return "capacity";
    case ImageCheckId::layout: return "layout";
    case ImageCheckId::finite: return "finite";
    case ImageCheckId::positive: return "positive";
    case ImageCheckId::ranges: return "ranges";
    case ImageCheckId::fitted_rows: return "fitted_rows";
    case ImageCheckId::variance: return "variance";
    case ImageCheckId::hysteresis: return "hysteresis";
    case ImageCheckId::compliance: return "compliance";
  }
  return "unknown";
}

// How a finding's value relates to its expected value when the check passes.
enum class ImageExpectation : std::uint8_t {
  equal,        // value == expected
  at_least,     // value >= expected
  at_most,      // value <= expected
  multiple_of,  // value is a multiple of expected
  known,        // value is a code this parser knows; expected is the newest one
  finite,       // value is neither NaN nor Inf
  positive,     // value > 0
};

// One evaluated condition. Values are doubles so that one type holds every
// u32 field, a float of the payload, and a NaN as it is.
struct ImageFinding {
  ImageCheckId check;
  bool passed;
  ImageStatus status;     // what the condition makes parse_image() return when it fails first
  const char* field;      // a header or metadata field, a block, or a parameter array
  std::int32_t index;     // element of an array field, or byte offset of a reserved byte; -1 for a single value
  std::uint32_t count;    // values the finding covers: an array that passed as a whole, else 1
  double value;           // what the image holds
  double expected;        // what the expectation compares it to
  ImageExpectation expectation;
};

// Receives the findings of parse_image(..., every_check) in evaluation order.
// The first failed finding is the one whose status parse_image() returns.
class ImageCheckSink {
 public:
  virtual void on_finding(const ImageFinding& finding) = 0;

 protected:
  ~ImageCheckSink() = default;
};

namespace detail {
inline std::uint16_t read_u16(const std::uint8_t* p) { std::uint16_t v; std::memcpy(&v, p, 2); return v; }
inline std::uint32_t read_u32(const std::uint8_t* p) { std::uint32_t v; std::memcpy(&v, p, 4); return v; }
inline std::uint64_t read_u64(const std::uint8_t* p) { std::uint64_t v; std::memcpy(&v, p, 8); return v; }

// The firmware's run: the first failure decides, nothing after it is read.
// The finding's details are unused here and compile away.
struct StopAtFirstFailure {
  static constexpr bool kEveryCheck = false;
  ImageStatus status = ImageStatus::ok;

  bool expect(bool passed, ImageCheckId, ImageStatus failure, const char*, std::int32_t, double, double,
              ImageExpectation, std::uint32_t = 1) {
    if (!passed) status = failure;
    return passed;
  }
  // Names that only a report needs stay out of the firmware's flash.
  static constexpr const char* name(const char*) { return nullptr; }
};

// The host tools' run: every outcome goes to the sink and evaluation goes on
// (as far as the bytes can be read safely); the first failure still decides.
struct ReportEveryCheck {
  static constexpr bool kEveryCheck = true;
  ImageCheckSink& sink;
  ImageStatus status = ImageStatus::ok;

  bool expect(bool passed, ImageCheckId check, ImageStatus failure, const char* field, std::int32_t index,
              double value, double expected, ImageExpectation expectation, std::uint32_t count = 1) {
    if (!passed && status == ImageStatus::ok) status = failure;
    sink.on_finding(ImageFinding{check, passed, failure, field, index, count, value, expected, expectation});
    return true;
  }
  static constexpr const char* name(const char* field) { return field; }
};

// Each value against `good`; a failure per bad value, or one pass for all.
// Returns false where a StopAtFirstFailure run must stop.
template <typename Run, typename Good>
bool expect_each(Run& run, const float* values, std::uint32_t count, Good good, ImageCheckId check,
                 ImageStatus failure, const char* field, ImageExpectation expectation) {
  bool all_good = true;
  for (std::uint32_t i = 0; i < count; ++i) {
    if (good(values[i])) continue;
    all_good = false;
    if (!run.expect(false, check, failure, field, static_cast<std::int32_t>(i), values[i], 0.0, expectation)) {
      return false;
    }
  }
  if (all_good) run.expect(true, check, failure, field, -1, 0.0, 0.0, expectation, count);
  return true;
}

inline bool is_finite(float value) { return std::isfinite(value); }
inline bool is_positive(float value) { return value > 0.0f; }

// The hysteresis block's values (hysteresis.hpp, check_hysteresis): widths
// finite, non-negative and at most kMaxHysteresisWidthMm (the homing move
// must take every cable twice as far), weights finite and non-negative with
// a sum of at most 1 per cable (a float32 rounding's allowance, as
// check_hysteresis makes), homing lags within +-width. A failure per bad
// value, or one pass for the block. False where a stopping run must stop.
template <typename Run>
bool check_hysteresis_block(Run& run, const float* block, std::uint32_t cables, std::uint32_t operators) {
  using Expect = ImageExpectation;
  const std::uint32_t count = cables * operators;
  const float* widths = block + image_hysteresis_field::widths;
  const float* weights = widths + count;
  const float* homing_lags = weights + count;
  const float max_width = static_cast<float>(kMaxHysteresisWidthMm);
  bool all_good = true;
  const auto expect = [&](bool passed, const char* field, std::uint32_t index, double value, double expected,
                          Expect expectation) {
    if (passed) return true;
    all_good = false;
    return run.expect(false, ImageCheckId::hysteresis, ImageStatus::invalid_parameters, field,
                      static_cast<std::int32_t>(index), value, expected, expectation);
  };
  for (std::uint32_t c = 0; c < cables; ++c) {
    float weight_sum = 0.0f;
    for (std::uint32_t k = 0; k < operators; ++k) {
      const std::uint32_t i = c * operators + k;
      const float width = widths[i];
      const float weight = weights[i];
      const float lag = homing_lags[i];
      const bool width_finite = std::isfinite(width);
      const bool weight_finite = std::isfinite(weight);
      const bool lag_finite = std::isfinite(lag);
      if (!expect(width_finite, "hysteresis_width", i, width, 0, Expect::finite) ||
          !expect(!width_finite || width >= 0.0f, "hysteresis_width", i, width, 0, Expect::at_least) ||
          !expect(!width_finite || width <= max_width, "hysteresis_width", i, width, max_width, Expect::at_most) ||
          !expect(weight_finite, "hysteresis_weight", i, weight, 0, Expect::finite) ||
          !expect(!weight_finite || weight >= 0.0f, "hysteresis_weight", i, weight, 0, Expect::at_least) ||
          !expect(lag_finite, "hysteresis_homing_lag", i, lag, 0, Expect::finite) ||
          !expect(!lag_finite || !width_finite || std::abs(lag) <= width, "hysteresis_homing_lag", i,
                  std::abs(lag), width, Expect::at_most)) {
        return false;
      }
      weight_sum += weight;
    }
    if (!expect(!std::isfinite(weight_sum) || weight_sum <= 1.0f + 8.0f * 1.1920929e-7f, "hysteresis_weight_sum", c,
                weight_sum, 1.0, Expect::at_most)) {
      return false;
    }
  }
  if (all_good) {
    run.expect(true, ImageCheckId::hysteresis, ImageStatus::invalid_parameters, Run::name("hysteresis"), -1, 0, 0,
               Expect::finite, 3 * count);
  }
  return true;
}
// The compliance block's values (payload_compliance.hpp): all finite, the
// ratios above zero, the unloaded mass not below zero and a softening that
// keeps 1 + s |b| positive for bends up to a quarter turn (a segment that
// stiffens into bending against the load is no stiffness). A failure per bad
// value, or one pass for the block. False where a stopping run must stop.
template <typename Run>
bool check_compliance_block(Run& run, const float* block, std::uint32_t segments) {
  using Expect = ImageExpectation;
  const float* ratios = block + image_compliance_field::ratios;
  const float softening = ratios[segments];
  const float unloaded_mass = ratios[segments + 1];
  bool all_good = true;
  const auto expect = [&](bool passed, const char* field, std::int32_t index, double value, double expected,
                          Expect expectation) {
    if (passed) return true;
    all_good = false;
    return run.expect(false, ImageCheckId::compliance, ImageStatus::invalid_parameters, field, index, value, expected,
                      expectation);
  };
  for (std::uint32_t k = 0; k < 3; ++k) {
    const float g = block[image_compliance_field::weighted_gravity + k];
    if (!expect(std::isfinite(g), "compliance_weighted_gravity", static_cast<std::int32_t>(k), g, 0, Expect::finite)) {
      return false;
    }
  }
  for (std::uint32_t i = 0; i < segments; ++i) {
    const float r = ratios[i];
    if (!expect(std::isfinite(r), "compliance_ratio", static_cast<std::int32_t>(i), r, 0, Expect::finite) ||
        !expect(!std::isfinite(r) || r > 0.0f, "compliance_ratio", static_cast<std::int32_t>(i), r, 0,
                Expect::positive)) {
      return false;
    }
  }
  const float least_softening = static_cast<float>(-1.0 / kComplianceLargestBendRad);
  if (!expect(std::isfinite(softening), "compliance_softening", -1, softening, 0, Expect::finite) ||
      !expect(!std::isfinite(softening) || softening > least_softening, "compliance_softening", -1, softening,
              least_softening, Expect::at_least) ||
      !expect(std::isfinite(unloaded_mass), "compliance_unloaded_mass", -1, unloaded_mass, 0, Expect::finite) ||
      !expect(!std::isfinite(unloaded_mass) || unloaded_mass >= 0.0f, "compliance_unloaded_mass", -1, unloaded_mass,
              0, Expect::at_least)) {
    return false;
  }
  if (all_good) {
    run.expect(true, ImageCheckId::compliance, ImageStatus::invalid_parameters, Run::name("compliance"), -1, 0, 0,
               Expect::finite, image_compliance_floats(segments));
  }
  return true;
}
}  // namespace detail

// The checks of parse_image() that read every byte of an image (its CRC-32
// and the finite payload), run a slice at a time by a caller that must keep
// each step short: the firmware's model update scans beside the SHA-256, a
// slice a cycle. parse_image(..., scan) then runs every other check and takes
// these two verdicts from the scan. The scan reads the header only to find
// the payload's blocks; parse_image() uses its finite verdict only for
// blocks where it has verified them to lie, and its CRC only when it covers
// exactly the bytes before the trailer, and otherwise computes them itself.
class ImageScan {
 public:
  static constexpr int kBlocks = 5;  // geometry, parameters, inputs, alpha, variance

  void begin(const std::uint8_t* bytes, std::size_t size) {
    *this = ImageScan{};
    bytes_ = bytes;
    if (bytes == nullptr || size < kImageHeaderSize) return;
    using namespace image_field;
    const std::uint32_t total = detail::read_u32(bytes + total_size);
    end_ = total >= kImageHeaderSize + kImageTrailerSize && total <= size ? total - kImageTrailerSize
                                                                          : static_cast<std::uint32_t>(size);
    const std::uint16_t major = detail::read_u16(bytes + version_major);
    const std::uint32_t n = detail::read_u32(bytes + training_points);
    const std::uint32_t d = detail::read_u16(bytes + input_dims);
    const std::uint32_t rank = major == 1 ? 0 : detail::read_u16(bytes + variance_rank);
    const std::uint64_t floats[kBlocks] = {3u * std::uint64_t{detail::read_u16(bytes + segment_count)},
                                           image_parameter_floats(d, major), std::uint64_t{n} * d,
                                           std::uint64_t{n} * kImageOutputs,
                                           rank > 0 ? image_variance_floats(rank, d) : 0};
    const std::size_t offsets[kBlocks] = {geometry_offset, parameters_offset, inputs_offset, alpha_offset,
                                          variance_offset};
    for (int i = 0; i < kBlocks; ++i) {
      const std::uint32_t at = detail::read_u32(bytes + offsets[i]);
      // Blocks the scan cannot check (outside the bytes, misaligned) stay
      // empty: parse_image() then checks them itself, or refuses the image.
      if (floats[i] == 0 || at % alignof(float) != 0 || at > end_ || 4 * floats[i] > end_ - at) continue;
      first_[i] = at;
      floats_[i] = static_cast<std::uint32_t>(floats[i]);
    }
  }

  // Up to max_bytes more; true once every byte is scanned. A slice ends on a
  // float boundary when max_bytes is a multiple of 4.
  bool step(std::uint32_t max_bytes) {
    const std::uint32_t to = end_ - at_ < max_bytes ? end_ : at_ + max_bytes;
    crc_ = crc32(bytes_ + at_, to - at_, crc_);
    for (int i = 0; i < kBlocks; ++i) {
      const std::uint32_t last = first_[i] + 4 * floats_[i];
      std::uint32_t from = at_ > first_[i] ? at_ : first_[i];
      from += (from - first_[i]) % 4 == 0 ? 0 : 4 - (from - first_[i]) % 4;
      for (std::uint32_t byte = from; byte + 4 <= to && byte < last; byte += 4) {
        float value;
        std::memcpy(&value, bytes_ + byte, 4);
        finite_[i] = finite_[i] && std::isfinite(value);
      }
    }
    at_ = to;
    return done();
  }

  bool done() const { return bytes_ != nullptr && at_ == end_; }
  const std::uint8_t* bytes() const { return bytes_; }
  std::uint32_t crc() const { return crc_; }
  std::uint32_t crc_bytes() const { return end_; }
  // Whether the scan checked `count` floats at `values` and found them all
  // finite (checked: false when it did not scan exactly that block).
  bool covers(const float* values, std::uint32_t count, bool& finite) const {
    for (int i = 0; i < kBlocks; ++i) {
      if (done() && floats_[i] == count && reinterpret_cast<const std::uint8_t*>(values) == bytes_ + first_[i]) {
        finite = finite_[i];
        return true;
      }
    }
    return false;
  }

 private:
  const std::uint8_t* bytes_ = nullptr;
  std::uint32_t end_ = 0;  // the bytes before the trailer
  std::uint32_t at_ = 0;
  std::uint32_t crc_ = 0;
  std::uint32_t first_[kBlocks] = {};
  std::uint32_t floats_[kBlocks] = {};
  bool finite_[kBlocks] = {true, true, true, true, true};
};

namespace detail {

// Checks run from what is needed to read the rest (size, magic, version,
// header) to the integrity check and then to the meaning of the payload, so
// every rejection reports the first thing that is wrong. A reporting run
// goes past failures, but evaluates a check only where its bytes lie inside
// the buffer (and floats only where they are aligned).
template <typename Run>
ImageStatus check_image(const std::uint8_t* bytes, std::size_t size, ImageView& view, const ImageCapacity& capacity,
                        Run& run, const ImageScan* scan = nullptr) {
  using namespace image_field;
  using Check = ImageCheckId;
  using Status = ImageStatus;
  using Expect = ImageExpectation;

  const bool whole_header = bytes != nullptr && size >= kImageHeaderSize;
  if (!run.expect(whole_header, Check::size, Status::truncated, "file_size", -1, static_cast<double>(size),
                  kImageHeaderSize, Expect::at_least)) {
    return run.status;
  }
  // A file too short for a header may still show what it is.
  if (bytes != nullptr && size >= magic + 4) {
    const std::uint32_t declared_magic = read_u32(bytes + magic);
    if (!run.expect(declared_magic == kImageMagic, Check::magic, Status::bad_magic, "magic", -1, declared_magic,
                    kImageMagic, Expect::equal)) {
      return run.status;
    }
  }
  std::uint16_t major = kImageVersionMajor;
  if (bytes != nullptr && size >= version_major + 2) {
    major = read_u16(bytes + version_major);
    const bool readable = major >= kImageOldestVersionMajor && major <= kImageVersionMajor;
    if (!run.expect(readable, Check::version, Status::unsupported_version, "version_major", -1, major,
                    kImageVersionMajor, Expect::known)) {
      return run.status;
    }
  }
  if (!whole_header) return run.status;
  const bool v1 = major == 1;

  const std::uint32_t declared_header = read_u32(bytes + header_size);
  if (!run.expect(declared_header == kImageHeaderSize, Check::header, Status::bad_header, "header_size", -1,
                  declared_header, kImageHeaderSize, Expect::equal)) {
    return run.status;
  }
  const std::uint32_t declared_total = read_u32(bytes + total_size);
  const bool total_holds_trailer = declared_total >= kImageHeaderSize + kImageTrailerSize;
  if (!run.expect(total_holds_trailer, Check::header, Status::bad_header, "total_size", -1, declared_total,
                  kImageHeaderSize + kImageTrailerSize, Expect::at_least)) {
    return run.status;
  }
  if (total_holds_trailer && !run.expect(declared_total <= size, Check::size, Status::truncated, "total_size", -1,
                                         declared_total, static_cast<double>(size), Expect::at_most)) {
    return run.status;
  }
  const std::uintptr_t address = reinterpret_cast<std::uintptr_t>(bytes);
  const bool aligned = address % alignof(float) == 0;
  if (!run.expect(aligned, Check::alignment, Status::misaligned, "buffer_address", -1, static_cast<double>(address),
                  alignof(float), Expect::multiple_of)) {
    return run.status;
  }

  if (total_holds_trailer && declared_total <= size) {
    const std::uint32_t stored_crc = read_u32(bytes + declared_total - kImageTrailerSize);
    const std::uint32_t covered = declared_total - kImageTrailerSize;
    const bool scanned = scan != nullptr && scan->done() && scan->bytes() == bytes && scan->crc_bytes() == covered;
    const std::uint32_t computed_crc = scanned ? scan->crc() : crc32(bytes, covered);
    if (!run.expect(stored_crc == computed_crc, Check::checksum, Status::checksum_mismatch, "crc32", -1, stored_crc,
                    computed_crc, Expect::equal)) {
      return run.status;
    }
  }

  // v2 gives bytes 29 and 30 a meaning, and bytes 56..61 a meaning that v2.0
  // requires to be zero; reserved bytes are zero in both versions.
  const std::uint16_t minor = read_u16(bytes + version_minor);
  // v2.3 gives byte 31 the compliance block's segment count.
  const bool compliance_fields = !v1 && minor >= kImageVersionMinorCompliance;
  for (std::size_t at = v1 ? model_kind : (compliance_fields ? geometry_offset : reserved_a); at < geometry_offset;
       ++at) {
    if (!run.expect(bytes[at] == 0, Check::header, Status::bad_header, "reserved", static_cast<std::int32_t>(at),
                    bytes[at], 0, Expect::equal)) {
      return run.status;
    }
  }
  // v2.0 reserves the variance fields and requires them to be zero; v2.1
  // defines the block they locate.
  const std::uint32_t declared_variance_offset = v1 ? 0 : read_u32(bytes + variance_offset);
  const std::uint32_t rank = v1 ? 0 : read_u16(bytes + variance_rank);
  if (!v1 && minor == 0) {
    if (!run.expect(declared_variance_offset == 0, Check::header, Status::bad_header, "variance_offset", -1,
                    declared_variance_offset, 0, Expect::equal) ||
        !run.expect(rank == 0, Check::header, Status::bad_header, "variance_rank", -1, rank, 0, Expect::equal)) {
      return run.status;
    }
  }
  // v2.2 gives bytes 62 and 63 the hysteresis block's counts.
  const bool hysteresis_fields = !v1 && minor >= kImageVersionMinorHysteresis;
  for (std::size_t at = v1 ? variance_offset : (hysteresis_fields ? kImageHeaderSize : reserved_b);
       at < kImageHeaderSize; ++at) {
    if (!run.expect(bytes[at] == 0, Check::header, Status::bad_header, "reserved", static_cast<std::int32_t>(at),
                    bytes[at], 0, Expect::equal)) {
      return run.status;
    }
  }

  if (!run.expect(bytes[scalar_type] == static_cast<std::uint8_t>(ImageScalar::float32), Check::kind,
                  Status::unsupported_kind, "scalar_type", -1, bytes[scalar_type],
                  static_cast<std::uint8_t>(ImageScalar::float32), Expect::equal) ||
      !run.expect(bytes[kernel_kind] == static_cast<std::uint8_t>(ImageKernel::squared_exponential_ard), Check::kind,
                  Status::unsupported_kind, "kernel_kind", -1, bytes[kernel_kind],
                  static_cast<std::uint8_t>(ImageKernel::squared_exponential_ard), Expect::equal) ||
      !run.expect(is_known(static_cast<InputEncoding>(bytes[input_encoding])), Check::kind, Status::unsupported_kind,
                  "input_encoding", -1, bytes[input_encoding], static_cast<std::uint8_t>(InputEncoding::bend_vector),
                  Expect::known)) {
    return run.status;
  }
  const ImageModelKind kind = v1 ? ImageModelKind::exact_gp : static_cast<ImageModelKind>(bytes[model_kind]);
  const std::uint32_t extra = v1 ? 0 : bytes[extra_inputs];
  if (!v1) {
    // One extra input is defined, the tip payload; more would be inputs this
    // parser cannot supply.
    if (!run.expect(is_known(kind), Check::kind, Status::unsupported_kind, "model_kind", -1, bytes[model_kind],
                    static_cast<std::uint8_t>(ImageModelKind::sparse_gp), Expect::known) ||
        !run.expect(extra <= kMaxExtraInputs, Check::kind, Status::unsupported_kind, "extra_inputs", -1, extra,
                    kMaxExtraInputs, Expect::at_most)) {
      return run.status;
    }
  }

  const std::uint32_t n = read_u32(bytes + training_points);
  const std::uint32_t d = read_u16(bytes + input_dims);
  const std::uint32_t segments = read_u16(bytes + segment_count);
  const std::uint32_t outputs = read_u16(bytes + output_dims);
  if (!run.expect(n >= 1, Check::header, Status::bad_header, "training_points", -1, n, 1, Expect::at_least) ||
      !run.expect(segments >= 1, Check::header, Status::bad_header, "segment_count", -1, segments, 1,
                  Expect::at_least) ||
      !run.expect(d == 2 * segments + extra, Check::header, Status::bad_header, "input_dims", -1, d,
                  2 * segments + extra, Expect::equal) ||
      !run.expect(outputs == kImageOutputs, Check::header, Status::bad_header, "output_dims", -1, outputs,
                  kImageOutputs, Expect::equal)) {
    return run.status;
  }
  // v2.2: the hysteresis block's counts, both zero without one. The model
  // library's storage (HysteresisModel) bounds them, not the build.
  const std::uint32_t hysteresis_cable_count = hysteresis_fields ? bytes[hysteresis_cables] : 0;
  const std::uint32_t hysteresis_operator_count = hysteresis_fields ? bytes[hysteresis_operators] : 0;
  if (hysteresis_cable_count != 0 || hysteresis_operator_count != 0) {
    if (!run.expect(hysteresis_cable_count == 4 * segments, Check::header, Status::bad_header, "hysteresis_cables", -1,
                    hysteresis_cable_count, 4 * segments, Expect::equal) ||
        !run.expect(hysteresis_operator_count >= 1, Check::header, Status::bad_header, "hysteresis_operators", -1,
                    hysteresis_operator_count, 1, Expect::at_least) ||
        !run.expect(hysteresis_cable_count <= static_cast<std::uint32_t>(kMaxCables), Check::capacity,
                    Status::over_capacity, "hysteresis_cables", -1, hysteresis_cable_count, kMaxCables,
                    Expect::at_most) ||
        !run.expect(hysteresis_operator_count <= static_cast<std::uint32_t>(kMaxHysteresisOperators),
                    Check::capacity, Status::over_capacity, "hysteresis_operators", -1, hysteresis_operator_count,
                    kMaxHysteresisOperators, Expect::at_most)) {
      return run.status;
    }
  }
  const std::uint32_t hysteresis_floats = image_hysteresis_floats(hysteresis_cable_count, hysteresis_operator_count);
  // v2.3: the compliance block's segment count, zero without one. The sag
  // needs the tip load, so only a model with the payload input has one.
  const std::uint32_t compliance_segment_count = compliance_fields ? bytes[compliance_segments] : 0;
  if (compliance_segment_count != 0) {
    if (!run.expect(compliance_segment_count == segments, Check::header, Status::bad_header, "compliance_segments", -1,
                    compliance_segment_count, segments, Expect::equal) ||
        !run.expect(extra == 1, Check::header, Status::bad_header, "compliance_without_payload_input", -1, extra, 1,
                    Expect::equal)) {
      return run.status;
    }
  }
  const std::uint32_t compliance_floats = image_compliance_floats(compliance_segment_count);
  if (!run.expect(n <= capacity.max_training_points, Check::capacity, Status::over_capacity, "training_points", -1, n,
                  capacity.max_training_points, Expect::at_most) ||
      !run.expect(segments <= capacity.max_segments, Check::capacity, Status::over_capacity, "segment_count", -1,
                  segments, capacity.max_segments, Expect::at_most) ||
      !run.expect(rank <= capacity.max_variance_rank, Check::capacity, Status::over_capacity, "variance_rank", -1,
                  rank, capacity.max_variance_rank, Expect::at_most) ||
      !run.expect(extra <= capacity.max_extra_inputs, Check::capacity, Status::over_capacity, "extra_inputs", -1,
                  extra, capacity.max_extra_inputs, Expect::at_most)) {
    return run.status;
  }

  constexpr const char* offset_names[] = {"geometry_offset", "parameters_offset", "inputs_offset", "alpha_offset",
                                          "metadata_offset", "variance_offset"};
  const std::uint32_t offsets[] = {read_u32(bytes + geometry_offset), read_u32(bytes + parameters_offset),
                                   read_u32(bytes + inputs_offset),   read_u32(bytes + alpha_offset),
                                   read_u32(bytes + metadata_offset), declared_variance_offset};
  for (int i = 0; i < 6; ++i) {
    if (!run.expect(offsets[i] % kImageBlockAlignment == 0, Check::alignment, Status::misaligned, offset_names[i], -1,
                    offsets[i], kImageBlockAlignment, Expect::multiple_of)) {
      return run.status;
    }
  }
  // Under a generous capacity the 32-bit layout arithmetic below could wrap
  // into a size that matches; dims whose arrays alone exceed the image cannot.
  const std::uint64_t array_bytes =
      (std::uint64_t{n} * (d + kImageOutputs) + std::uint64_t{image_variance_floats(rank, d)} + hysteresis_floats +
       compliance_floats) *
      4;
  if (!run.expect(array_bytes <= declared_total, Check::layout, Status::size_mismatch, "total_size", -1,
                  declared_total, static_cast<double>(array_bytes), Expect::at_least)) {
    return run.status;
  }
  if (array_bytes <= declared_total) {
    const ImageLayout expected = image_layout(n, d, segments, major, rank, extra, hysteresis_floats, compliance_floats);
    const std::uint32_t expected_offsets[] = {expected.geometry_offset, expected.parameters_offset,
                                              expected.inputs_offset,   expected.alpha_offset,
                                              expected.metadata_offset, expected.variance_offset};
    if (!run.expect(declared_total == expected.total_size, Check::layout, Status::size_mismatch, "total_size", -1,
                    declared_total, expected.total_size, Expect::equal)) {
      return run.status;
    }
    const std::uint32_t declared_metadata_size = read_u32(bytes + metadata_size);
    if (!run.expect(declared_metadata_size == kImageMetadataSize, Check::layout, Status::size_mismatch,
                    "metadata_size", -1, declared_metadata_size, kImageMetadataSize, Expect::equal)) {
      return run.status;
    }
    for (int i = 0; i < 6; ++i) {
      if (!run.expect(offsets[i] == expected_offsets[i], Check::layout, Status::size_mismatch, offset_names[i], -1,
                      offsets[i], expected_offsets[i], Expect::equal)) {
        return run.status;
      }
    }
  }

  // From here on a stopping run has verified every block to lie where the
  // dims put it, inside the image. A reporting run reads a block where the
  // header puts it, if it lies inside the buffer.
  const auto block = [&](std::uint32_t offset, std::uint64_t floats) -> const float* {
    if constexpr (Run::kEveryCheck) {
      if (!aligned || offset % alignof(float) != 0 || offset > size || 4 * floats > size - offset) return nullptr;
    }
    return reinterpret_cast<const float*>(bytes + offset);
  };
  const std::uint32_t parameter_floats = image_parameter_floats(d, major, extra);
  const float* geometry = block(offsets[0], 3 * std::uint64_t{segments});
  const float* parameters = block(offsets[1], parameter_floats);
  const float* inputs = block(offsets[2], std::uint64_t{n} * d);
  const float* alpha = block(offsets[3], std::uint64_t{n} * kImageOutputs);
  const std::uint8_t* metadata =
      reinterpret_cast<const std::uint8_t*>(block(offsets[4], kImageMetadataSize / sizeof(float)));
  const std::uint64_t variance_floats = image_variance_floats(rank, d);
  const float* variance = rank > 0 ? block(offsets[5], variance_floats) : nullptr;
  // The hysteresis and compliance blocks lie where the dims put them (no
  // offset fields).
  const ImageLayout implied = image_layout(n, d, segments, major, rank, extra, hysteresis_floats, compliance_floats);
  const bool blocks_fit = array_bytes <= declared_total;
  const float* hysteresis =
      hysteresis_floats > 0 && blocks_fit ? block(implied.hysteresis_offset, hysteresis_floats) : nullptr;
  const float* compliance =
      compliance_floats > 0 && blocks_fit ? block(implied.compliance_offset, compliance_floats) : nullptr;

  const struct {
    const char* name;
    const float* values;
    std::uint32_t count;
  } payload[] = {{Run::name("geometry"), geometry, 3 * segments},
                 {Run::name("parameters"), parameters, parameter_floats},
                 {Run::name("inputs"), inputs, n * d},
                 {Run::name("alpha"), alpha, n * kImageOutputs},
                 {Run::name("variance"), variance, static_cast<std::uint32_t>(variance_floats)}};
  for (const auto& values : payload) {
    bool finite = true;
    if (values.values != nullptr && scan != nullptr && scan->covers(values.values, values.count, finite)) {
      if (!run.expect(finite, Check::finite, Status::non_finite_payload, values.name, -1, 0.0, 0.0, Expect::finite,
                      values.count)) {
        return run.status;
      }
      continue;
    }
    if (values.values != nullptr && !expect_each(run, values.values, values.count, is_finite, Check::finite,
                                                 Status::non_finite_payload, values.name, Expect::finite)) {
      return run.status;
    }
  }

  // The parameter arrays, back to back; none where the block is not readable.
  const auto parameter = [parameters](std::uint32_t first) {
    return parameters != nullptr ? parameters + first : nullptr;
  };
  const float* input_scale = parameter(d);
  const float* length_scale = parameter(2 * d);
  const float* output_mean = parameter(3 * d);
  const float* output_scale = parameter(3 * d + kImageOutputs);
  const float* signal_variance = parameter(3 * d + 2 * kImageOutputs);
  const float* noise_variance = parameter(3 * d + 3 * kImageOutputs);
  const struct {
    const char* name;
    const float* values;
    std::uint32_t count;
  } must_be_positive[] = {{Run::name("geometry"), geometry, 3 * segments},
                          {Run::name("input_scale"), input_scale, d},
                          {Run::name("length_scale"), length_scale, d},
                          {Run::name("output_scale"), output_scale, kImageOutputs},
                          {Run::name("signal_variance"), signal_variance, kImageOutputs},
                          {Run::name("noise_variance"), noise_variance, kImageOutputs}};
  for (const auto& values : must_be_positive) {
    if (values.values != nullptr && !expect_each(run, values.values, values.count, is_positive, Check::positive,
                                                 Status::invalid_parameters, values.name, Expect::positive)) {
      return run.status;
    }
  }

  const float* input_min = v1 ? nullptr : parameter(3 * d + 4 * kImageOutputs);
  const float* input_max = v1 ? nullptr : parameter(4 * d + 4 * kImageOutputs);
  const float* extra_default = extra > 0 ? parameter(5 * d + 4 * kImageOutputs) : nullptr;
  if (input_min != nullptr) {
    bool all_ordered = true;
    for (std::uint32_t i = 0; i < d; ++i) {
      if (input_min[i] <= input_max[i]) continue;
      all_ordered = false;
      if (!run.expect(false, Check::ranges, Status::invalid_parameters, "input_min", static_cast<std::int32_t>(i),
                      input_min[i], input_max[i], Expect::at_most)) {
        return run.status;
      }
    }
    if (all_ordered) {
      run.expect(true, Check::ranges, Status::invalid_parameters, "input_min", -1, 0, 0, Expect::at_most, d);
    }
  }

  // A payload is a mass: its default is not negative.
  for (std::uint32_t i = 0; extra_default != nullptr && i < extra; ++i) {
    if (!run.expect(extra_default[i] >= 0.0f, Check::ranges, Status::invalid_parameters, "extra_input_default",
                    static_cast<std::int32_t>(i), extra_default[i], 0, Expect::at_least)) {
      return run.status;
    }
  }

  std::uint32_t fitted = n;  // a v1 image was fitted on exactly the rows it carries
  if (!v1 && metadata != nullptr) {
    fitted = read_u32(metadata + image_metadata_field::fitted_rows);
    if (!run.expect(fitted >= 1, Check::fitted_rows, Status::invalid_parameters, "fitted_rows", -1, fitted, 1,
                    Expect::at_least)) {
      return run.status;
    }
    // An exact model's points are its rows; a sparse model's rows may be
    // any number, its points summarise them.
    if (kind == ImageModelKind::exact_gp &&
        !run.expect(fitted == n, Check::fitted_rows, Status::invalid_parameters, "fitted_rows", -1, fitted, n,
                    Expect::equal)) {
      return run.status;
    }
  }
  // The variance block: positive calibration, a threshold that is a share
  // of the signal variance, a zero reserved word, positive factor diagonals
  // (they are divided by), and the one kernel it was computed with: its
  // factors hold signal / noise, so every output must share both.
  const float* variance_points = variance != nullptr ? variance + image_variance_field::points : nullptr;
  const float* inducing_factor = variance_points != nullptr ? variance_points + rank * d : nullptr;
  const float* posterior_factor = inducing_factor != nullptr ? inducing_factor + packed_triangle_floats(rank) : nullptr;
  if (variance == nullptr && Run::kEveryCheck) {
    // Nothing to judge; the report still names the check.
    run.expect(true, Check::variance, Status::invalid_parameters, "variance_rank", -1, rank, 0, Expect::at_least);
  }
  if (variance != nullptr) {
    using namespace image_variance_field;
    if (!expect_each(run, variance, reserved, is_positive, Check::positive, Status::invalid_parameters,
                     Run::name("variance_calibration"), Expect::positive)) {
      return run.status;
    }
    for (std::uint32_t i = 0; i < rank; ++i) {
      const std::uint32_t diagonal = packed_triangle_floats(i + 1) - 1;
      if (!run.expect(is_positive(inducing_factor[diagonal]), Check::variance, Status::invalid_parameters,
                      "variance_inducing_factor", static_cast<std::int32_t>(diagonal), inducing_factor[diagonal], 0,
                      Expect::positive) ||
          !run.expect(is_positive(posterior_factor[diagonal]), Check::variance, Status::invalid_parameters,
                      "variance_posterior_factor", static_cast<std::int32_t>(diagonal), posterior_factor[diagonal],
                      0, Expect::positive)) {
        return run.status;
      }
    }
    if (!run.expect(variance[extrapolation_variance] <= 1.0f, Check::variance, Status::invalid_parameters,
                    "extrapolation_variance", -1, variance[extrapolation_variance], 1, Expect::at_most) ||
        !run.expect(variance[reserved] == 0.0f, Check::variance, Status::invalid_parameters, "variance_reserved", -1,
                    variance[reserved], 0, Expect::equal)) {
      return run.status;
    }
    if (signal_variance != nullptr) {
      for (int k = 1; k < kImageOutputs; ++k) {
        if (!run.expect(signal_variance[k] == signal_variance[0], Check::variance, Status::invalid_parameters,
                        "signal_variance", k, signal_variance[k], signal_variance[0], Expect::equal) ||
            !run.expect(noise_variance[k] == noise_variance[0], Check::variance, Status::invalid_parameters,
                        "noise_variance", k, noise_variance[k], noise_variance[0], Expect::equal)) {
          return run.status;
        }
      }
    }
  }
  if (hysteresis == nullptr && Run::kEveryCheck) {
    run.expect(true, Check::hysteresis, Status::invalid_parameters, "hysteresis_operators", -1,
               hysteresis_operator_count, 0, Expect::at_least);
  }
  if (hysteresis != nullptr &&
      !check_hysteresis_block(run, hysteresis, hysteresis_cable_count, hysteresis_operator_count)) {
    return run.status;
  }
  if (compliance == nullptr && Run::kEveryCheck) {
    run.expect(true, Check::compliance, Status::invalid_parameters, "compliance_segments", -1,
               compliance_segment_count, 0, Expect::at_least);
  }
  if (compliance != nullptr && !check_compliance_block(run, compliance, compliance_segment_count)) {
    return run.status;
  }
  if (run.status != Status::ok) return run.status;

  ImageView v{};
  v.version_major = major;
  v.version_minor = read_u16(bytes + version_minor);
  v.total_size = declared_total;
  v.model_kind = kind;
  v.training_points = n;
  v.fitted_rows = fitted;
  v.input_dims = static_cast<int>(d);
  v.segment_count = static_cast<int>(segments);
  v.extra_inputs = static_cast<int>(extra);
  v.encoding = static_cast<InputEncoding>(bytes[input_encoding]);
  v.geometry = geometry;
  v.input_mean = parameters;
  v.input_scale = input_scale;
  v.length_scale = length_scale;
  v.output_mean = output_mean;
  v.output_scale = output_scale;
  v.signal_variance = signal_variance;
  v.noise_variance = noise_variance;
  v.input_min = input_min;
  v.input_max = input_max;
  v.extra_input_default = extra_default;
  v.inputs = inputs;
  v.alpha = alpha;
  v.variance_rank = rank;
  v.variance_calibration = variance;
  v.variance_points = variance_points;
  v.variance_inducing_factor = inducing_factor;
  v.variance_posterior_factor = posterior_factor;
  v.hysteresis_cables = hysteresis != nullptr ? static_cast<int>(hysteresis_cable_count) : 0;
  v.hysteresis_operators = hysteresis != nullptr ? static_cast<int>(hysteresis_operator_count) : 0;
  const std::uint32_t hysteresis_values = hysteresis_cable_count * hysteresis_operator_count;
  v.hysteresis_widths = hysteresis;
  v.hysteresis_weights = hysteresis != nullptr ? hysteresis + hysteresis_values : nullptr;
  v.hysteresis_homing_lags = hysteresis != nullptr ? hysteresis + 2 * hysteresis_values : nullptr;
  v.compliance_segments = compliance != nullptr ? static_cast<int>(compliance_segment_count) : 0;
  v.compliance_weighted_gravity = compliance;
  v.compliance_ratios = compliance != nullptr ? compliance + image_compliance_field::ratios : nullptr;
  v.compliance_softening = compliance != nullptr ? v.compliance_ratios + compliance_segment_count : nullptr;
  v.compliance_unloaded_mass = compliance != nullptr ? v.compliance_softening + 1 : nullptr;
  v.dataset_hash = read_u64(metadata + image_metadata_field::dataset_hash);
  v.created_unix_s = static_cast<std::int64_t>(read_u64(metadata + image_metadata_field::created_unix_s));
  v.validation_samples = read_u32(metadata + image_metadata_field::validation_samples);
  std::memcpy(&v.metrics, metadata + image_metadata_field::metrics, sizeof(ImageMetrics));
  v.trainer = reinterpret_cast<const char*>(metadata + image_metadata_field::trainer);
  view = v;
  return Status::ok;
}
}  // namespace detail

// Returns the first failure, in the order of the specification's validation
// table, and fills `view` only for a valid image.
inline ImageStatus parse_image(const std::uint8_t* bytes, std::size_t size, ImageView& view,
                               const ImageCapacity& capacity = {}) {
  detail::StopAtFirstFailure run;
  return detail::check_image(bytes, size, view, capacity, run);
}

// The same verdict, with the checks that read every byte taken from `scan`
// (ImageScan: run over these bytes, a slice at a time, by the caller) where
// it covers them; what is left is independent of the image's size but for
// the variance block's diagonals and the few parameter arrays.
inline ImageStatus parse_image(const std::uint8_t* bytes, std::size_t size, ImageView& view,
                               const ImageCapacity& capacity, const ImageScan& scan) {
  detail::StopAtFirstFailure run;
  return detail::check_image(bytes, size, view, capacity, run, &scan);
}

// The same verdict; with a sink, every check that can be evaluated is, and
// its findings go to `every_check` (the firmware never needs this).
inline ImageStatus parse_image(const std::uint8_t* bytes, std::size_t size, ImageView& view,
                               const ImageCapacity& capacity, ImageCheckSink* every_check) {
  if (every_check == nullptr) return parse_image(bytes, size, view, capacity);
  detail::ReportEveryCheck run{*every_check};
  return detail::check_image(bytes, size, view, capacity, run);
}

}  // namespace cdcr::model
