#pragma once
// Flash image format v1: the trained compensation model as the firmware reads
// it. The full specification is model/flash-image-v1.md; this header is its
// only parser, shared by the host tools and the firmware.
//
// parse_image() validates everything before anything is used, and returns a
// view whose arrays point into the caller's bytes (zero-copy: on a board the
// bytes are the flash region itself).

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
inline constexpr std::uint16_t kImageVersionMajor = 1;
inline constexpr std::uint16_t kImageVersionMinor = 0;
inline constexpr std::uint32_t kImageHeaderSize = 64;
inline constexpr std::uint32_t kImageBlockAlignment = 8;
inline constexpr std::uint32_t kImageTrailerSize = 4;  // CRC-32
inline constexpr std::uint32_t kImageMetadataSize = 88;
inline constexpr int kImageOutputs = 6;                 // an error twist, (v, omega)

enum class ImageScalar : std::uint8_t { float32 = 1 };
// Squared exponential with ARD length scales shared by all outputs, and a
// signal and noise variance per output.
enum class ImageKernel : std::uint8_t { squared_exponential_ard = 1 };

enum class ImageStatus : std::uint8_t {
  ok = 0,
  truncated,            // fewer bytes than the header, or than its total_size
  bad_magic,
  unsupported_version,  // unknown major version
  bad_header,           // header_size, reserved fields or dims inconsistent
  size_mismatch,        // total_size disagrees with the size the dims imply
  misaligned,           // buffer not 4-byte aligned, or a block offset not 8-byte aligned
  checksum_mismatch,
  unsupported_kind,     // scalar type, kernel or input encoding this parser does not know
  over_capacity,        // dims beyond the caller's compile-time capacity
  non_finite_payload,   // NaN or Inf anywhere in the float payload
  invalid_parameters,   // non-positive scale, variance or geometry
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
    case ImageStatus::unsupported_kind: return "unsupported scalar type, kernel or input encoding";
    case ImageStatus::over_capacity: return "image dimensions exceed this build's capacity";
    case ImageStatus::non_finite_payload: return "image payload contains NaN or Inf";
    case ImageStatus::invalid_parameters: return "image holds a non-positive scale, variance or geometry value";
  }
  return "unknown image status";
}

struct ImageCapacity {
  std::uint32_t max_training_points = kMaxTrainingPoints;
  std::uint32_t max_segments = kMaxSegments;
};

// Byte offsets of the header fields (all little-endian).
namespace image_field {
inline constexpr std::size_t magic = 0;             // u32
inline constexpr std::size_t version_major = 4;     // u16
inline constexpr std::size_t version_minor = 6;     // u16
inline constexpr std::size_t header_size = 8;       // u32
inline constexpr std::size_t total_size = 12;       // u32, including the CRC trailer
inline constexpr std::size_t training_points = 16;  // u32, N
inline constexpr std::size_t input_dims = 20;       // u16, D = 2 * segments
inline constexpr std::size_t output_dims = 22;      // u16, always 6
inline constexpr std::size_t segment_count = 24;    // u16
inline constexpr std::size_t scalar_type = 26;      // u8, ImageScalar
inline constexpr std::size_t kernel_kind = 27;      // u8, ImageKernel
inline constexpr std::size_t input_encoding = 28;   // u8, InputEncoding
inline constexpr std::size_t reserved_a = 29;       // 3 bytes, zero
inline constexpr std::size_t geometry_offset = 32;  // u32
inline constexpr std::size_t parameters_offset = 36;
inline constexpr std::size_t inputs_offset = 40;
inline constexpr std::size_t alpha_offset = 44;
inline constexpr std::size_t metadata_offset = 48;
inline constexpr std::size_t metadata_size = 52;    // u32, kImageMetadataSize
inline constexpr std::size_t reserved_b = 56;       // 8 bytes, zero
}  // namespace image_field

