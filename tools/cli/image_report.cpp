#include "image_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <initializer_list>
#include <utility>

#include <fmt/format.h>

#include "cdcr/model/input_encoding.hpp"
#include "cdcr/model/limits.hpp"

namespace cdcr::cli {

namespace {

using model::ImageCheckId;
using model::ImageExpectation;
using model::ImageFinding;
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

std::string join(const std::vector<std::string>& parts, const char* separator = "; ") {
  std::string out;
  for (const std::string& part : parts) {
    if (!out.empty()) out += separator;
    out += part;
  }
  return out;
}

// Failures kept per check: a damaged header can declare a payload of
// millions of bad values.
constexpr std::size_t kKeptFailuresPerCheck = 16;
// Failures a check's detail lists before it counts the rest.
constexpr std::size_t kListedFailures = 3;

// Collects the parser's findings in its order.
class Findings final : public model::ImageCheckSink {
 public:
  void on_finding(const ImageFinding& finding) override {
    auto& per_check = by_check_[static_cast<std::size_t>(finding.check)];
    if (!finding.passed) {
      if (!first_failure_) first_failure_ = finding.check;
      per_check.failures += 1;
      if (per_check.failures > kKeptFailuresPerCheck) return;
    }
    per_check.kept.push_back(finding);
  }

  struct PerCheck {
    std::vector<ImageFinding> kept;  // the passes and the first failures
    std::size_t failures = 0;
  };
  const PerCheck& of(ImageCheckId check) const { return by_check_[static_cast<std::size_t>(check)]; }
  std::optional<ImageCheckId> first_failure() const { return first_failure_; }

  const ImageFinding* find(ImageCheckId check, const char* field) const {
    for (const ImageFinding& f : of(check).kept) {
      if (std::strcmp(f.field, field) == 0) return &f;
    }
    return nullptr;
  }

