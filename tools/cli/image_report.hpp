#pragma once
// Everything `cdcr inspect` can say about a flash image, including a damaged
// one: each field is read for display only if it lies inside the file, and
// the checks are the shared parser's own (model::parse_image with the
// firmware's compile-time capacity, reporting every check to a sink), so a
// report shows every problem rather than only the first, and nothing here
// decides what is valid.

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "cdcr/model/flash_image.hpp"

namespace cdcr::cli {

// The enumerator's name, e.g. "checksum_mismatch": stable for scripts,
// unlike the message of model::to_string().
const char* image_status_name(model::ImageStatus status);

enum class CheckResult { passed, failed, not_checked };

// One of the parser's checks (model::ImageCheckId), with its findings put
// into words.
struct ImageCheck {
  model::ImageCheckId id;
  const char* name;  // size, magic, version, header, alignment, checksum, kind, capacity, layout, finite, positive,
                     // ranges, fitted_rows, variance, hysteresis, compliance
  CheckResult result = CheckResult::not_checked;
  std::string detail;
};

struct ImageHeaderFields {
  std::uint32_t magic = 0;
  std::uint16_t version_major = 0;
  std::uint16_t version_minor = 0;
  std::uint32_t header_size = 0;
  std::uint32_t total_size = 0;
  std::uint32_t training_points = 0;
  std::uint16_t input_dims = 0;
  std::uint16_t output_dims = 0;
  std::uint16_t segment_count = 0;
  std::uint8_t scalar_type = 0;
  std::uint8_t kernel_kind = 0;
  std::uint8_t input_encoding = 0;
  std::uint8_t model_kind = 0;    // v2
  std::uint8_t extra_inputs = 0;  // v2
  std::uint32_t geometry_offset = 0;
  std::uint32_t parameters_offset = 0;
  std::uint32_t inputs_offset = 0;
  std::uint32_t alpha_offset = 0;
  std::uint32_t metadata_offset = 0;
  std::uint32_t metadata_size = 0;
  std::uint32_t variance_offset = 0;  // v2
  std::uint16_t variance_rank = 0;    // v2
  std::uint8_t hysteresis_cables = 0;     // v2.2
  std::uint8_t hysteresis_operators = 0;  // v2.2
  std::uint8_t compliance_segments = 0;   // v2.3
};

// A block where the header says it is, with the size the dims imply.
struct ImageBlock {
  const char* name;
  std::uint64_t offset;
  std::uint64_t size;
  bool inside_file;
};

struct ImageParameters {
  std::vector<float> input_mean, input_scale, length_scale;        // D each
  std::vector<float> output_mean, output_scale;                    // 6 each
  std::vector<float> signal_variance, noise_variance;              // 6 each
  std::vector<float> input_min, input_max;                         // D each, v2; empty for v1
  std::vector<float> extra_input_default;                          // extra_inputs: the default payload (kg)
};

// The hysteresis block (v2.2), cables x operators each, row-major per cable.
struct ImageHysteresis {
  int cables = 0;
  int operators = 0;
  std::vector<float> widths_mm, weights, homing_lags_mm;
};

// The cables block (v2.7): a segment's cables and their anchor angles.
struct ImageSegmentCables {
  float count = 0;
  std::array<float, 4> angles_rad{};
};

// The compliance block (v2.3).
struct ImageCompliance {
  std::array<float, 3> weighted_gravity{};  // rad per kg mm, base frame
  std::vector<float> ratios;                // per segment
  float softening_per_rad = 0;
  float unloaded_mass_kg = 0;
};

struct ImageMetadata {
  std::uint64_t dataset_hash = 0;
  std::int64_t created_unix_s = 0;
  std::uint32_t validation_samples = 0;
  std::uint32_t fitted_rows = 0;  // v2; v1: reserved
  model::ImageMetrics metrics{};
  std::string trainer;  // non-printable bytes escaped as \xNN
};

struct ImageReport {
  std::size_t file_size = 0;
  model::ImageStatus status = model::ImageStatus::truncated;

  std::optional<std::uint32_t> magic;          // from 4 bytes on
  std::optional<std::uint16_t> version_major;  // from 6 bytes on
  std::optional<ImageHeaderFields> header;     // from 64 bytes on
  std::optional<std::uint32_t> stored_crc;     // when total_size lies inside the file
  std::optional<std::uint32_t> computed_crc;
  std::optional<std::uint64_t> trailing_bytes;

  std::vector<ImageBlock> blocks;
  std::optional<std::vector<std::array<float, 3>>> geometry;  // per segment: length_mm, radius_mm, theta_max_rad
  std::optional<ImageParameters> parameters;
  std::optional<float> max_abs_input;  // kernel coordinates
  std::optional<float> max_abs_alpha;
  std::optional<ImageHysteresis> hysteresis;  // a v2.2 image's block, when it lies inside the file
  std::optional<ImageCompliance> compliance;  // a v2.3 image's block, when it lies inside the file
  std::optional<std::vector<ImageSegmentCables>> cables;  // a v2.7 image's block, when it lies inside the file
  std::optional<ImageMetadata> metadata;
  // Data rows the model was fitted on: the metadata's for v2, the training
  // points for v1 (whose images carry exactly the rows they were fitted on).
  std::optional<std::uint32_t> fitted_rows;

  std::vector<ImageCheck> checks;  // in the parser's order
  std::optional<model::ImageCheckId> first_failure;  // the check whose failure is the status

  bool valid() const { return status == model::ImageStatus::ok; }
  const ImageCheck* failed_check() const;
};

ImageReport inspect_image(const std::uint8_t* bytes, std::size_t size);

}  // namespace cdcr::cli
