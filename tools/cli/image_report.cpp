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
    case ImageCheckId::cables:
      pass(r.cables ? fmt::format("{} segments: 3 or 4 cables each, angles finite, anchors that read a bend, the inputs "
                                  "and hysteresis cables they imply",
                                  r.cables->size())
                    : std::string("no cables block: four cables at 90 degrees a segment"));
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

// The header's fields, for display, from a file that holds the whole header.
// A field a version does not use reads as zero.
ImageHeaderFields read_header(const std::uint8_t* bytes) {
  namespace field = model::image_field;
  const auto value = [bytes](const model::ImageHeaderField& f) { return model::image_field_value(bytes, f); };
  ImageHeaderFields h;
  h.magic = value(field::magic);
  h.version_major = static_cast<std::uint16_t>(value(field::version_major));
  h.version_minor = static_cast<std::uint16_t>(value(field::version_minor));
  const auto used = [&h, &value](const model::ImageHeaderField& f) {
    return model::image_field_in_use(f, h.version_major, h.version_minor) ? value(f) : 0;
  };
  h.header_size = value(field::header_size);
  h.total_size = value(field::total_size);
  h.training_points = value(field::training_points);
  h.input_dims = static_cast<std::uint16_t>(value(field::input_dims));
  h.output_dims = static_cast<std::uint16_t>(value(field::output_dims));
  h.segment_count = static_cast<std::uint16_t>(value(field::segment_count));
  h.scalar_type = static_cast<std::uint8_t>(value(field::scalar_type));
  h.kernel_kind = static_cast<std::uint8_t>(value(field::kernel_kind));
  h.input_encoding = static_cast<std::uint8_t>(value(field::input_encoding));
  h.model_kind = static_cast<std::uint8_t>(value(field::model_kind));
  h.extra_inputs = static_cast<std::uint8_t>(value(field::extra_inputs));
  h.geometry_offset = value(field::geometry_offset);
  h.parameters_offset = value(field::parameters_offset);
  h.inputs_offset = value(field::inputs_offset);
  h.alpha_offset = value(field::alpha_offset);
  h.metadata_offset = value(field::metadata_offset);
  h.metadata_size = value(field::metadata_size);
  h.variance_offset = value(field::variance_offset);
  h.variance_rank = static_cast<std::uint16_t>(value(field::variance_rank));
  h.hysteresis_cables = static_cast<std::uint8_t>(used(field::hysteresis_cables));
  h.hysteresis_operators = static_cast<std::uint8_t>(used(field::hysteresis_operators));
  h.compliance_segments = static_cast<std::uint8_t>(used(field::compliance_segments));
  return h;
}

// The dims a damaged header declares, as the layout reads them.
model::ImageDims declared_dims(const ImageHeaderFields& h) {
  const bool v1 = h.version_major == 1;
  model::ImageDims dims{h.training_points, h.input_dims, h.segment_count, h.version_major};
  dims.extra_inputs = v1 ? 0 : h.extra_inputs;
  dims.hysteresis_floats = model::image_hysteresis_floats(h.hysteresis_cables, h.hysteresis_operators);
  dims.compliance_floats = model::image_compliance_floats(h.compliance_segments);
  dims.cables_floats =
      model::image_has_cables_block(h.version_major, h.version_minor) ? model::image_cables_floats(h.segment_count) : 0;
  return dims;
}

bool inside(std::size_t size, std::uint64_t offset, std::uint64_t length) {
  return offset <= size && length <= size - offset;
}