 private:
  std::array<PerCheck, model::kImageCheckCount> by_check_;
  std::optional<ImageCheckId> first_failure_;
};

// Header fields are integers; payload values are floats, shown as the
// shortest decimal that reads back as the same float.
std::string number(double value) {
  if (std::isfinite(value) && value == std::floor(value) && std::abs(value) < 1e18) {
    return fmt::format("{}", static_cast<long long>(value));
  }
  return fmt::format("{}", static_cast<float>(value));
}

std::string subject(const ImageFinding& f) {
  return f.index >= 0 ? fmt::format("{}[{}]", f.field, f.index) : std::string(f.field);
}

// One finding in words. Most follow from the expectation; a few fields read
// better in their own terms.
std::string describe(const ImageFinding& f) {
  const std::string field = f.field;
  const std::string value = number(f.value);
  const std::string expected = number(f.expected);
  switch (f.check) {
    case ImageCheckId::size:
      if (field == "file_size") return fmt::format("{} bytes, fewer than the {}-byte header", value, expected);
      return fmt::format("file {} bytes, fewer than total_size {}", expected, value);
    case ImageCheckId::magic: {
      const std::string text = magic_text(static_cast<std::uint32_t>(f.value));
      return f.passed ? text : text + ", expected 'CDGP'";
    }
    case ImageCheckId::version:
      return fmt::format("major version {}{}", value, f.passed ? "" : ", this parser reads 1 and 2");
    case ImageCheckId::checksum:
      return fmt::format("stored 0x{:08x}, computed 0x{:08x}", static_cast<std::uint32_t>(f.value),
                         static_cast<std::uint32_t>(f.expected));
    case ImageCheckId::header:
      if (field == "reserved") return fmt::format("reserved byte {} is non-zero", f.index);
      if (field == "total_size") return fmt::format("total_size {} cannot hold header and trailer", value);
      if (field == "training_points" && f.value == 0) return "no training points";
      if (field == "segment_count" && f.value == 0) return "no segments";
      if (field == "variance_offset" || field == "variance_rank") {
        return fmt::format("{} {}, v2.0 defines no variance factor (must be 0)", field, value);
      }
      break;
    case ImageCheckId::alignment:
      if (field == "buffer_address") {
        return fmt::format("buffer address 0x{:x} is not a multiple of {}", static_cast<std::uint64_t>(f.value),
                           expected);
      }
      break;
    case ImageCheckId::layout:
      if (f.expectation == ImageExpectation::at_least) {
        return fmt::format("the arrays the dims declare need {} bytes, total_size is {}", expected, value);
      }
      if (field != "metadata_size") return fmt::format("{} {}, the dims imply {}", field, value, expected);
      break;
    case ImageCheckId::positive:
      if (field == "geometry" && f.index >= 0) {
        const char* names[] = {"backbone_length_mm", "anchor_radius_mm", "theta_max_rad"};
        return fmt::format("segment {} {} = {}", f.index / 3 + 1, names[f.index % 3], value);
      }
      break;
    case ImageCheckId::ranges:
      return fmt::format("input_min[{0}] {1} > input_max[{0}] {2}", f.index, value, expected);
    default:
      break;
  }
  switch (f.expectation) {
    case ImageExpectation::equal: return fmt::format("{} {}, expected {}", subject(f), value, expected);
    case ImageExpectation::at_least: return fmt::format("{} {}, expected at least {}", subject(f), value, expected);
    case ImageExpectation::at_most: return fmt::format("{} {}, expected at most {}", subject(f), value, expected);
    case ImageExpectation::multiple_of:
      return fmt::format("{} {} is not a multiple of {}", subject(f), value, expected);
    case ImageExpectation::known: return fmt::format("{} {} unknown", subject(f), value);
    case ImageExpectation::finite: return fmt::format("{} is {}", subject(f), value);
    case ImageExpectation::positive: return fmt::format("{} = {}", subject(f), value);
  }
  return subject(f);
}

std::string failures_text(const Findings::PerCheck& findings) {
  // Listing one more failure reads better than "1 more".
  const std::size_t listed = findings.failures > kListedFailures + 1 ? kListedFailures : findings.failures;
  std::vector<std::string> parts;
  for (const ImageFinding& f : findings.kept) {
    if (!f.passed && parts.size() < listed) parts.push_back(describe(f));
  }
  if (parts.size() < findings.failures) parts.push_back(fmt::format("{} more", findings.failures - parts.size()));
  return join(parts);
}

// The payload arrays a check reads, and the ones the parser could not read
// (their block is not inside the file): no finding names them.
std::vector<std::string> unread(const Findings& findings, ImageCheckId check,
                                std::initializer_list<std::pair<const char*, const char*>> field_and_block) {
  std::vector<std::string> missing;
  for (const auto& [field, block] : field_and_block) {
    if (findings.find(check, field) == nullptr) missing.push_back(block);
  }
  return missing;
}

// What a check that passed, or was not evaluated, says: display only.
void describe_unfailed(ImageCheck& check, const Findings& findings, const ImageReport& r) {
  const auto& kept = findings.of(check.id).kept;
  const auto values = [&kept] {
    std::uint64_t count = 0;
    for (const ImageFinding& f : kept) count += f.count;
    return count;
  };
  const auto pass = [&check](std::string detail) {
    check.result = CheckResult::passed;
    check.detail = std::move(detail);
  };
  const bool v1 = r.version_major && *r.version_major == 1;

  if (!r.header) {
    if (kept.empty()) {
      check.detail = "the header is incomplete";
    } else {
      pass(describe(kept.front()));
    }
    return;
  }
  const ImageHeaderFields& h = *r.header;
  switch (check.id) {
    case ImageCheckId::finite: {
      const std::vector<std::string> missing = unread(
          findings, check.id,
          {{"geometry", "geometry"}, {"parameters", "parameters"}, {"inputs", "inputs"}, {"alpha", "alpha"}});
      if (missing.empty()) {
        pass(fmt::format("all {} payload values finite", values()));
      } else {
        check.detail = fmt::format("{} values finite; not read: {}", values(), join(missing, ", "));
      }
      return;
    }
    case ImageCheckId::positive: {
      const std::vector<std::string> missing =
          unread(findings, check.id, {{"geometry", "geometry"}, {"input_scale", "parameters"}});
      if (missing.empty()) {
        pass("geometry, scales, length scales and variances are positive");
      } else {
        check.detail = fmt::format("not read: {}", join(missing, ", "));
      }
      return;
    }
    default:
      break;
  }
  if (kept.empty()) {
    if (check.id == ImageCheckId::ranges && v1) {
      check.detail = "a v1 image holds no input ranges";
    } else if (check.id == ImageCheckId::fitted_rows && v1) {
      check.detail = "a v1 image holds no fitted_rows: it was fitted on its training points";
    } else {
      check.detail = "not evaluated: what it reads is not inside the file, or not where it can be read";
    }
    return;
  }
  switch (check.id) {
    case ImageCheckId::size:
      if (r.trailing_bytes) {
        pass(fmt::format("file {} bytes, image {} bytes, {} trailing", r.file_size, h.total_size, *r.trailing_bytes));
      } else {
        check.detail = fmt::format("file {} bytes; total_size {} is not a size", r.file_size, h.total_size);
      }
      return;
    case ImageCheckId::header: pass("consistent"); return;
    case ImageCheckId::alignment: pass("buffer and block offsets aligned; offsets are multiples of 8"); return;
    case ImageCheckId::kind:
      pass(fmt::format("float32, squared exponential ARD, {}{}",
                       model::to_string(static_cast<model::InputEncoding>(h.input_encoding)),
                       v1 ? "" : fmt::format(", {}, no extra inputs",
                                             model::to_string(static_cast<model::ImageModelKind>(h.model_kind)))));
      return;
    case ImageCheckId::layout: pass("offsets and sizes match the dims"); return;
    case ImageCheckId::ranges: pass(fmt::format("input_min <= input_max for all {} inputs", values())); return;
    case ImageCheckId::variance:
      pass(h.variance_rank == 0
               ? std::string("no variance block")
               : fmt::format("{} variance points, positive factor diagonals, one kernel for every output",
                             h.variance_rank));
      return;
    case ImageCheckId::hysteresis:
      if (!r.hysteresis) {
        pass("no hysteresis block");
      } else {
        const ImageHysteresis& b = *r.hysteresis;
        pass(fmt::format("{} cables x {} play operators: widths within [0, {}] mm, weights >= 0 summing to at most "
                         "1 per cable, homing lags within +-width",
                         b.cables, b.operators, model::kMaxHysteresisWidthMm));
      }
      return;
    case ImageCheckId::compliance:
      if (!r.compliance) {
        pass("no compliance block");
      } else {
        pass(fmt::format("{} segments: finite, ratios > 0, unloaded mass >= 0, softening keeping the compliance "
                         "positive to a quarter turn, payload input present",
                         r.compliance->ratios.size()));
      }
      return;
    case ImageCheckId::fitted_rows:
      if (r.fitted_rows && *r.fitted_rows == h.training_points) {
        pass(fmt::format("{} rows, the training points", *r.fitted_rows));
      } else {
        pass(fmt::format("{} data rows behind {} points", r.fitted_rows.value_or(0), h.training_points));
      }
      return;
    default:
      pass(describe(kept.front()));
      return;
  }
}

// capacity reads the same whether it passes or fails.
std::string capacity_text(const Findings& findings) {
  const ImageFinding* points = findings.find(ImageCheckId::capacity, "training_points");
  const ImageFinding* segments = findings.find(ImageCheckId::capacity, "segment_count");
  if (points == nullptr || segments == nullptr) return {};
  return fmt::format("{} training points (firmware limit {}), {} segment{} (limit {})", number(points->value),
                     number(points->expected), number(segments->value), segments->value == 1 ? "" : "s",
                     number(segments->expected));
}

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

const ImageCheck* ImageReport::failed_check() const {
  if (!first_failure) return nullptr;
  for (const ImageCheck& check : checks) {
    if (check.id == *first_failure) return &check;
  }
  return nullptr;
}

ImageReport inspect_image(const std::uint8_t* bytes, std::size_t size) {
  using namespace model::image_field;
  ImageReport r;
  r.file_size = size;
  Findings findings;
  {
    model::ImageView view{};
    r.status = model::parse_image(bytes, size, view, model::ImageCapacity{}, &findings);
  }
  r.first_failure = findings.first_failure();

  // The fields, for display: whatever of them lies inside the file.
  if (size >= 4) r.magic = read<std::uint32_t>(bytes, magic.offset);
  if (size >= 6) r.version_major = read<std::uint16_t>(bytes, version_major.offset);
  if (size >= model::kImageHeaderSize) {
    ImageHeaderFields h;
    h.magic = *r.magic;
    h.version_major = *r.version_major;
    h.version_minor = read<std::uint16_t>(bytes, version_minor.offset);
    h.header_size = read<std::uint32_t>(bytes, header_size.offset);
    h.total_size = read<std::uint32_t>(bytes, total_size.offset);
    h.training_points = read<std::uint32_t>(bytes, training_points.offset);
    h.input_dims = read<std::uint16_t>(bytes, input_dims.offset);
    h.output_dims = read<std::uint16_t>(bytes, output_dims.offset);
    h.segment_count = read<std::uint16_t>(bytes, segment_count.offset);
    h.scalar_type = bytes[scalar_type.offset];
    h.kernel_kind = bytes[kernel_kind.offset];
    h.input_encoding = bytes[input_encoding.offset];
    h.model_kind = bytes[model_kind.offset];
    h.extra_inputs = bytes[extra_inputs.offset];
    h.geometry_offset = read<std::uint32_t>(bytes, geometry_offset.offset);
    h.parameters_offset = read<std::uint32_t>(bytes, parameters_offset.offset);
    h.inputs_offset = read<std::uint32_t>(bytes, inputs_offset.offset);
    h.alpha_offset = read<std::uint32_t>(bytes, alpha_offset.offset);
    h.metadata_offset = read<std::uint32_t>(bytes, metadata_offset.offset);
    h.metadata_size = read<std::uint32_t>(bytes, metadata_size.offset);
    h.variance_offset = read<std::uint32_t>(bytes, variance_offset.offset);
    h.variance_rank = read<std::uint16_t>(bytes, variance_rank.offset);
    if (h.version_major >= 2 && h.version_minor >= model::kImageVersionMinorHysteresis) {
      h.hysteresis_cables = bytes[hysteresis_cables.offset];
      h.hysteresis_operators = bytes[hysteresis_operators.offset];
    }
    if (h.version_major >= 2 && h.version_minor >= model::kImageVersionMinorCompliance) {
      h.compliance_segments = bytes[compliance_segments.offset];
    }
    r.header = h;
  }
  if (const ImageFinding* f = findings.find(ImageCheckId::size, "total_size"); f != nullptr && f->passed) {
    r.trailing_bytes = size - r.header->total_size;
  }
  if (const ImageFinding* f = findings.find(ImageCheckId::checksum, "crc32"); f != nullptr) {
    r.stored_crc = static_cast<std::uint32_t>(f->value);
    r.computed_crc = static_cast<std::uint32_t>(f->expected);
  }

  if (r.header) {
    const ImageHeaderFields& h = *r.header;
    const bool v1 = h.version_major == 1;
    // Blocks as the header places them, sized by its dims. 64-bit
    // arithmetic: the dims of a damaged header can be anything.
    const std::uint64_t n = h.training_points;
    const std::uint64_t d = h.input_dims;
    const std::uint64_t segments = h.segment_count;
    const std::uint64_t extra = v1 ? 0 : h.extra_inputs;
    const std::uint64_t parameter_floats = model::image_parameter_floats(
        static_cast<std::uint32_t>(d), h.version_major, static_cast<std::uint32_t>(extra));
    const std::uint64_t offsets[] = {h.geometry_offset, h.parameters_offset, h.inputs_offset, h.alpha_offset,
                                     h.metadata_offset};
    const std::uint64_t block_sizes[] = {12 * segments, 4 * parameter_floats, 4 * n * d, 4 * n * model::kImageOutputs,
                                         model::kImageMetadataSize};
    const char* block_names[] = {"geometry", "parameters", "inputs", "alpha", "metadata"};
    const auto inside = [size](std::uint64_t offset, std::uint64_t length) {
      return offset <= size && length <= size - offset;
    };
    r.blocks.push_back({"header", 0, model::kImageHeaderSize, true});
    for (int i = 0; i < 5; ++i) {
      r.blocks.push_back({block_names[i], offsets[i], block_sizes[i], inside(offsets[i], block_sizes[i])});
    }
    const auto span = [](std::uint64_t bytes_of_block) {
      return (bytes_of_block + model::kImageBlockAlignment - 1) / model::kImageBlockAlignment *
             model::kImageBlockAlignment;
    };
    // The compliance block (v2.3) lies just before the metadata.
    const std::uint64_t compliance_bytes = 4 * std::uint64_t{model::image_compliance_floats(h.compliance_segments)};
    const std::uint64_t compliance_span = span(compliance_bytes);
    if (compliance_bytes > 0 && h.metadata_offset >= compliance_span) {
      const std::uint64_t at = h.metadata_offset - compliance_span;
      const bool readable = inside(at, compliance_bytes);
      r.blocks.insert(r.blocks.end() - 1, {"compliance", at, compliance_bytes, readable});
      if (readable) {
        const std::vector<float> values = read_floats(bytes, at, compliance_bytes / 4);
        ImageCompliance block;
        std::copy(values.begin(), values.begin() + 3, block.weighted_gravity.begin());
        block.ratios.assign(values.begin() + model::image_compliance_field::ratios,
                            values.begin() + model::image_compliance_field::ratios + h.compliance_segments);
        block.softening_per_rad = values[values.size() - 2];
        block.unloaded_mass_kg = values[values.size() - 1];
        r.compliance = std::move(block);
      }
    }
    // The hysteresis block (v2.2) lies before them.
    const std::uint64_t hysteresis_bytes =
        4 * std::uint64_t{model::image_hysteresis_floats(h.hysteresis_cables, h.hysteresis_operators)};
    const std::uint64_t hysteresis_span = span(hysteresis_bytes);
    const std::uint64_t hysteresis_end = compliance_bytes > 0 && h.metadata_offset >= compliance_span
                                             ? h.metadata_offset - compliance_span
                                             : h.metadata_offset;
    if (hysteresis_bytes > 0 && hysteresis_end >= hysteresis_span) {
      const std::uint64_t at = hysteresis_end - hysteresis_span;
      const bool readable = inside(at, hysteresis_bytes);
      r.blocks.insert(r.blocks.end() - 1, {"hysteresis", at, hysteresis_bytes, readable});
      if (readable) {
        const std::uint64_t count = std::uint64_t{h.hysteresis_cables} * h.hysteresis_operators;
        ImageHysteresis block;
        block.cables = h.hysteresis_cables;
        block.operators = h.hysteresis_operators;
        block.widths_mm = read_floats(bytes, at, count);
        block.weights = read_floats(bytes, at + 4 * count, count);
        block.homing_lags_mm = read_floats(bytes, at + 8 * count, count);
        r.hysteresis = std::move(block);
      }
    }
    if (h.total_size >= model::kImageTrailerSize) {
      r.blocks.push_back({"crc32", h.total_size - model::kImageTrailerSize, model::kImageTrailerSize,
                          inside(h.total_size - model::kImageTrailerSize, model::kImageTrailerSize)});
    }

    if (inside(h.geometry_offset, block_sizes[0]) && segments > 0) {
      const std::vector<float> values = read_floats(bytes, h.geometry_offset, 3 * segments);
      std::vector<std::array<float, 3>> geometry(static_cast<std::size_t>(segments));
      for (std::size_t s = 0; s < geometry.size(); ++s) geometry[s] = {values[3 * s], values[3 * s + 1], values[3 * s + 2]};
      r.geometry = std::move(geometry);
    }
    if (inside(h.parameters_offset, block_sizes[1])) {
      const std::vector<float> values = read_floats(bytes, h.parameters_offset, parameter_floats);
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
      if (!v1) {
        p.input_min = slice(3 * d + 24, d);
        p.input_max = slice(4 * d + 24, d);
        p.extra_input_default = slice(5 * d + 24, extra);
      }
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
      meta.fitted_rows = read<std::uint32_t>(m, fitted_rows);
      std::memcpy(&meta.metrics, m + metrics, sizeof(model::ImageMetrics));
      meta.trainer = escaped_text(m + trainer, 32);
      r.metadata = std::move(meta);
      if (!v1) r.fitted_rows = r.metadata->fitted_rows;
    }
    if (v1) r.fitted_rows = h.training_points;
  }

  // The checks, in the parser's order, in words.
  for (int c = 0; c < model::kImageCheckCount; ++c) {
    const auto id = static_cast<ImageCheckId>(c);
    ImageCheck check{id, model::to_string(id), CheckResult::not_checked, {}};
    const Findings::PerCheck& per_check = findings.of(id);
    if (per_check.failures > 0) {
      check.result = CheckResult::failed;
      check.detail = failures_text(per_check);
    } else {
      describe_unfailed(check, findings, r);
    }
    if (id == ImageCheckId::capacity && !per_check.kept.empty()) check.detail = capacity_text(findings);
    r.checks.push_back(std::move(check));
  }
  return r;
}

}  // namespace cdcr::cli
