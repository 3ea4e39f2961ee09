#include "image_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <fmt/format.h>

#include "cdcr/model/crc32.hpp"
#include "cdcr/model/input_encoding.hpp"
#include "cdcr/model/limits.hpp"

namespace cdcr::cli {

namespace {

using model::ImageStatus;

template <typename T>
T read(const std::uint8_t* bytes, std::size_t offset) {
  T value;
  std::memcpy(&value, bytes + offset, sizeof(T));
  return value;
}

std::vector<float> read_floats(const std::uint8_t* bytes, std::uint64_t offset, std::uint64_t count) {
  std::vector<float> values(static_cast<std::size_t>(count));
  if (count > 0) std::memcpy(values.data(), bytes + offset, static_cast<std::size_t>(count) * sizeof(float));
  return values;
}

std::string escaped_text(const std::uint8_t* bytes, std::size_t max_length) {
  std::string text;
  for (std::size_t i = 0; i < max_length && bytes[i] != 0; ++i) {
    const std::uint8_t c = bytes[i];
    if (c >= 0x20 && c < 0x7F && c != '\\') {
      text += static_cast<char>(c);
    } else {
      text += fmt::format("\\x{:02x}", c);
    }
  }
  return text;
}

std::string magic_text(std::uint32_t magic) {
  std::uint8_t bytes[4];
  std::memcpy(bytes, &magic, 4);
  return fmt::format("'{}' (0x{:08x})", escaped_text(bytes, 4), magic);
}

void set(ImageCheck& check, bool passed, std::string detail) {
  check.result = passed ? CheckResult::passed : CheckResult::failed;
  check.detail = std::move(detail);
}

std::string join(const std::vector<std::string>& parts, const char* separator = "; ") {
  std::string out;
  for (const std::string& part : parts) {
    if (!out.empty()) out += separator;
    out += part;
  }
  return out;
}

// The payload blocks the finite and positive checks look at.
struct FloatBlock {
  const char* name;
  std::uint64_t offset;
  std::uint64_t count;
};

}  // namespace

const char* image_status_name(ImageStatus status) {
  switch (status) {
    case ImageStatus::ok: return "ok";
    case ImageStatus::truncated: return "truncated";
    case ImageStatus::bad_magic: return "bad_magic";
    case ImageStatus::unsupported_version: return "unsupported_version";
    case ImageStatus::bad_header: return "bad_header";
    case ImageStatus::size_mismatch: return "size_mismatch";
    case ImageStatus::misaligned: return "misaligned";
    case ImageStatus::checksum_mismatch: return "checksum_mismatch";
    case ImageStatus::unsupported_kind: return "unsupported_kind";
    case ImageStatus::over_capacity: return "over_capacity";
    case ImageStatus::non_finite_payload: return "non_finite_payload";
    case ImageStatus::invalid_parameters: return "invalid_parameters";
  }
  return "unknown";
}

const char* check_for_status(ImageStatus status) {
  switch (status) {
    case ImageStatus::ok: return nullptr;
    case ImageStatus::truncated: return "size";
    case ImageStatus::bad_magic: return "magic";
    case ImageStatus::unsupported_version: return "version";
    case ImageStatus::bad_header: return "header";
    case ImageStatus::misaligned: return "alignment";
    case ImageStatus::checksum_mismatch: return "checksum";
    case ImageStatus::unsupported_kind: return "kind";
    case ImageStatus::over_capacity: return "capacity";
    case ImageStatus::size_mismatch: return "layout";
    case ImageStatus::non_finite_payload: return "finite";
    case ImageStatus::invalid_parameters: return "positive";
  }
  return nullptr;
}

const ImageCheck* ImageReport::failed_check() const {
  const char* name = check_for_status(status);
  if (name == nullptr) return nullptr;
  for (const ImageCheck& check : checks) {
    if (std::strcmp(check.name, name) == 0) return &check;
  }
  return nullptr;
}

ImageReport inspect_image(const std::uint8_t* bytes, std::size_t size) {
  using namespace model::image_field;
  ImageReport r;
  r.file_size = size;
  {
    model::ImageView view{};
    r.status = model::parse_image(bytes, size, view);
  }
  for (const char* name : {"size", "magic", "version", "header", "alignment", "checksum", "kind", "capacity", "layout",
                           "finite", "positive"}) {
    r.checks.push_back(ImageCheck{name, CheckResult::not_checked, {}});
  }
  const auto check = [&r](const char* name) -> ImageCheck& {
    for (ImageCheck& c : r.checks) {
      if (std::strcmp(c.name, name) == 0) return c;
    }
    return r.checks.front();  // unreachable: every name above is listed
  };

  if (size >= 4) {
    r.magic = read<std::uint32_t>(bytes, magic);
    set(check("magic"), *r.magic == model::kImageMagic,
        *r.magic == model::kImageMagic ? magic_text(*r.magic) : magic_text(*r.magic) + ", expected 'CDGP'");
  }
  if (size >= 6) {
    r.version_major = read<std::uint16_t>(bytes, version_major);
    set(check("version"), *r.version_major == model::kImageVersionMajor,
        fmt::format("major version {}{}", *r.version_major,
                    *r.version_major == model::kImageVersionMajor ? "" : ", this parser reads 1"));
  }
  if (size < model::kImageHeaderSize) {
    set(check("size"), false, fmt::format("{} bytes, fewer than the {}-byte header", size, model::kImageHeaderSize));
    for (ImageCheck& c : r.checks) {
      if (c.result == CheckResult::not_checked) c.detail = "the header is incomplete";
    }
    return r;
  }

  ImageHeaderFields h;
  h.magic = *r.magic;
  h.version_major = *r.version_major;
  h.version_minor = read<std::uint16_t>(bytes, version_minor);
  h.header_size = read<std::uint32_t>(bytes, header_size);
  h.total_size = read<std::uint32_t>(bytes, total_size);
  h.training_points = read<std::uint32_t>(bytes, training_points);
  h.input_dims = read<std::uint16_t>(bytes, input_dims);
  h.output_dims = read<std::uint16_t>(bytes, output_dims);
  h.segment_count = read<std::uint16_t>(bytes, segment_count);
  h.scalar_type = bytes[scalar_type];
  h.kernel_kind = bytes[kernel_kind];
  h.input_encoding = bytes[input_encoding];
  h.geometry_offset = read<std::uint32_t>(bytes, geometry_offset);
  h.parameters_offset = read<std::uint32_t>(bytes, parameters_offset);
  h.inputs_offset = read<std::uint32_t>(bytes, inputs_offset);
  h.alpha_offset = read<std::uint32_t>(bytes, alpha_offset);
  h.metadata_offset = read<std::uint32_t>(bytes, metadata_offset);
  h.metadata_size = read<std::uint32_t>(bytes, metadata_size);
  r.header = h;

  // size: the file holds the whole image; more is fine.
  const bool total_plausible = h.total_size >= model::kImageHeaderSize + model::kImageTrailerSize;
  if (!total_plausible) {
    check("size").detail = fmt::format("total_size {} is not a size", h.total_size);
  } else if (h.total_size <= size) {
    r.trailing_bytes = size - h.total_size;
    set(check("size"), true,
        fmt::format("file {} bytes, image {} bytes, {} trailing", size, h.total_size, *r.trailing_bytes));
  } else {
    set(check("size"), false, fmt::format("file {} bytes, fewer than total_size {}", size, h.total_size));
  }

  // header: everything about the header itself that the parser checks.
  {
    std::vector<std::string> problems;
    if (h.header_size != model::kImageHeaderSize) {
      problems.push_back(fmt::format("header_size {}, expected {}", h.header_size, model::kImageHeaderSize));
    }
    if (!total_plausible) problems.push_back(fmt::format("total_size {} cannot hold header and trailer", h.total_size));
    for (std::size_t i = 0; i < 3; ++i) {
      if (bytes[reserved_a + i] != 0) problems.push_back(fmt::format("reserved byte {} is non-zero", reserved_a + i));
    }
    for (std::size_t i = 0; i < 8; ++i) {
      if (bytes[reserved_b + i] != 0) problems.push_back(fmt::format("reserved byte {} is non-zero", reserved_b + i));
    }
    if (h.training_points == 0) problems.push_back("no training points");
    if (h.segment_count == 0) problems.push_back("no segments");
    if (h.input_dims != 2u * h.segment_count) {
      problems.push_back(fmt::format("input_dims {} is not twice segment_count {}", h.input_dims, h.segment_count));
    }
    if (h.output_dims != model::kImageOutputs) {
      problems.push_back(fmt::format("output_dims {}, expected {}", h.output_dims, model::kImageOutputs));
    }
    set(check("header"), problems.empty(), problems.empty() ? "consistent" : join(problems));
  }
  const bool dims_consistent = h.training_points > 0 && h.segment_count > 0 && h.input_dims == 2u * h.segment_count &&
                               h.output_dims == model::kImageOutputs;

  const std::uint32_t offsets[] = {h.geometry_offset, h.parameters_offset, h.inputs_offset, h.alpha_offset,
                                   h.metadata_offset};
  const char* offset_names[] = {"geometry_offset", "parameters_offset", "inputs_offset", "alpha_offset",
                                "metadata_offset"};
  {
    std::vector<std::string> problems;
    for (int i = 0; i < 5; ++i) {
      if (offsets[i] % model::kImageBlockAlignment != 0) {
        problems.push_back(fmt::format("{} {} is not a multiple of {}", offset_names[i], offsets[i],
                                       model::kImageBlockAlignment));
      }
    }
    set(check("alignment"), problems.empty(), problems.empty() ? "block offsets are multiples of 8" : join(problems));
  }

  if (total_plausible && h.total_size <= size) {
    r.stored_crc = read<std::uint32_t>(bytes, h.total_size - model::kImageTrailerSize);
    r.computed_crc = model::crc32(bytes, h.total_size - model::kImageTrailerSize);
    set(check("checksum"), *r.stored_crc == *r.computed_crc,
        fmt::format("stored 0x{:08x}, computed 0x{:08x}", *r.stored_crc, *r.computed_crc));
  } else {
    check("checksum").detail = "the trailer is not inside the file";
  }

  {
    std::vector<std::string> problems;
    if (h.scalar_type != static_cast<std::uint8_t>(model::ImageScalar::float32)) {
      problems.push_back(fmt::format("scalar type {} unknown", h.scalar_type));
    }
    if (h.kernel_kind != static_cast<std::uint8_t>(model::ImageKernel::squared_exponential_ard)) {
      problems.push_back(fmt::format("kernel kind {} unknown", h.kernel_kind));
    }
    if (!model::is_known(static_cast<model::InputEncoding>(h.input_encoding))) {
      problems.push_back(fmt::format("input encoding {} unknown", h.input_encoding));
    }
    set(check("kind"), problems.empty(),
        problems.empty() ? fmt::format("float32, squared exponential ARD, {}",
                                       model::to_string(static_cast<model::InputEncoding>(h.input_encoding)))
                         : join(problems));
  }

  {
    const model::ImageCapacity firmware{};
    const bool fits = h.training_points <= firmware.max_training_points && h.segment_count <= firmware.max_segments;
    set(check("capacity"), fits,
        fmt::format("{} training points (firmware limit {}), {} segment{} (limit {})", h.training_points,
                    firmware.max_training_points, h.segment_count, h.segment_count == 1 ? "" : "s",
                    firmware.max_segments));
  }

  // Blocks as the header places them, sized by its dims. 64-bit arithmetic:
  // the dims of a damaged header can be anything.
  const std::uint64_t n = h.training_points;
  const std::uint64_t d = h.input_dims;
  const std::uint64_t segments = h.segment_count;
  const std::uint64_t block_sizes[] = {12 * segments, 4 * (3 * d + 4 * model::kImageOutputs), 4 * n * d,
                                       4 * n * model::kImageOutputs, model::kImageMetadataSize};
  const char* block_names[] = {"geometry", "parameters", "inputs", "alpha", "metadata"};
  const auto inside = [size](std::uint64_t offset, std::uint64_t length) {
    return offset <= size && length <= size - offset;
  };
  r.blocks.push_back({"header", 0, model::kImageHeaderSize, true});
  for (int i = 0; i < 5; ++i) r.blocks.push_back({block_names[i], offsets[i], block_sizes[i], inside(offsets[i], block_sizes[i])});
  if (total_plausible) {
    r.blocks.push_back({"crc32", h.total_size - model::kImageTrailerSize, model::kImageTrailerSize,
                        inside(h.total_size - model::kImageTrailerSize, model::kImageTrailerSize)});
  }

  if (dims_consistent) {
    std::vector<std::string> problems;
    const std::uint64_t arrays = 4 * n * (d + model::kImageOutputs);
    if (arrays > h.total_size) {
      problems.push_back(fmt::format("{} training points need {} bytes of arrays, total_size is {}", n, arrays,
                                     h.total_size));
    } else {
      const model::ImageLayout expected = model::image_layout(h.training_points, h.input_dims, h.segment_count);
      const std::uint32_t expected_offsets[] = {expected.geometry_offset, expected.parameters_offset,
                                                expected.inputs_offset, expected.alpha_offset,
                                                expected.metadata_offset};
      if (h.total_size != expected.total_size) {
        problems.push_back(fmt::format("total_size {}, the dims imply {}", h.total_size, expected.total_size));
      }
      for (int i = 0; i < 5; ++i) {
        if (offsets[i] != expected_offsets[i]) {
          problems.push_back(fmt::format("{} {}, the dims imply {}", offset_names[i], offsets[i], expected_offsets[i]));
        }
      }
    }
    if (h.metadata_size != model::kImageMetadataSize) {
      problems.push_back(fmt::format("metadata_size {}, expected {}", h.metadata_size, model::kImageMetadataSize));
    }
    set(check("layout"), problems.empty(), problems.empty() ? "offsets and sizes match the dims" : join(problems));
  } else {
    check("layout").detail = "the dims are inconsistent";
  }

  // The payload, wherever it lies inside the file.
  if (inside(h.geometry_offset, block_sizes[0]) && segments > 0) {
    const std::vector<float> values = read_floats(bytes, h.geometry_offset, 3 * segments);
    std::vector<std::array<float, 3>> geometry(static_cast<std::size_t>(segments));
    for (std::size_t s = 0; s < geometry.size(); ++s) geometry[s] = {values[3 * s], values[3 * s + 1], values[3 * s + 2]};
    r.geometry = std::move(geometry);
  }
  if (inside(h.parameters_offset, block_sizes[1])) {
    const std::vector<float> values = read_floats(bytes, h.parameters_offset, block_sizes[1] / 4);
    const auto slice = [&values](std::uint64_t from, std::uint64_t count) {
      return std::vector<float>(values.begin() + static_cast<std::ptrdiff_t>(from),
                                values.begin() + static_cast<std::ptrdiff_t>(from + count));
    };
    ImageParameters p;
    p.input_mean = slice(0, d);
    p.input_scale = slice(d, d);
    p.length_scale = slice(2 * d, d);
    p.output_mean = slice(3 * d, 6);
    p.output_scale = slice(3 * d + 6, 6);
    p.signal_variance = slice(3 * d + 12, 6);
    p.noise_variance = slice(3 * d + 18, 6);
    r.parameters = std::move(p);
  }
  const auto max_abs = [bytes](std::uint64_t offset, std::uint64_t count) {
    float largest = 0.0f;
    for (std::uint64_t i = 0; i < count; ++i) {
      const float value = std::abs(read<float>(bytes, static_cast<std::size_t>(offset + 4 * i)));
      if (!(value <= largest)) largest = value;  // NaN sticks
    }
    return largest;
  };
  if (inside(h.inputs_offset, block_sizes[2]) && n * d > 0) r.max_abs_input = max_abs(h.inputs_offset, n * d);
  if (inside(h.alpha_offset, block_sizes[3]) && n > 0) r.max_abs_alpha = max_abs(h.alpha_offset, 6 * n);
  if (inside(h.metadata_offset, model::kImageMetadataSize)) {
    using namespace model::image_metadata_field;
    const std::uint8_t* m = bytes + h.metadata_offset;
    ImageMetadata meta;
    meta.dataset_hash = read<std::uint64_t>(m, dataset_hash);
    meta.created_unix_s = read<std::int64_t>(m, created_unix_s);
    meta.validation_samples = read<std::uint32_t>(m, validation_samples);
    std::memcpy(&meta.metrics, m + metrics, sizeof(model::ImageMetrics));
    meta.trainer = escaped_text(m + trainer, 32);
    r.metadata = std::move(meta);
  }

  // finite and positive, over the blocks that are inside the file.
  {
    const FloatBlock payload[] = {{"geometry", h.geometry_offset, 3 * segments},
                                  {"parameters", h.parameters_offset, block_sizes[1] / 4},
                                  {"inputs", h.inputs_offset, n * d},
                                  {"alpha", h.alpha_offset, 6 * n}};
    std::vector<std::string> missing;
    std::string first_non_finite;
    std::uint64_t checked = 0;
    for (const FloatBlock& block : payload) {
      if (!inside(block.offset, 4 * block.count)) {
        missing.push_back(block.name);
        continue;
      }
      for (std::uint64_t i = 0; i < block.count && first_non_finite.empty(); ++i) {
        const float value = read<float>(bytes, static_cast<std::size_t>(block.offset + 4 * i));
        if (!std::isfinite(value)) first_non_finite = fmt::format("{}[{}] is {}", block.name, i, value);
      }
      checked += block.count;
    }
    ImageCheck& finite = check("finite");
    if (!first_non_finite.empty()) {
      set(finite, false, first_non_finite);
    } else if (!missing.empty()) {
      finite.detail = fmt::format("{} values finite; not inside the file: {}", checked, join(missing, ", "));
    } else {
      set(finite, true, fmt::format("all {} payload values finite", checked));
    }
  }
  {
    std::vector<std::string> problems;
    std::vector<std::string> missing;
    if (r.geometry) {
      const char* fields[] = {"backbone_length_mm", "anchor_radius_mm", "theta_max_rad"};
      for (std::size_t s = 0; s < r.geometry->size(); ++s) {
        for (int k = 0; k < 3; ++k) {
          if (!((*r.geometry)[s][k] > 0.0f)) {
            problems.push_back(fmt::format("segment {} {} = {}", s + 1, fields[k], (*r.geometry)[s][k]));
          }
        }
      }
    } else {
      missing.push_back("geometry");
    }
    if (r.parameters) {
      const auto positive = [&problems](const char* name, const std::vector<float>& values) {
        for (std::size_t i = 0; i < values.size(); ++i) {
          if (!(values[i] > 0.0f)) problems.push_back(fmt::format("{}[{}] = {}", name, i, values[i]));
        }
      };
      positive("input_scale", r.parameters->input_scale);
      positive("length_scale", r.parameters->length_scale);
      positive("output_scale", r.parameters->output_scale);
      positive("signal_variance", r.parameters->signal_variance);
      positive("noise_variance", r.parameters->noise_variance);
    } else {
      missing.push_back("parameters");
    }
    ImageCheck& positive = check("positive");
    if (!problems.empty()) {
      if (problems.size() > 4) {
        const std::size_t more = problems.size() - 3;
        problems.resize(3);
        problems.push_back(fmt::format("{} more", more));
      }
      set(positive, false, join(problems));
    } else if (!missing.empty()) {
      positive.detail = fmt::format("not inside the file: {}", join(missing, ", "));
    } else {
      set(positive, true, "geometry, scales, length scales and variances are positive");
    }
  }

  // The parser has the last word; its failure is always shown as failed,
  // even if the evaluation above missed it.
  if (const char* name = check_for_status(r.status); name != nullptr) {
    ImageCheck& failed = check(name);
    if (failed.result != CheckResult::failed) {
      failed.result = CheckResult::failed;
      failed.detail += std::string(failed.detail.empty() ? "" : "; ") + kParserVerdict + model::to_string(r.status);
    }
  }
  return r;
}

}  // namespace cdcr::cli