// Byte offsets inside the metadata block.
namespace image_metadata_field {
inline constexpr std::size_t dataset_hash = 0;        // u64, FNV-1a of the training data file
inline constexpr std::size_t created_unix_s = 8;      // i64
inline constexpr std::size_t validation_samples = 16; // u32
inline constexpr std::size_t reserved = 20;           // u32, zero
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
  std::uint16_t version_minor;
  std::uint32_t total_size;
  std::uint32_t training_points;  // N
  int input_dims;                 // D
  int segment_count;
  InputEncoding encoding;
  const float* geometry;        // segment_count x {backbone_length_mm, anchor_radius_mm, theta_max_rad}
  const float* input_mean;      // D
  const float* input_scale;     // D
  const float* length_scale;    // D, in normalised input units
  const float* output_mean;     // 6
  const float* output_scale;    // 6
  const float* signal_variance; // 6, normalised output units
  const float* noise_variance;  // 6, normalised output units
  const float* inputs;          // N x D row-major, kernel coordinates: (x - mean) / (scale * length_scale)
  const float* alpha;           // N x 6 row-major: (K + noise I)^-1 y per normalised output
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
  std::uint32_t metadata_offset;
  std::uint32_t total_size;
};

constexpr std::uint32_t align_up(std::uint32_t value, std::uint32_t alignment) {
  return (value + alignment - 1) / alignment * alignment;
}

constexpr std::uint32_t image_parameter_floats(std::uint32_t input_dims) {
  return 3 * input_dims + 4 * kImageOutputs;
}

// Blocks follow the header in this order, each 8-byte aligned, then the CRC.
constexpr ImageLayout image_layout(std::uint32_t training_points, std::uint32_t input_dims,
                                   std::uint32_t segment_count) {
  ImageLayout layout{};
  std::uint32_t at = kImageHeaderSize;
  layout.geometry_offset = at;
  at = align_up(at + 4 * 3 * segment_count, kImageBlockAlignment);
  layout.parameters_offset = at;
  at = align_up(at + 4 * image_parameter_floats(input_dims), kImageBlockAlignment);
  layout.inputs_offset = at;
  at = align_up(at + 4 * training_points * input_dims, kImageBlockAlignment);
  layout.alpha_offset = at;
  at = align_up(at + 4 * training_points * kImageOutputs, kImageBlockAlignment);
  layout.metadata_offset = at;
  at = align_up(at + kImageMetadataSize, kImageBlockAlignment);
  layout.total_size = at + kImageTrailerSize;
  return layout;
}

namespace detail {
inline std::uint16_t read_u16(const std::uint8_t* p) { std::uint16_t v; std::memcpy(&v, p, 2); return v; }
inline std::uint32_t read_u32(const std::uint8_t* p) { std::uint32_t v; std::memcpy(&v, p, 4); return v; }
inline std::uint64_t read_u64(const std::uint8_t* p) { std::uint64_t v; std::memcpy(&v, p, 8); return v; }

inline bool all_finite(const float* values, std::uint32_t count) {
  for (std::uint32_t i = 0; i < count; ++i) {
    if (!std::isfinite(values[i])) return false;
  }
  return true;
}
inline bool all_positive(const float* values, std::uint32_t count) {
  for (std::uint32_t i = 0; i < count; ++i) {
    if (!(values[i] > 0.0f)) return false;
  }
  return true;
}
}  // namespace detail