// The blocks as the header places them, sized by its dims (64-bit: the dims
// of a damaged header can be anything), and the hysteresis and compliance
// blocks' values where they lie inside the file.
void read_blocks(ImageReport& r, const std::uint8_t* bytes, std::size_t size) {
  const ImageHeaderFields& h = *r.header;
  const model::ImageDims dims = declared_dims(h);
  r.blocks.push_back({"header", 0, model::kImageHeaderSize, true});
  for (const model::ImageBlockFormat& block : model::kImageBlocks) {
    if (block.only_when_counted) continue;
    const std::uint64_t offset = model::image_field_value(bytes, *model::image_block_offset_field(block.id));
    const std::uint64_t length = model::image_block_bytes(block.id, dims);
    r.blocks.push_back({block.name, offset, length, inside(size, offset, length)});
  }
  const auto span = [](std::uint64_t bytes_of_block) {
    return (bytes_of_block + model::kImageBlockAlignment - 1) / model::kImageBlockAlignment *
           model::kImageBlockAlignment;
  };
  // The cables block (v2.7) lies just before the metadata.
  const std::uint64_t cables_bytes = model::image_block_bytes(model::ImageBlockId::cables, dims);
  const std::uint64_t cables_span = span(cables_bytes);
  const std::uint64_t cables_at = cables_bytes > 0 && h.metadata_offset >= cables_span
                                      ? h.metadata_offset - cables_span
                                      : h.metadata_offset;
  if (cables_at != h.metadata_offset) {
    const bool readable = inside(size, cables_at, cables_bytes);
    r.blocks.insert(r.blocks.end() - 1, {"cables", cables_at, cables_bytes, readable});
    if (readable) {
      const std::vector<float> values = read_floats(bytes, cables_at, cables_bytes / 4);
      std::vector<ImageSegmentCables> segments(h.segment_count);
      for (std::size_t i = 0; i < segments.size(); ++i) {
        const float* segment = values.data() + i * model::image_cables_field::per_segment;
        segments[i].count = segment[model::image_cables_field::count];
        std::copy(segment + model::image_cables_field::angles, segment + model::image_cables_field::per_segment,
                  segments[i].angles_rad.begin());
      }
      r.cables = std::move(segments);
    }
  }
  // The compliance block (v2.3) lies before it.
  const std::uint64_t compliance_bytes = model::image_block_bytes(model::ImageBlockId::compliance, dims);
  const std::uint64_t compliance_span = span(compliance_bytes);
  if (compliance_bytes > 0 && cables_at >= compliance_span) {
    const std::uint64_t at = cables_at - compliance_span;
    const bool readable = inside(size, at, compliance_bytes);
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
  const std::uint64_t hysteresis_bytes = model::image_block_bytes(model::ImageBlockId::hysteresis, dims);
  const std::uint64_t hysteresis_span = span(hysteresis_bytes);
  const std::uint64_t hysteresis_end =
      compliance_bytes > 0 && cables_at >= compliance_span ? cables_at - compliance_span : cables_at;
  if (hysteresis_bytes > 0 && hysteresis_end >= hysteresis_span) {
    const std::uint64_t at = hysteresis_end - hysteresis_span;
    const bool readable = inside(size, at, hysteresis_bytes);
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
                        inside(size, h.total_size - model::kImageTrailerSize, model::kImageTrailerSize)});
  }
}

ImageParameters read_parameters(const std::uint8_t* bytes, const ImageHeaderFields& h, std::uint64_t count) {
  const bool v1 = h.version_major == 1;
  const std::uint64_t d = h.input_dims;
  const std::vector<float> values = read_floats(bytes, h.parameters_offset, count);
  const auto slice = [&values](std::uint64_t from, std::uint64_t length) {
    return std::vector<float>(values.begin() + static_cast<std::ptrdiff_t>(from),
                              values.begin() + static_cast<std::ptrdiff_t>(from + length));
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
    p.extra_input_default = slice(5 * d + 24, h.extra_inputs);
  }
  return p;
}

ImageMetadata read_metadata(const std::uint8_t* m) {
  using namespace model::image_metadata_field;
  ImageMetadata meta;
  meta.dataset_hash = read<std::uint64_t>(m, dataset_hash);
  meta.created_unix_s = read<std::int64_t>(m, created_unix_s);
  meta.validation_samples = read<std::uint32_t>(m, validation_samples);
  meta.fitted_rows = read<std::uint32_t>(m, fitted_rows);
  std::memcpy(&meta.metrics, m + metrics, sizeof(model::ImageMetrics));
  meta.trainer = escaped_text(m + trainer, 32);
  return meta;
}

