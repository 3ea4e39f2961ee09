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

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <iterator>
#include <utility>

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
// 2.4: the bend-vector-cable-fit input encoding (the cables' residuals as
// inputs, input_encoding.hpp). Written only for a model that takes them.
inline constexpr std::uint16_t kImageVersionMinorCableFit = 4;
// 2.5: the history input encodings (where each cable last moved, from the
// hysteresis block's last operator). Written only for a model that takes them.
inline constexpr std::uint16_t kImageVersionMinorHistory = 5;
// 2.6: the variance block's extrapolation_variance alone flags a query as
// extrapolating (a threshold on the latent share, calibrated on held-out
// rows); the fitted rows' range is still reported but no longer flags. In
// older images, and without a variance block, the range flags as before.
// Written for every image with a variance block.
inline constexpr std::uint16_t kImageVersionMinorHeldOutThreshold = 6;
// 2.7: the cables block, every segment's cable count and anchor angles
// (geometry.hpp's CableLayout). Every 2.7 image has one; the exporter writes
// 2.7 only for a robot whose segments are not all the paper's four cables at
// 90 degrees, so a four-cable image stays byte for byte what it was.
inline constexpr std::uint16_t kImageVersionMinorCables = 7;
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

// The cables block (v2.7), float32, per segment: the cable count (3 or 4),
// then kMaxCablesPerSegment anchor angles in rad, the unused ones zero.
namespace image_cables_field {
inline constexpr std::uint32_t count = 0;
inline constexpr std::uint32_t angles = 1;
inline constexpr std::uint32_t per_segment = 1 + kMaxCablesPerSegment;
}  // namespace image_cables_field

// Whether an image of this version carries the cables block.
constexpr bool image_has_cables_block(std::uint16_t major, std::uint16_t minor) {
  return major == 2 && minor >= kImageVersionMinorCables;
}

constexpr std::uint32_t image_cables_floats(std::uint32_t segments) {
  return image_cables_field::per_segment * segments;
}

constexpr std::uint32_t packed_triangle_floats(std::uint32_t rank) { return rank * (rank + 1) / 2; }

// In 64 bits: a damaged header's rank (up to 65535) must not wrap the count.
constexpr std::uint64_t image_variance_floats(std::uint32_t rank, std::uint32_t input_dims) {
  const std::uint64_t r = rank;
  return r == 0 ? 0 : image_variance_field::points + r * input_dims + r * (r + 1);
}

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
  // Every segment's cables (v2.7; null without the block: the paper's four
  // at 90 degrees), image_cables_field order; compensated_kinematics.hpp's
  // geometry_from_image makes each a model::CableLayout. cable_count is
  // the robot's cables either way.
  const float* cables;
  int cable_count;
  std::uint64_t dataset_hash;
  std::int64_t created_unix_s;
  std::uint32_t validation_samples;
  ImageMetrics metrics;
  const char* trainer;  // up to 32 bytes, not necessarily NUL-terminated
};

// --- the format, described once -----------------------------------------------
//
// Two tables: the blocks after the header in the order they follow it, and
// the header's fields. The parser, the exporter (tools/export) and
// `cdcr inspect` take offsets, sizes, names and versions from them.

// Layout that the dims imply: where each block starts and the total size.
struct ImageLayout {
  std::uint32_t geometry_offset;
  std::uint32_t parameters_offset;
  std::uint32_t inputs_offset;
  std::uint32_t alpha_offset;
  std::uint32_t variance_offset;  // 0 without a variance block
  std::uint32_t hysteresis_offset;  // 0 without a hysteresis block
  std::uint32_t compliance_offset;  // 0 without a compliance block
  std::uint32_t cables_offset;      // 0 without a cables block
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

// The blocks, in the order they follow the header.
enum class ImageBlockId : std::uint8_t {
  geometry,
  parameters,
  inputs,
  alpha,
  variance,
  hysteresis,
  compliance,
  cables,
  metadata,
  none,  // a header field that locates no block
};

// The counts a block's size follows from.
struct ImageDims {
  std::uint32_t training_points;
  std::uint32_t input_dims;
  std::uint32_t segment_count;
  std::uint16_t version_major = kImageVersionMajor;
  std::uint32_t variance_rank = 0;
  std::uint32_t extra_inputs = 0;
  std::uint32_t hysteresis_floats = 0;
  std::uint32_t compliance_floats = 0;
  std::uint32_t cables_floats = 0;
};

// A block's bytes, in 64 bits: the dims of a damaged header can be anything.
constexpr std::uint64_t image_block_bytes(ImageBlockId block, const ImageDims& dims) {
  switch (block) {
    case ImageBlockId::geometry: return 4 * 3 * std::uint64_t{dims.segment_count};
    case ImageBlockId::parameters:
      return 4 * std::uint64_t{image_parameter_floats(dims.input_dims, dims.version_major, dims.extra_inputs)};
    case ImageBlockId::inputs: return 4 * std::uint64_t{dims.training_points} * dims.input_dims;
    case ImageBlockId::alpha: return 4 * std::uint64_t{dims.training_points} * kImageOutputs;
    case ImageBlockId::variance: return 4 * image_variance_floats(dims.variance_rank, dims.input_dims);
    case ImageBlockId::hysteresis: return 4 * std::uint64_t{dims.hysteresis_floats};
    case ImageBlockId::compliance: return 4 * std::uint64_t{dims.compliance_floats};
    case ImageBlockId::cables: return 4 * std::uint64_t{dims.cables_floats};
    case ImageBlockId::metadata: return kImageMetadataSize;
    case ImageBlockId::none: break;
  }
  return 0;
}

struct ImageBlockFormat {
  ImageBlockId id;
  const char* name;
  std::uint16_t version_major;  // the version that introduced the block
  std::uint16_t version_minor;
  bool only_when_counted;       // present only when its count (the dims) is non-zero
  std::uint32_t ImageLayout::*offset;
};

// Each block starts at the next multiple of kImageBlockAlignment after the
// one before it; the CRC-32 trailer follows the last.
inline constexpr ImageBlockFormat kImageBlocks[] = {
    {ImageBlockId::geometry, "geometry", 1, 0, false, &ImageLayout::geometry_offset},
    {ImageBlockId::parameters, "parameters", 1, 0, false, &ImageLayout::parameters_offset},
    {ImageBlockId::inputs, "inputs", 1, 0, false, &ImageLayout::inputs_offset},
    {ImageBlockId::alpha, "alpha", 1, 0, false, &ImageLayout::alpha_offset},
    {ImageBlockId::variance, "variance", 2, kImageVersionMinor, true, &ImageLayout::variance_offset},
    {ImageBlockId::hysteresis, "hysteresis", 2, kImageVersionMinorHysteresis, true, &ImageLayout::hysteresis_offset},
    {ImageBlockId::compliance, "compliance", 2, kImageVersionMinorCompliance, true, &ImageLayout::compliance_offset},
    {ImageBlockId::cables, "cables", 2, kImageVersionMinorCables, true, &ImageLayout::cables_offset},
    {ImageBlockId::metadata, "metadata", 1, 0, false, &ImageLayout::metadata_offset},
};

constexpr const ImageBlockFormat& image_block(ImageBlockId block) {
  return kImageBlocks[static_cast<std::size_t>(block)];
}

// Calls visit(index) for each block, index a std::integral_constant, in
// the order the blocks follow the header. Unrolled at compile time, each
// block a constant: a firmware build keeps neither the table nor its names.
template <typename Visit, std::size_t... I>
constexpr void for_each_image_block(Visit&& visit, std::index_sequence<I...>) {
  (visit(std::integral_constant<std::size_t, I>{}), ...);
}

// Where the dims put every block. 32-bit offsets, as in the header.
constexpr ImageLayout image_layout(const ImageDims& dims) {
  ImageLayout layout{};
  std::uint32_t at = kImageHeaderSize;
  const auto place = [&](auto index) {
    constexpr ImageBlockFormat block = kImageBlocks[decltype(index)::value];
    const std::uint64_t bytes = image_block_bytes(block.id, dims);
    if (block.only_when_counted && bytes == 0) return;
    layout.*block.offset = at;
    at = align_up(at + static_cast<std::uint32_t>(bytes), kImageBlockAlignment);
  };
  for_each_image_block(place, std::make_index_sequence<std::size(kImageBlocks)>{});
  layout.total_size = at + kImageTrailerSize;
  return layout;
}

constexpr ImageLayout image_layout(std::uint32_t training_points, std::uint32_t input_dims,
                                   std::uint32_t segment_count, std::uint16_t version_major = kImageVersionMajor,
                                   std::uint32_t variance_rank = 0, std::uint32_t extra_inputs = 0,
                                   std::uint32_t hysteresis_floats = 0, std::uint32_t compliance_floats = 0,
                                   std::uint32_t cables_floats = 0) {
  return image_layout(ImageDims{training_points, input_dims, segment_count, version_major, variance_rank,
                                extra_inputs, hysteresis_floats, compliance_floats, cables_floats});
}

// A header field's type; the value is its size in bytes.
enum class ImageFieldType : std::uint8_t { u8 = 1, u16 = 2, u32 = 4 };

// What an image older than a field holds in the field's bytes.
enum class ImageFieldRule : std::uint8_t {
  none,             // every version this parser reads has the field
  reserved_before,  // older versions reserve the bytes: each must be zero
  zero_before,      // older minor versions of its major version name the field and require it to be zero;
                    // older major versions reserve its bytes
};

struct ImageHeaderField {
  const char* name;
  std::uint8_t offset;
  ImageFieldType type;
  std::uint16_t version_major;  // the version that gave the field its meaning
  std::uint16_t version_minor;
  ImageFieldRule before = ImageFieldRule::none;  // what an older image holds there
  ImageBlockId locates = ImageBlockId::none;     // the block whose offset the field holds