// Checks run from what is needed to read the rest (size, magic, version,
// header) to the integrity check and then to the meaning of the payload, so
// every rejection reports the first thing that is wrong.
inline ImageStatus parse_image(const std::uint8_t* bytes, std::size_t size, ImageView& view,
                               const ImageCapacity& capacity = {}) {
  using namespace image_field;
  using detail::read_u16;
  using detail::read_u32;
  if (bytes == nullptr || size < kImageHeaderSize) return ImageStatus::truncated;
  if (read_u32(bytes + magic) != kImageMagic) return ImageStatus::bad_magic;
  if (read_u16(bytes + version_major) != kImageVersionMajor) return ImageStatus::unsupported_version;
  if (read_u32(bytes + header_size) != kImageHeaderSize) return ImageStatus::bad_header;
  const std::uint32_t declared_total = read_u32(bytes + total_size);
  if (declared_total < kImageHeaderSize + kImageTrailerSize) return ImageStatus::bad_header;
  if (declared_total > size) return ImageStatus::truncated;
  if (reinterpret_cast<std::uintptr_t>(bytes) % alignof(float) != 0) return ImageStatus::misaligned;

  std::uint32_t stored_crc = read_u32(bytes + declared_total - kImageTrailerSize);
  if (crc32(bytes, declared_total - kImageTrailerSize) != stored_crc) return ImageStatus::checksum_mismatch;

  for (std::size_t i = 0; i < 3; ++i) {
    if (bytes[reserved_a + i] != 0) return ImageStatus::bad_header;
  }
  for (std::size_t i = 0; i < 8; ++i) {
    if (bytes[reserved_b + i] != 0) return ImageStatus::bad_header;
  }
  if (bytes[scalar_type] != static_cast<std::uint8_t>(ImageScalar::float32) ||
      bytes[kernel_kind] != static_cast<std::uint8_t>(ImageKernel::squared_exponential_ard) ||
      !is_known(static_cast<InputEncoding>(bytes[input_encoding]))) {
    return ImageStatus::unsupported_kind;
  }

  const std::uint32_t n = read_u32(bytes + training_points);
  const std::uint32_t d = read_u16(bytes + input_dims);
  const std::uint32_t segments = read_u16(bytes + segment_count);
  if (n == 0 || segments == 0 || d != 2 * segments || read_u16(bytes + output_dims) != kImageOutputs) {
    return ImageStatus::bad_header;
  }
  if (n > capacity.max_training_points || segments > capacity.max_segments) return ImageStatus::over_capacity;

  const std::uint32_t offsets[] = {read_u32(bytes + geometry_offset), read_u32(bytes + parameters_offset),
                                   read_u32(bytes + inputs_offset), read_u32(bytes + alpha_offset),
                                   read_u32(bytes + metadata_offset)};
  for (std::uint32_t offset : offsets) {
    if (offset % kImageBlockAlignment != 0) return ImageStatus::misaligned;
  }
  // Under a generous capacity the 32-bit layout arithmetic below could wrap
  // into a size that matches; dims whose arrays alone exceed the image cannot.
  if (std::uint64_t{n} * (d + kImageOutputs) * 4 > declared_total) return ImageStatus::size_mismatch;
  const ImageLayout expected = image_layout(n, d, segments);
  if (declared_total != expected.total_size || read_u32(bytes + metadata_size) != kImageMetadataSize ||
      offsets[0] != expected.geometry_offset || offsets[1] != expected.parameters_offset ||
      offsets[2] != expected.inputs_offset || offsets[3] != expected.alpha_offset ||
      offsets[4] != expected.metadata_offset) {
    return ImageStatus::size_mismatch;
  }

  const auto floats_at = [bytes](std::uint32_t offset) { return reinterpret_cast<const float*>(bytes + offset); };
  ImageView v{};
  v.version_minor = read_u16(bytes + version_minor);
  v.total_size = declared_total;
  v.training_points = n;
  v.input_dims = static_cast<int>(d);
  v.segment_count = static_cast<int>(segments);
  v.encoding = static_cast<InputEncoding>(bytes[input_encoding]);
  v.geometry = floats_at(expected.geometry_offset);
  const float* parameters = floats_at(expected.parameters_offset);
  v.input_mean = parameters;
  v.input_scale = parameters + d;
  v.length_scale = parameters + 2 * d;
  v.output_mean = parameters + 3 * d;
  v.output_scale = v.output_mean + kImageOutputs;
  v.signal_variance = v.output_scale + kImageOutputs;
  v.noise_variance = v.signal_variance + kImageOutputs;
  v.inputs = floats_at(expected.inputs_offset);
  v.alpha = floats_at(expected.alpha_offset);

  const std::uint8_t* metadata = bytes + expected.metadata_offset;
  v.dataset_hash = detail::read_u64(metadata + image_metadata_field::dataset_hash);
  v.created_unix_s = static_cast<std::int64_t>(detail::read_u64(metadata + image_metadata_field::created_unix_s));
  v.validation_samples = read_u32(metadata + image_metadata_field::validation_samples);
  std::memcpy(&v.metrics, metadata + image_metadata_field::metrics, sizeof(ImageMetrics));
  v.trainer = reinterpret_cast<const char*>(metadata + image_metadata_field::trainer);

  if (!detail::all_finite(v.geometry, 3 * segments) || !detail::all_finite(parameters, image_parameter_floats(d)) ||
      !detail::all_finite(v.inputs, n * d) || !detail::all_finite(v.alpha, n * kImageOutputs)) {
    return ImageStatus::non_finite_payload;
  }
  if (!detail::all_positive(v.geometry, 3 * segments) || !detail::all_positive(v.input_scale, d) ||
      !detail::all_positive(v.length_scale, d) || !detail::all_positive(v.output_scale, kImageOutputs) ||
      !detail::all_positive(v.signal_variance, kImageOutputs) ||
      !detail::all_positive(v.noise_variance, kImageOutputs)) {
    return ImageStatus::invalid_parameters;
  }
  view = v;
  return ImageStatus::ok;
}

}  // namespace cdcr::model