// The geometry, parameters and metadata, and the largest inputs and weights,
// where they lie inside the file.
void read_payload(ImageReport& r, const std::uint8_t* bytes, std::size_t size) {
  const ImageHeaderFields& h = *r.header;
  const bool v1 = h.version_major == 1;
  const model::ImageDims dims = declared_dims(h);
  const std::uint64_t n = h.training_points;
  const std::uint64_t d = h.input_dims;
  const std::uint64_t segments = h.segment_count;
  const auto block_inside = [&](model::ImageBlockId block, std::uint64_t offset) {
    return inside(size, offset, model::image_block_bytes(block, dims));
  };
  if (block_inside(model::ImageBlockId::geometry, h.geometry_offset) && segments > 0) {
    const std::vector<float> values = read_floats(bytes, h.geometry_offset, 3 * segments);
    std::vector<std::array<float, 3>> geometry(static_cast<std::size_t>(segments));
    for (std::size_t s = 0; s < geometry.size(); ++s) geometry[s] = {values[3 * s], values[3 * s + 1], values[3 * s + 2]};
    r.geometry = std::move(geometry);
  }
  if (block_inside(model::ImageBlockId::parameters, h.parameters_offset)) {
    r.parameters = read_parameters(bytes, h, model::image_block_bytes(model::ImageBlockId::parameters, dims) / 4);
  }
  const auto max_abs = [bytes](std::uint64_t offset, std::uint64_t count) {
    float largest = 0.0f;
    for (std::uint64_t i = 0; i < count; ++i) {
      const float value = std::abs(read<float>(bytes, static_cast<std::size_t>(offset + 4 * i)));
      if (!(value <= largest)) largest = value;  // NaN sticks
    }
    return largest;
  };
  if (block_inside(model::ImageBlockId::inputs, h.inputs_offset) && n * d > 0) {
    r.max_abs_input = max_abs(h.inputs_offset, n * d);
  }
  if (block_inside(model::ImageBlockId::alpha, h.alpha_offset) && n > 0) {
    r.max_abs_alpha = max_abs(h.alpha_offset, 6 * n);
  }
  if (block_inside(model::ImageBlockId::metadata, h.metadata_offset)) {
    r.metadata = read_metadata(bytes + h.metadata_offset);
    if (!v1) r.fitted_rows = r.metadata->fitted_rows;
  }
  if (v1) r.fitted_rows = h.training_points;
}

// The checks, in the parser's order, in words.
std::vector<ImageCheck> describe_checks(const Findings& findings, const ImageReport& r) {
  std::vector<ImageCheck> checks;
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
    checks.push_back(std::move(check));
  }
  return checks;
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
  namespace field = model::image_field;
  ImageReport r;
  r.file_size = size;
  Findings findings;
  {
    model::ImageView view{};
    r.status = model::parse_image(bytes, size, view, model::ImageCapacity{}, &findings);
  }
  r.first_failure = findings.first_failure();

  // The fields, for display: whatever of them lies inside the file.
  if (size >= field::magic.offset + field::magic.size()) r.magic = model::image_field_value(bytes, field::magic);
  if (size >= field::version_major.offset + field::version_major.size()) {
    r.version_major = static_cast<std::uint16_t>(model::image_field_value(bytes, field::version_major));
  }
  if (size >= model::kImageHeaderSize) r.header = read_header(bytes);
  if (const ImageFinding* f = findings.find(ImageCheckId::size, "total_size"); f != nullptr && f->passed) {
    r.trailing_bytes = size - r.header->total_size;
  }
  if (const ImageFinding* f = findings.find(ImageCheckId::checksum, "crc32"); f != nullptr) {
    r.stored_crc = static_cast<std::uint32_t>(f->value);
    r.computed_crc = static_cast<std::uint32_t>(f->expected);
  }
  if (r.header) {
    read_blocks(r, bytes, size);
    read_payload(r, bytes, size);
  }
  r.checks = describe_checks(findings, r);
  return r;
}

}  // namespace cdcr::cli