  constexpr std::uint32_t size() const { return static_cast<std::uint32_t>(type); }
};

// The header's fields (all little-endian). A field is used from its version
// on; before it, its rule says what the bytes hold.
namespace image_field {
inline constexpr ImageHeaderField magic{"magic", 0, ImageFieldType::u32, 1, 0};
inline constexpr ImageHeaderField version_major{"version_major", 4, ImageFieldType::u16, 1, 0};
inline constexpr ImageHeaderField version_minor{"version_minor", 6, ImageFieldType::u16, 1, 0};
inline constexpr ImageHeaderField header_size{"header_size", 8, ImageFieldType::u32, 1, 0};
// Including the CRC trailer.
inline constexpr ImageHeaderField total_size{"total_size", 12, ImageFieldType::u32, 1, 0};
// The points: N training inputs or M inducing inputs.
inline constexpr ImageHeaderField training_points{"training_points", 16, ImageFieldType::u32, 1, 0};
// D = 2 * segment_count + extra_inputs.
inline constexpr ImageHeaderField input_dims{"input_dims", 20, ImageFieldType::u16, 1, 0};
// Always kImageOutputs.
inline constexpr ImageHeaderField output_dims{"output_dims", 22, ImageFieldType::u16, 1, 0};
inline constexpr ImageHeaderField segment_count{"segment_count", 24, ImageFieldType::u16, 1, 0};
// ImageScalar, ImageKernel and InputEncoding.
inline constexpr ImageHeaderField scalar_type{"scalar_type", 26, ImageFieldType::u8, 1, 0};
inline constexpr ImageHeaderField kernel_kind{"kernel_kind", 27, ImageFieldType::u8, 1, 0};
inline constexpr ImageHeaderField input_encoding{"input_encoding", 28, ImageFieldType::u8, 1, 0};
// ImageModelKind.
inline constexpr ImageHeaderField model_kind{"model_kind", 29, ImageFieldType::u8, 2, 0,
                                             ImageFieldRule::reserved_before};
// Inputs after the joint encoding: 0, or 1 the payload.
inline constexpr ImageHeaderField extra_inputs{"extra_inputs", 30, ImageFieldType::u8, 2, 0,
                                               ImageFieldRule::reserved_before};
// The compliance block's segments; zero without one.
inline constexpr ImageHeaderField compliance_segments{"compliance_segments", 31, ImageFieldType::u8, 2,
                                                      kImageVersionMinorCompliance,
                                                      ImageFieldRule::reserved_before};
inline constexpr ImageHeaderField geometry_offset{"geometry_offset", 32, ImageFieldType::u32, 1, 0,
                                                  ImageFieldRule::none, ImageBlockId::geometry};
inline constexpr ImageHeaderField parameters_offset{"parameters_offset", 36, ImageFieldType::u32, 1, 0,
                                                    ImageFieldRule::none, ImageBlockId::parameters};
inline constexpr ImageHeaderField inputs_offset{"inputs_offset", 40, ImageFieldType::u32, 1, 0,
                                                ImageFieldRule::none, ImageBlockId::inputs};
inline constexpr ImageHeaderField alpha_offset{"alpha_offset", 44, ImageFieldType::u32, 1, 0, ImageFieldRule::none,
                                               ImageBlockId::alpha};
inline constexpr ImageHeaderField metadata_offset{"metadata_offset", 48, ImageFieldType::u32, 1, 0,
                                                  ImageFieldRule::none, ImageBlockId::metadata};
// Always kImageMetadataSize.
inline constexpr ImageHeaderField metadata_size{"metadata_size", 52, ImageFieldType::u32, 1, 0};
// The variance block and R, its points; zero without one. v2.0 defines no
// block: both zero.
inline constexpr ImageHeaderField variance_offset{"variance_offset", 56, ImageFieldType::u32, 2, kImageVersionMinor,
                                                  ImageFieldRule::zero_before, ImageBlockId::variance};
inline constexpr ImageHeaderField variance_rank{"variance_rank", 60, ImageFieldType::u16, 2, kImageVersionMinor,
                                                ImageFieldRule::zero_before};
// The hysteresis block's cables and play operators per cable; zero without one.
inline constexpr ImageHeaderField hysteresis_cables{"hysteresis_cables", 62, ImageFieldType::u8, 2,
                                                    kImageVersionMinorHysteresis,
                                                    ImageFieldRule::reserved_before};
inline constexpr ImageHeaderField hysteresis_operators{"hysteresis_operators", 63, ImageFieldType::u8, 2,
                                                       kImageVersionMinorHysteresis,
                                                       ImageFieldRule::reserved_before};
}  // namespace image_field

// Every field in the order of its bytes.
inline constexpr ImageHeaderField kImageHeaderFields[] = {
    image_field::magic,           image_field::version_major,       image_field::version_minor,
    image_field::header_size,     image_field::total_size,          image_field::training_points,
    image_field::input_dims,      image_field::output_dims,         image_field::segment_count,
    image_field::scalar_type,     image_field::kernel_kind,         image_field::input_encoding,
    image_field::model_kind,      image_field::extra_inputs,        image_field::compliance_segments,
    image_field::geometry_offset, image_field::parameters_offset,   image_field::inputs_offset,
    image_field::alpha_offset,    image_field::metadata_offset,     image_field::metadata_size,
    image_field::variance_offset, image_field::variance_rank,       image_field::hysteresis_cables,
    image_field::hysteresis_operators,
};

// The header field that holds a block's offset; null for a block that lies
// where the layout puts it (hysteresis, compliance).
constexpr const ImageHeaderField* image_block_offset_field(ImageBlockId block) {
  for (const ImageHeaderField& field : kImageHeaderFields) {
    if (field.locates == block) return &field;
  }
  return nullptr;
}

// The fields cover the header, each byte once, in order; each field is
// aligned to its size.
constexpr bool image_header_fields_tile() {
  std::uint32_t at = 0;
  for (const ImageHeaderField& field : kImageHeaderFields) {
    if (field.offset != at || field.offset % field.size() != 0) return false;
    at += field.size();
  }
  return at == kImageHeaderSize;
}
static_assert(image_header_fields_tile(), "the header fields must cover the header byte for byte");

// Calls visit(index) for each header field, index a std::integral_constant,
// in the order of the header's bytes, until visit returns false. Unrolled at
// compile time, each field a constant: a firmware build keeps neither the
// table nor its names.
template <typename Visit, std::size_t... I>
constexpr bool for_each_image_header_field(Visit&& visit, std::index_sequence<I...>) {
  return (visit(std::integral_constant<std::size_t, I>{}) && ...);
}

template <typename Visit>
constexpr bool for_each_image_header_field(Visit&& visit) {
  return for_each_image_header_field(visit, std::make_index_sequence<std::size(kImageHeaderFields)>{});
}

// Whether an image of this version uses the field (gives it its meaning).
// Minor versions count within any major version from the field's on.
constexpr bool image_field_in_use(const ImageHeaderField& field, std::uint16_t major, std::uint16_t minor) {
  return major >= field.version_major && minor >= field.version_minor;
}

// Whether an image of this version names the field, used or not: a
// zero_before field is named from the first minor version of its major.
constexpr bool image_field_named(const ImageHeaderField& field, std::uint16_t major, std::uint16_t minor) {
  return field.before == ImageFieldRule::zero_before ? major >= field.version_major
                                                     : image_field_in_use(field, major, minor);
}

// The field's value, from a header of at least field.offset + field.size() bytes.
inline std::uint32_t image_field_value(const std::uint8_t* header, const ImageHeaderField& field) {
  std::uint32_t value = 0;  // little-endian: the low bytes come first
  std::memcpy(&value, header + field.offset, field.size());
  return value;
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
  cables,       // invalid_parameters, v2.7: the cables block's counts and angles, and the inputs they imply
};
inline constexpr int kImageCheckCount = static_cast<int>(ImageCheckId::cables) + 1;

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
    case ImageCheckId::cables: return "cables";
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

// A named run of the payload's floats (name nullptr in the firmware's run,
// which reports no names), for the checks that walk several.
struct NamedFloats {
  const char* name;
  const float* values;
  std::uint32_t count;
};

// A named run's values against `good`; nothing to check where the image
// has no such run.
template <typename Run, typename Good>
bool expect_each(Run& run, const NamedFloats& named, Good good, ImageCheckId check, ImageStatus failure,
                 ImageExpectation expectation) {
  return named.values == nullptr ||
         expect_each(run, named.values, named.count, good, check, failure, named.name, expectation);
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
bool check_hysteresis_block(Run& run, const float* block, std::uint32_t cables, std::uint32_t operators,
                            bool history) {
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
      // The history inputs divide the last operator's lag by its width.
      const bool history_operator = history && k + 1 == operators;
      if (!expect(width_finite, "hysteresis_width", i, width, 0, Expect::finite) ||
          !expect(!width_finite || width >= 0.0f, "hysteresis_width", i, width, 0, Expect::at_least) ||
          !expect(!width_finite || !history_operator || width > 0.0f, "hysteresis_history_width", i, width, 0,
                  Expect::positive) ||
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
    const std::uint32_t total = image_field_value(bytes, image_field::total_size);
    end_ = total >= kImageHeaderSize + kImageTrailerSize && total <= size ? total - kImageTrailerSize
                                                                          : static_cast<std::uint32_t>(size);
    const auto major = static_cast<std::uint16_t>(image_field_value(bytes, image_field::version_major));
    const ImageDims dims{image_field_value(bytes, image_field::training_points),
                         image_field_value(bytes, image_field::input_dims),
                         image_field_value(bytes, image_field::segment_count), major,
                         major == 1 ? 0 : image_field_value(bytes, image_field::variance_rank)};
    // The float blocks the header locates: all but the metadata.
    int i = 0;
    for_each_image_header_field([&](auto index) {
      constexpr ImageHeaderField field = kImageHeaderFields[decltype(index)::value];
      if constexpr (field.locates != ImageBlockId::none && field.locates != ImageBlockId::metadata) {
        const std::uint64_t floats = image_block_bytes(field.locates, dims) / 4;
        const std::uint32_t at = image_field_value(bytes, field);
        // Blocks the scan cannot check (outside the bytes, misaligned) stay
        // empty: parse_image() then checks them itself, or refuses the image.
        if (floats != 0 && at % alignof(float) == 0 && at <= end_ && 4 * floats <= end_ - at) {
          first_[i] = at;
          floats_[i] = static_cast<std::uint32_t>(floats);
        }
        ++i;
      }
      return true;
    });
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

// What the header declares, as the checks have read it so far.
struct DeclaredImage {
  std::uint16_t major = kImageVersionMajor;
  std::uint16_t layout_major = kImageVersionMajor;  // an unknown major version is laid out as the newest
  std::uint16_t minor = 0;
  bool v1 = false;
  std::uint32_t total = 0;  // total_size
  bool total_holds_trailer = false;
  bool aligned = false;  // the buffer
  ImageModelKind kind = ImageModelKind::exact_gp;
  std::uint32_t points = 0;
  std::uint32_t input_dims = 0;
  std::uint32_t segments = 0;
  std::uint32_t extra = 0;
  InputEncoding encoding = InputEncoding::bend_vector;
  std::uint32_t rank = 0;
  std::uint32_t hysteresis_cables = 0;
  std::uint32_t hysteresis_operators = 0;
  std::uint32_t compliance_segments = 0;

  ImageDims dims() const {
    return ImageDims{points,
                     input_dims,
                     segments,
                     major,
                     rank,
                     extra,
                     image_hysteresis_floats(hysteresis_cables, hysteresis_operators),
                     image_compliance_floats(compliance_segments),
                     cables_block() ? image_cables_floats(segments) : 0};
  }
  bool cables_block() const { return image_has_cables_block(major, minor); }
  // The field's value, or zero where this version does not name it.
  std::uint32_t value(const std::uint8_t* bytes, const ImageHeaderField& field) const {
    return image_field_named(field, layout_major, minor) ? image_field_value(bytes, field) : 0;
  }
};

// The blocks where a stopping run has verified them to lie, or where a
// reporting run found them inside the buffer; null otherwise.
struct ImageBlocks {
  const float* geometry = nullptr;
  const float* parameters = nullptr;
  const float* inputs = nullptr;
  const float* alpha = nullptr;
  const std::uint8_t* metadata = nullptr;
  const float* variance = nullptr;
  const float* hysteresis = nullptr;
  const float* compliance = nullptr;
  const float* cables = nullptr;
};

// The parameter arrays, back to back; null where the block is not readable.
struct ImageParameterArrays {
  const float* input_mean = nullptr;
  const float* input_scale = nullptr;
  const float* length_scale = nullptr;
  const float* output_mean = nullptr;
  const float* output_scale = nullptr;
  const float* signal_variance = nullptr;
  const float* noise_variance = nullptr;
  const float* input_min = nullptr;  // v2
  const float* input_max = nullptr;
  const float* extra_default = nullptr;  // with extra inputs
};

inline ImageParameterArrays parameter_arrays(const float* parameters, const DeclaredImage& h) {
  ImageParameterArrays p;
  if (parameters == nullptr) return p;
  const std::uint32_t d = h.input_dims;
  p.input_mean = parameters;
  p.input_scale = parameters + d;
  p.length_scale = parameters + 2 * d;
  p.output_mean = parameters + 3 * d;
  p.output_scale = p.output_mean + kImageOutputs;
  p.signal_variance = p.output_mean + 2 * kImageOutputs;
  p.noise_variance = p.output_mean + 3 * kImageOutputs;
  p.input_min = h.v1 ? nullptr : p.output_mean + 4 * kImageOutputs;
  p.input_max = h.v1 ? nullptr : p.input_min + d;
  p.extra_default = h.extra > 0 ? p.output_mean + 4 * kImageOutputs + 2 * d : nullptr;
  return p;
}

// size, magic and version: what a file too short for a header may still
// show. False where the run must stop, and where there is no whole header.
template <typename Run>
bool check_identity(Run& run, const std::uint8_t* bytes, std::size_t size, DeclaredImage& h) {
  using Expect = ImageExpectation;
  const bool whole_header = bytes != nullptr && size >= kImageHeaderSize;
  if (!run.expect(whole_header, ImageCheckId::size, ImageStatus::truncated, "file_size", -1,
                  static_cast<double>(size), kImageHeaderSize, Expect::at_least)) {
    return false;
  }
  const ImageHeaderField& magic = image_field::magic;
  if (bytes != nullptr && size >= magic.offset + magic.size()) {
    const std::uint32_t declared_magic = image_field_value(bytes, magic);
    if (!run.expect(declared_magic == kImageMagic, ImageCheckId::magic, ImageStatus::bad_magic, magic.name, -1,
                    declared_magic, kImageMagic, Expect::equal)) {
      return false;
    }
  }
  const ImageHeaderField& major = image_field::version_major;
  if (bytes != nullptr && size >= major.offset + major.size()) {
    h.major = static_cast<std::uint16_t>(image_field_value(bytes, major));
    const bool readable = h.major >= kImageOldestVersionMajor && h.major <= kImageVersionMajor;
    if (!run.expect(readable, ImageCheckId::version, ImageStatus::unsupported_version, major.name, -1, h.major,
                    kImageVersionMajor, Expect::known)) {
      return false;
    }
  }
  h.v1 = h.major == 1;
  h.layout_major = h.v1 ? h.major : kImageVersionMajor;
  return whole_header;
}

// header_size and total_size against the buffer, and the buffer's alignment.
template <typename Run>
bool check_sizes(Run& run, const std::uint8_t* bytes, std::size_t size, DeclaredImage& h) {
  using Expect = ImageExpectation;
  const std::uint32_t declared_header = image_field_value(bytes, image_field::header_size);
  if (!run.expect(declared_header == kImageHeaderSize, ImageCheckId::header, ImageStatus::bad_header, "header_size",
                  -1, declared_header, kImageHeaderSize, Expect::equal)) {
    return false;
  }
  h.total = image_field_value(bytes, image_field::total_size);
  h.total_holds_trailer = h.total >= kImageHeaderSize + kImageTrailerSize;
  if (!run.expect(h.total_holds_trailer, ImageCheckId::header, ImageStatus::bad_header, "total_size", -1, h.total,
                  kImageHeaderSize + kImageTrailerSize, Expect::at_least)) {
    return false;
  }
  if (h.total_holds_trailer && !run.expect(h.total <= size, ImageCheckId::size, ImageStatus::truncated, "total_size",
                                           -1, h.total, static_cast<double>(size), Expect::at_most)) {
    return false;
  }
  const std::uintptr_t address = reinterpret_cast<std::uintptr_t>(bytes);
  h.aligned = address % alignof(float) == 0;
  return run.expect(h.aligned, ImageCheckId::alignment, ImageStatus::misaligned, "buffer_address", -1,
                    static_cast<double>(address), alignof(float), Expect::multiple_of);
}

template <typename Run>
bool check_checksum(Run& run, const std::uint8_t* bytes, std::size_t size, const DeclaredImage& h,
                    const ImageScan* scan) {
  if (!h.total_holds_trailer || h.total > size) return true;
  const std::uint32_t stored_crc = read_u32(bytes + h.total - kImageTrailerSize);
  const std::uint32_t covered = h.total - kImageTrailerSize;
  const bool scanned = scan != nullptr && scan->done() && scan->bytes() == bytes && scan->crc_bytes() == covered;
  const std::uint32_t computed_crc = scanned ? scan->crc() : crc32(bytes, covered);
  return run.expect(stored_crc == computed_crc, ImageCheckId::checksum, ImageStatus::checksum_mismatch, "crc32", -1,
                    stored_crc, computed_crc, ImageExpectation::equal);
}

// One field's bytes in an image older than the field, by the field's rule:
// reserved bytes are each zero, a named but unused field is zero.
template <std::size_t I, typename Run>
bool check_older_version_field(Run& run, const std::uint8_t* bytes, const DeclaredImage& h) {
  constexpr ImageHeaderField field = kImageHeaderFields[I];
  if constexpr (field.before == ImageFieldRule::none) {
    return true;
  } else {
    if (image_field_in_use(field, h.layout_major, h.minor)) return true;
    if (field.before == ImageFieldRule::zero_before && image_field_named(field, h.layout_major, h.minor)) {
      const std::uint32_t value = image_field_value(bytes, field);
      return run.expect(value == 0, ImageCheckId::header, ImageStatus::bad_header, field.name, -1, value, 0,
                        ImageExpectation::equal);
    }
    for (std::uint32_t at = field.offset; at < field.offset + field.size(); ++at) {
      if (!run.expect(bytes[at] == 0, ImageCheckId::header, ImageStatus::bad_header, "reserved",
                      static_cast<std::int32_t>(at), bytes[at], 0, ImageExpectation::equal)) {
        return false;
      }
    }
    return true;
  }
}

// Every field the image's version does not use holds what its rule says, in
// the order of the header's bytes.
template <typename Run>
bool check_older_version_fields(Run& run, const std::uint8_t* bytes, const DeclaredImage& h) {
  return for_each_image_header_field(
      [&](auto index) { return check_older_version_field<decltype(index)::value>(run, bytes, h); });
}

template <typename Run>
bool check_kind(Run& run, const std::uint8_t* bytes, DeclaredImage& h) {
  using Expect = ImageExpectation;
  const std::uint8_t scalar = bytes[image_field::scalar_type.offset];
  const std::uint8_t kernel = bytes[image_field::kernel_kind.offset];
  const std::uint8_t encoding = bytes[image_field::input_encoding.offset];
  if (!run.expect(scalar == static_cast<std::uint8_t>(ImageScalar::float32), ImageCheckId::kind,
                  ImageStatus::unsupported_kind, "scalar_type", -1, scalar,
                  static_cast<std::uint8_t>(ImageScalar::float32), Expect::equal) ||
      !run.expect(kernel == static_cast<std::uint8_t>(ImageKernel::squared_exponential_ard), ImageCheckId::kind,
                  ImageStatus::unsupported_kind, "kernel_kind", -1, kernel,
                  static_cast<std::uint8_t>(ImageKernel::squared_exponential_ard), Expect::equal) ||
      !run.expect(is_known(static_cast<InputEncoding>(encoding)), ImageCheckId::kind, ImageStatus::unsupported_kind,
                  "input_encoding", -1, encoding, static_cast<std::uint8_t>(InputEncoding::bend_vector),
                  Expect::known)) {
    return false;
  }
  h.encoding = static_cast<InputEncoding>(encoding);
  // The cable-fit encoding is v2.4's, the history's v2.5: an older image
  // cannot declare them.
  const std::uint32_t encoding_minor = takes_history(h.encoding)           ? kImageVersionMinorHistory
                                       : takes_cable_residuals(h.encoding) ? kImageVersionMinorCableFit
                                                                           : 0;
  if (encoding_minor > 0 &&
      !run.expect(!h.v1 && h.minor >= encoding_minor, ImageCheckId::kind, ImageStatus::unsupported_kind,
                  "version_minor", -1, h.minor, encoding_minor, Expect::at_least)) {
    return false;
  }
  const std::uint8_t declared_kind = bytes[image_field::model_kind.offset];
  h.kind = h.v1 ? ImageModelKind::exact_gp : static_cast<ImageModelKind>(declared_kind);
  h.extra = h.value(bytes, image_field::extra_inputs);
  if (h.v1) return true;
  // One extra input is defined, the tip payload; more would be inputs this
  // parser cannot supply.
  return run.expect(is_known(h.kind), ImageCheckId::kind, ImageStatus::unsupported_kind, "model_kind", -1,
                    declared_kind, static_cast<std::uint8_t>(ImageModelKind::sparse_gp), Expect::known) &&
         run.expect(h.extra <= kMaxExtraInputs, ImageCheckId::kind, ImageStatus::unsupported_kind, "extra_inputs", -1,
                    h.extra, kMaxExtraInputs, Expect::at_most);
}

// The inputs the encoding gives the declared segments (segment_count is a
// u16: any declared count stays an int, and the check against input_dims
// reports one beyond any robot).
inline std::uint32_t encoded_inputs(const DeclaredImage& h) {
  return static_cast<std::uint32_t>(encoded_input_count(h.encoding, static_cast<int>(h.segments)));
}

template <typename Run>
bool check_dims(Run& run, const std::uint8_t* bytes, DeclaredImage& h) {
  using Expect = ImageExpectation;
  h.points = image_field_value(bytes, image_field::training_points);
  h.input_dims = image_field_value(bytes, image_field::input_dims);
  h.segments = image_field_value(bytes, image_field::segment_count);
  const std::uint32_t outputs = image_field_value(bytes, image_field::output_dims);
  return run.expect(h.points >= 1, ImageCheckId::header, ImageStatus::bad_header, "training_points", -1, h.points, 1,
                    Expect::at_least) &&
         run.expect(h.segments >= 1, ImageCheckId::header, ImageStatus::bad_header, "segment_count", -1, h.segments,
                    1, Expect::at_least) &&
         // With the cables block the inputs follow its counts (checked there).
         (h.cables_block() ||
          run.expect(h.input_dims == encoded_inputs(h) + h.extra, ImageCheckId::header, ImageStatus::bad_header,
                     "input_dims", -1, h.input_dims, encoded_inputs(h) + h.extra, Expect::equal)) &&
         run.expect(outputs == kImageOutputs, ImageCheckId::header, ImageStatus::bad_header, "output_dims", -1,
                    outputs, kImageOutputs, Expect::equal);
}

// v2.2: the hysteresis block's counts, both zero without one. The model
// library's storage (HysteresisModel) bounds them, not the build.
template <typename Run>
bool check_hysteresis_counts(Run& run, const std::uint8_t* bytes, DeclaredImage& h) {
  using Expect = ImageExpectation;
  h.hysteresis_cables = h.value(bytes, image_field::hysteresis_cables);
  h.hysteresis_operators = h.value(bytes, image_field::hysteresis_operators);
  const std::uint32_t cables = h.hysteresis_cables;
  const std::uint32_t operators = h.hysteresis_operators;
  // The history inputs come from the block's state.
  if (cables == 0 && operators == 0) {
    return run.expect(!takes_history(h.encoding), ImageCheckId::header, ImageStatus::bad_header,
                      "history_without_hysteresis", -1, cables, 4 * h.segments, Expect::equal);
  }
  // With the cables block, its count (checked there); the paper's four a
  // segment without.
  return (h.cables_block() ||
          run.expect(cables == 4 * h.segments, ImageCheckId::header, ImageStatus::bad_header, "hysteresis_cables", -1,
                     cables, 4 * h.segments, Expect::equal)) &&
         run.expect(operators >= 1, ImageCheckId::header, ImageStatus::bad_header, "hysteresis_operators", -1,
                    operators, 1, Expect::at_least) &&
         run.expect(cables <= static_cast<std::uint32_t>(kMaxCables), ImageCheckId::capacity,
                    ImageStatus::over_capacity, "hysteresis_cables", -1, cables, kMaxCables, Expect::at_most) &&
         run.expect(operators <= static_cast<std::uint32_t>(kMaxHysteresisOperators), ImageCheckId::capacity,
                    ImageStatus::over_capacity, "hysteresis_operators", -1, operators, kMaxHysteresisOperators,
                    Expect::at_most);
}

// v2.3: the compliance block's segment count, zero without one. The sag
// needs the tip load, so only a model with the payload input has one.
template <typename Run>
bool check_compliance_counts(Run& run, const std::uint8_t* bytes, DeclaredImage& h) {
  using Expect = ImageExpectation;
  h.compliance_segments = h.value(bytes, image_field::compliance_segments);
  if (h.compliance_segments == 0) return true;
  return run.expect(h.compliance_segments == h.segments, ImageCheckId::header, ImageStatus::bad_header,
                    "compliance_segments", -1, h.compliance_segments, h.segments, Expect::equal) &&
         run.expect(h.extra == 1, ImageCheckId::header, ImageStatus::bad_header, "compliance_without_payload_input",
                    -1, h.extra, 1, Expect::equal);
}

template <typename Run>
bool check_capacity(Run& run, const DeclaredImage& h, const ImageCapacity& capacity) {
  using Expect = ImageExpectation;
  return run.expect(h.points <= capacity.max_training_points, ImageCheckId::capacity, ImageStatus::over_capacity,
                    "training_points", -1, h.points, capacity.max_training_points, Expect::at_most) &&
         run.expect(h.segments <= capacity.max_segments, ImageCheckId::capacity, ImageStatus::over_capacity,
                    "segment_count", -1, h.segments, capacity.max_segments, Expect::at_most) &&
         run.expect(h.rank <= capacity.max_variance_rank, ImageCheckId::capacity, ImageStatus::over_capacity,
                    "variance_rank", -1, h.rank, capacity.max_variance_rank, Expect::at_most) &&
         run.expect(h.extra <= capacity.max_extra_inputs, ImageCheckId::capacity, ImageStatus::over_capacity,
                    "extra_inputs", -1, h.extra, capacity.max_extra_inputs, Expect::at_most) &&
         // The cable-fit and history encodings' inputs share the storage of
         // a robot of the most segments: 4n + E (8n + E, ...) must fit where
         // 2n + E always does.
         (encoded_inputs(h) <= 2 * h.segments ||
          run.expect(h.input_dims <= 2 * capacity.max_segments + capacity.max_extra_inputs, ImageCheckId::capacity,
                     ImageStatus::over_capacity, "input_dims", -1, h.input_dims,
                     2 * capacity.max_segments + capacity.max_extra_inputs, Expect::at_most));
}

// Each header field that locates a block holds a multiple of the block
// alignment (the fields in the order of the header's bytes).
template <typename Run>
bool check_block_alignment(Run& run, const std::uint8_t* bytes, const DeclaredImage& h) {
  return for_each_image_header_field([&](auto index) {
    constexpr ImageHeaderField field = kImageHeaderFields[decltype(index)::value];
    if constexpr (field.locates == ImageBlockId::none) {
      return true;
    } else {
      const std::uint32_t offset = h.value(bytes, field);
      return run.expect(offset % kImageBlockAlignment == 0, ImageCheckId::alignment, ImageStatus::misaligned,
                        Run::name(field.name), -1, offset, kImageBlockAlignment, ImageExpectation::multiple_of);
    }
  });
}

// The bytes of the arrays the dims declare. Under a generous capacity the
// 32-bit layout arithmetic could wrap into a size that matches; dims whose
// arrays alone exceed the image cannot.
inline std::uint64_t declared_array_bytes(const DeclaredImage& h) {
  const ImageDims dims = h.dims();
  return (std::uint64_t{h.points} * (h.input_dims + kImageOutputs) + image_variance_floats(h.rank, h.input_dims) +
          dims.hysteresis_floats + dims.compliance_floats + dims.cables_floats) *
         4;
}

// total_size, metadata_size and every block offset are what the dims imply.
template <typename Run>
bool check_layout(Run& run, const std::uint8_t* bytes, const DeclaredImage& h) {
  using Expect = ImageExpectation;
  const std::uint64_t array_bytes = declared_array_bytes(h);
  if (!run.expect(array_bytes <= h.total, ImageCheckId::layout, ImageStatus::size_mismatch, "total_size", -1, h.total,
                  static_cast<double>(array_bytes), Expect::at_least)) {
    return false;
  }
  if (array_bytes > h.total) return true;
  const ImageLayout expected = image_layout(h.dims());
  if (!run.expect(h.total == expected.total_size, ImageCheckId::layout, ImageStatus::size_mismatch, "total_size", -1,
                  h.total, expected.total_size, Expect::equal)) {
    return false;
  }
  const std::uint32_t declared_metadata_size = image_field_value(bytes, image_field::metadata_size);
  if (!run.expect(declared_metadata_size == kImageMetadataSize, ImageCheckId::layout, ImageStatus::size_mismatch,
                  "metadata_size", -1, declared_metadata_size, kImageMetadataSize, Expect::equal)) {
    return false;
  }
  return for_each_image_header_field([&](auto index) {
    constexpr ImageHeaderField field = kImageHeaderFields[decltype(index)::value];
    if constexpr (field.locates == ImageBlockId::none) {
      return true;
    } else {
      const std::uint32_t offset = h.value(bytes, field);
      const std::uint32_t expected_offset = expected.*image_block(field.locates).offset;
      return run.expect(offset == expected_offset, ImageCheckId::layout, ImageStatus::size_mismatch,
                        Run::name(field.name), -1, offset, expected_offset, Expect::equal);
    }
  });
}

// From here on a stopping run has verified every block to lie where the
// dims put it, inside the image. A reporting run reads a block where the
// header puts it, if it lies inside the buffer. The hysteresis and
// compliance blocks lie where the dims put them (no offset fields).
template <typename Run>
ImageBlocks locate_blocks(const std::uint8_t* bytes, std::size_t size, const DeclaredImage& h) {
  const ImageDims dims = h.dims();
  const auto block = [&]([[maybe_unused]] ImageBlockId id, std::uint32_t offset) -> const float* {
    if constexpr (Run::kEveryCheck) {
      const std::uint64_t block_bytes = image_block_bytes(id, dims);
      if (!h.aligned || offset % alignof(float) != 0 || offset > size || block_bytes > size - offset) return nullptr;
    }
    return reinterpret_cast<const float*>(bytes + offset);
  };
  const auto declared = [&](const ImageHeaderField& field) { return block(field.locates, h.value(bytes, field)); };
  ImageBlocks b;
  b.geometry = declared(image_field::geometry_offset);
  b.parameters = declared(image_field::parameters_offset);
  b.inputs = declared(image_field::inputs_offset);
  b.alpha = declared(image_field::alpha_offset);
  b.metadata = reinterpret_cast<const std::uint8_t*>(declared(image_field::metadata_offset));
  b.variance = h.rank > 0 ? declared(image_field::variance_offset) : nullptr;
  const ImageLayout implied = image_layout(dims);
  const bool fit = declared_array_bytes(h) <= h.total;
  b.hysteresis = dims.hysteresis_floats > 0 && fit ? block(ImageBlockId::hysteresis, implied.hysteresis_offset)
                                                   : nullptr;
  b.compliance = dims.compliance_floats > 0 && fit ? block(ImageBlockId::compliance, implied.compliance_offset)
                                                   : nullptr;
  b.cables = dims.cables_floats > 0 && fit ? block(ImageBlockId::cables, implied.cables_offset) : nullptr;
  return b;
}

// No NaN or Inf in the payload; the verdict is the scan's where it covers
// a block.
template <typename Run>
bool check_finite(Run& run, const ImageBlocks& b, const DeclaredImage& h, const ImageScan* scan) {
  const std::uint32_t n = h.points;
  const NamedFloats payload[] = {
      {Run::name("geometry"), b.geometry, 3 * h.segments},
      {Run::name("parameters"), b.parameters, image_parameter_floats(h.input_dims, h.major, h.extra)},
      {Run::name("inputs"), b.inputs, n * h.input_dims},
      {Run::name("alpha"), b.alpha, n * kImageOutputs},
      {Run::name("variance"), b.variance, static_cast<std::uint32_t>(image_variance_floats(h.rank, h.input_dims))}};
  for (const auto& values : payload) {
    bool finite = true;
    if (values.values != nullptr && scan != nullptr && scan->covers(values.values, values.count, finite)) {
      if (!run.expect(finite, ImageCheckId::finite, ImageStatus::non_finite_payload, values.name, -1, 0.0, 0.0,
                      ImageExpectation::finite, values.count)) {
        return false;
      }
      continue;
    }
    if (!expect_each(run, values, is_finite, ImageCheckId::finite, ImageStatus::non_finite_payload,
                     ImageExpectation::finite)) {
      return false;
    }
  }
  return true;
}

template <typename Run>
bool check_positive(Run& run, const ImageBlocks& b, const ImageParameterArrays& p, const DeclaredImage& h) {
  const std::uint32_t d = h.input_dims;
  const NamedFloats must_be_positive[] = {
      {Run::name("geometry"), b.geometry, 3 * h.segments},
      {Run::name("input_scale"), p.input_scale, d},
      {Run::name("length_scale"), p.length_scale, d},
      {Run::name("output_scale"), p.output_scale, kImageOutputs},
      {Run::name("signal_variance"), p.signal_variance, kImageOutputs},
      {Run::name("noise_variance"), p.noise_variance, kImageOutputs}};
  return std::all_of(std::begin(must_be_positive), std::end(must_be_positive), [&run](const NamedFloats& values) {
    return expect_each(run, values, is_positive, ImageCheckId::positive, ImageStatus::invalid_parameters,
                       ImageExpectation::positive);
  });
}

// v2: input_min <= input_max, and a payload's default is not negative (it is
// a mass).
template <typename Run>
bool check_ranges(Run& run, const ImageParameterArrays& p, const DeclaredImage& h) {
  if (p.input_min != nullptr) {
    bool all_ordered = true;
    for (std::uint32_t i = 0; i < h.input_dims; ++i) {
      if (p.input_min[i] <= p.input_max[i]) continue;
      all_ordered = false;
      if (!run.expect(false, ImageCheckId::ranges, ImageStatus::invalid_parameters, "input_min",
                      static_cast<std::int32_t>(i), p.input_min[i], p.input_max[i], ImageExpectation::at_most)) {
        return false;
      }
    }
    if (all_ordered) {
      run.expect(true, ImageCheckId::ranges, ImageStatus::invalid_parameters, "input_min", -1, 0, 0,
                 ImageExpectation::at_most, h.input_dims);
    }
  }
  for (std::uint32_t i = 0; p.extra_default != nullptr && i < h.extra; ++i) {
    if (!run.expect(p.extra_default[i] >= 0.0f, ImageCheckId::ranges, ImageStatus::invalid_parameters,
                    "extra_input_default", static_cast<std::int32_t>(i), p.extra_default[i], 0,
                    ImageExpectation::at_least)) {
      return false;
    }
  }
  return true;
}

// v2: the metadata's fitted_rows. A v1 image was fitted on exactly the rows
// it carries.
template <typename Run>
bool check_fitted_rows(Run& run, const std::uint8_t* metadata, const DeclaredImage& h, std::uint32_t& fitted) {
  using Expect = ImageExpectation;
  fitted = h.points;
  if (h.v1 || metadata == nullptr) return true;
  fitted = read_u32(metadata + image_metadata_field::fitted_rows);
  if (!run.expect(fitted >= 1, ImageCheckId::fitted_rows, ImageStatus::invalid_parameters, "fitted_rows", -1, fitted,
                  1, Expect::at_least)) {
    return false;
  }
  // An exact model's points are its rows; a sparse model's rows may be
  // any number, its points summarise them.
  return h.kind != ImageModelKind::exact_gp ||
         run.expect(fitted == h.points, ImageCheckId::fitted_rows, ImageStatus::invalid_parameters, "fitted_rows", -1,
                    fitted, h.points, Expect::equal);
}

// The variance block: positive calibration, a threshold that is a share
// of the signal variance, a zero reserved word, positive factor diagonals
// (they are divided by), and the one kernel it was computed with: its
// factors hold signal / noise, so every output must share both.
template <typename Run>
bool check_variance_block(Run& run, const float* variance, const ImageParameterArrays& p, const DeclaredImage& h) {
  using Expect = ImageExpectation;
  using namespace image_variance_field;
  if (variance == nullptr) {
    // Nothing to judge; the report still names the check.
    if (Run::kEveryCheck) {
      run.expect(true, ImageCheckId::variance, ImageStatus::invalid_parameters, "variance_rank", -1, h.rank, 0,
                 Expect::at_least);
    }
    return true;
  }
  if (!expect_each(run, variance, reserved, is_positive, ImageCheckId::positive, ImageStatus::invalid_parameters,
                   Run::name("variance_calibration"), Expect::positive)) {
    return false;
  }
  const float* inducing_factor = variance + points + h.rank * h.input_dims;
  const float* posterior_factor = inducing_factor + packed_triangle_floats(h.rank);
  for (std::uint32_t i = 0; i < h.rank; ++i) {
    const std::uint32_t diagonal = packed_triangle_floats(i + 1) - 1;
    if (!run.expect(is_positive(inducing_factor[diagonal]), ImageCheckId::variance, ImageStatus::invalid_parameters,
                    "variance_inducing_factor", static_cast<std::int32_t>(diagonal), inducing_factor[diagonal], 0,
                    Expect::positive) ||
        !run.expect(is_positive(posterior_factor[diagonal]), ImageCheckId::variance, ImageStatus::invalid_parameters,
                    "variance_posterior_factor", static_cast<std::int32_t>(diagonal), posterior_factor[diagonal], 0,
                    Expect::positive)) {
      return false;
    }
  }
  if (!run.expect(variance[extrapolation_variance] <= 1.0f, ImageCheckId::variance, ImageStatus::invalid_parameters,
                  "extrapolation_variance", -1, variance[extrapolation_variance], 1, Expect::at_most) ||
      !run.expect(variance[reserved] == 0.0f, ImageCheckId::variance, ImageStatus::invalid_parameters,
                  "variance_reserved", -1, variance[reserved], 0, Expect::equal)) {
    return false;
  }
  for (int k = 1; p.signal_variance != nullptr && k < kImageOutputs; ++k) {
    if (!run.expect(p.signal_variance[k] == p.signal_variance[0], ImageCheckId::variance,
                    ImageStatus::invalid_parameters, "signal_variance", k, p.signal_variance[k], p.signal_variance[0],
                    Expect::equal) ||
        !run.expect(p.noise_variance[k] == p.noise_variance[0], ImageCheckId::variance,
                    ImageStatus::invalid_parameters, "noise_variance", k, p.noise_variance[k], p.noise_variance[0],
                    Expect::equal)) {
      return false;
    }
  }
  return true;
}

// The v2.2 and v2.3 blocks' values; without a block the report still
// names the check.
template <typename Run>
bool check_optional_blocks(Run& run, const ImageBlocks& b, const DeclaredImage& h) {
  if (b.hysteresis == nullptr && Run::kEveryCheck) {
    run.expect(true, ImageCheckId::hysteresis, ImageStatus::invalid_parameters, "hysteresis_operators", -1,
               h.hysteresis_operators, 0, ImageExpectation::at_least);
  }
  if (b.hysteresis != nullptr &&
      !check_hysteresis_block(run, b.hysteresis, h.hysteresis_cables, h.hysteresis_operators,
                              takes_history(h.encoding))) {
    return false;
  }
  if (b.compliance == nullptr && Run::kEveryCheck) {
    run.expect(true, ImageCheckId::compliance, ImageStatus::invalid_parameters, "compliance_segments", -1,
               h.compliance_segments, 0, ImageExpectation::at_least);
  }
  return b.compliance == nullptr || check_compliance_block(run, b.compliance, h.compliance_segments);
}

// The cables block (v2.7): every segment's count 3 or 4, its angles finite
// and the unused ones zero, anchors that read a bend (CableLayout::
// validate), and the counts the header's inputs and hysteresis cables
// follow from. `cable_count` is the robot's cables, the paper's four a
// segment without the block. False where a stopping run must stop.
template <typename Run>
bool check_cables_block(Run& run, const float* block, const DeclaredImage& h, std::uint32_t& cable_count) {
  using Expect = ImageExpectation;
  using namespace image_cables_field;
  cable_count = 4 * h.segments;
  if (block == nullptr) {
    if (Run::kEveryCheck) {
      run.expect(true, ImageCheckId::cables, ImageStatus::invalid_parameters, "cables", -1, 0, 0, Expect::finite);
    }
    return true;
  }
  cable_count = 0;
  std::uint32_t inputs = h.extra;
  for (std::uint32_t i = 0; i < h.segments; ++i) {
    const float* segment = block + i * per_segment;
    const float count = segment[image_cables_field::count];
    const auto index = static_cast<std::int32_t>(i);
    if (!run.expect(count == 3.0f || count == 4.0f, ImageCheckId::cables, ImageStatus::invalid_parameters,
                    "cable_count", index, count, kMaxCablesPerSegment, Expect::known)) {
      return false;
    }
    const int cables = count == 3.0f ? 3 : 4;
    for (int j = 0; j < kMaxCablesPerSegment; ++j) {
      const float angle = segment[angles + j];
      const auto at = static_cast<std::int32_t>(i * per_segment + angles + j);
      if (!run.expect(std::isfinite(angle), ImageCheckId::cables, ImageStatus::invalid_parameters, "cable_angle", at,
                      angle, 0, Expect::finite) ||
          !run.expect(j < cables || angle == 0.0f, ImageCheckId::cables, ImageStatus::invalid_parameters,
                      "cable_angle_unused", at, angle, 0, Expect::equal)) {
        return false;
      }
    }
    const CableLayout<float> layout = CableLayout<float>::at_angles(cables, segment + angles);
    if (!run.expect(layout.validate() == Status::ok, ImageCheckId::cables, ImageStatus::invalid_parameters,
                    "cable_anchor_spread", index, layout.spread(), CableLayout<float>::kLeastAnchorSpread,
                    Expect::at_least)) {
      return false;
    }
    cable_count += static_cast<std::uint32_t>(cables);
    inputs += static_cast<std::uint32_t>(encoded_segment_inputs(h.encoding, cables));
  }
  if (!run.expect(h.input_dims == inputs, ImageCheckId::cables, ImageStatus::invalid_parameters, "input_dims", -1,
                  h.input_dims, inputs, Expect::equal) ||
      !run.expect(h.hysteresis_cables == 0 || h.hysteresis_cables == cable_count, ImageCheckId::cables,
                  ImageStatus::invalid_parameters, "hysteresis_cables", -1, h.hysteresis_cables, cable_count,
                  Expect::equal)) {
    return false;
  }
  run.expect(true, ImageCheckId::cables, ImageStatus::invalid_parameters, Run::name("cables"), -1, 0, 0,
             Expect::finite, image_cables_floats(h.segments));
  return true;
}

// The view of an image that passed every check.
inline ImageView make_view(const std::uint8_t* bytes, const DeclaredImage& h, const ImageBlocks& b,
                           const ImageParameterArrays& p, std::uint32_t fitted, std::uint32_t cable_count) {
  ImageView v{};
  v.version_major = h.major;
  v.version_minor = h.minor;
  v.total_size = h.total;
  v.model_kind = h.kind;
  v.training_points = h.points;
  v.fitted_rows = fitted;
  v.input_dims = static_cast<int>(h.input_dims);
  v.segment_count = static_cast<int>(h.segments);
  v.extra_inputs = static_cast<int>(h.extra);
  v.encoding = static_cast<InputEncoding>(bytes[image_field::input_encoding.offset]);
  v.geometry = b.geometry;
  v.input_mean = p.input_mean;
  v.input_scale = p.input_scale;
  v.length_scale = p.length_scale;
  v.output_mean = p.output_mean;
  v.output_scale = p.output_scale;
  v.signal_variance = p.signal_variance;
  v.noise_variance = p.noise_variance;
  v.input_min = p.input_min;
  v.input_max = p.input_max;
  v.extra_input_default = p.extra_default;
  v.inputs = b.inputs;
  v.alpha = b.alpha;
  v.variance_rank = h.rank;
  if (b.variance != nullptr) {
    v.variance_calibration = b.variance;
    v.variance_points = b.variance + image_variance_field::points;
    v.variance_inducing_factor = v.variance_points + h.rank * h.input_dims;
    v.variance_posterior_factor = v.variance_inducing_factor + packed_triangle_floats(h.rank);
  }
  if (b.hysteresis != nullptr) {
    const std::uint32_t values = h.hysteresis_cables * h.hysteresis_operators;
    v.hysteresis_cables = static_cast<int>(h.hysteresis_cables);
    v.hysteresis_operators = static_cast<int>(h.hysteresis_operators);
    v.hysteresis_widths = b.hysteresis + image_hysteresis_field::widths;
    v.hysteresis_weights = v.hysteresis_widths + values;
    v.hysteresis_homing_lags = v.hysteresis_weights + values;
  }
  if (b.compliance != nullptr) {
    v.compliance_segments = static_cast<int>(h.compliance_segments);
    v.compliance_weighted_gravity = b.compliance + image_compliance_field::weighted_gravity;
    v.compliance_ratios = b.compliance + image_compliance_field::ratios;
    v.compliance_softening = v.compliance_ratios + h.compliance_segments;
    v.compliance_unloaded_mass = v.compliance_softening + 1;
  }
  v.cables = b.cables;
  v.cable_count = static_cast<int>(cable_count);
  const std::uint8_t* metadata = b.metadata;
  v.dataset_hash = read_u64(metadata + image_metadata_field::dataset_hash);
  v.created_unix_s = static_cast<std::int64_t>(read_u64(metadata + image_metadata_field::created_unix_s));
  v.validation_samples = read_u32(metadata + image_metadata_field::validation_samples);
  std::memcpy(&v.metrics, metadata + image_metadata_field::metrics, sizeof(ImageMetrics));
  v.trainer = reinterpret_cast<const char*>(metadata + image_metadata_field::trainer);
  return v;
}

}  // namespace detail

// Segment i's cables in a parsed image: the block's count, or the paper's
// four without one.
inline int image_segment_cables(const ImageView& image, int segment) {
  if (image.cables == nullptr) return 4;
  return image.cables[segment * image_cables_field::per_segment + image_cables_field::count] == 3.0f ? 3 : 4;
}

namespace detail {

// Checks run from what is needed to read the rest (size, magic, version,
// header) to the integrity check and then to the meaning of the payload, so
// every rejection reports the first thing that is wrong. A reporting run
// goes past failures, but evaluates a check only where its bytes lie inside
// the buffer (and floats only where they are aligned).
template <typename Run>
ImageStatus check_image(const std::uint8_t* bytes, std::size_t size, ImageView& view, const ImageCapacity& capacity,
                        Run& run, const ImageScan* scan = nullptr) {
  DeclaredImage h;
  if (!check_identity(run, bytes, size, h) || !check_sizes(run, bytes, size, h) ||
      !check_checksum(run, bytes, size, h, scan)) {
    return run.status;
  }
  h.minor = static_cast<std::uint16_t>(image_field_value(bytes, image_field::version_minor));
  h.rank = h.value(bytes, image_field::variance_rank);
  if (!check_older_version_fields(run, bytes, h) ||
      !check_kind(run, bytes, h) || !check_dims(run, bytes, h) || !check_hysteresis_counts(run, bytes, h) ||
      !check_compliance_counts(run, bytes, h) || !check_capacity(run, h, capacity) ||
      !check_block_alignment(run, bytes, h) || !check_layout(run, bytes, h)) {
    return run.status;
  }
  const ImageBlocks blocks = locate_blocks<Run>(bytes, size, h);
  const ImageParameterArrays parameters = parameter_arrays(blocks.parameters, h);
  std::uint32_t fitted = h.points;
  std::uint32_t cable_count = 0;
  if (!check_finite(run, blocks, h, scan) || !check_positive(run, blocks, parameters, h) ||
      !check_ranges(run, parameters, h) || !check_fitted_rows(run, blocks.metadata, h, fitted) ||
      !check_variance_block(run, blocks.variance, parameters, h) || !check_optional_blocks(run, blocks, h) ||
      !check_cables_block(run, blocks.cables, h, cable_count)) {
    return run.status;
  }
  if (run.status != ImageStatus::ok) return run.status;
  view = make_view(bytes, h, blocks, parameters, fitted, cable_count);
  return ImageStatus::ok;
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
