#include "inspect_command.hpp"

#include <cmath>
#include <cstdlib>
#include <ctime>
#include <memory>
#include <optional>
#include <stdexcept>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "cli_errors.hpp"
#include "export/binary_file.hpp"
#include "image_report.hpp"
#include "json_output.hpp"

namespace cdcr::cli {
namespace {

constexpr const char* kOutputNames[] = {"v_x", "v_y", "v_z", "omega_x", "omega_y", "omega_z"};
constexpr const char* kOutputUnits[] = {"mm", "mm", "mm", "rad", "rad", "rad"};
// Rows beyond this are summarised: only a damaged header declares more.
constexpr std::size_t kMaxListedRows = 2 * model::kMaxSegments;

std::optional<std::string> iso8601_utc(std::int64_t unix_s) {
  const auto seconds = static_cast<std::time_t>(unix_s);
  if (static_cast<std::int64_t>(seconds) != unix_s) return std::nullopt;
  std::tm utc{};
  if (gmtime_r(&seconds, &utc) == nullptr) return std::nullopt;
  return fmt::format("{:04}-{:02}-{:02}T{:02}:{:02}:{:02}Z", utc.tm_year + 1900LL, utc.tm_mon + 1, utc.tm_mday,
                     utc.tm_hour, utc.tm_min, utc.tm_sec);
}

const char* scalar_name(std::uint8_t code) {
  return code == static_cast<std::uint8_t>(model::ImageScalar::float32) ? "float32" : nullptr;
}
const char* kernel_name(std::uint8_t code) {
  return code == static_cast<std::uint8_t>(model::ImageKernel::squared_exponential_ard) ? "squared-exponential-ard"
                                                                                        : nullptr;
}
const char* encoding_name(std::uint8_t code) {
  const auto encoding = static_cast<model::InputEncoding>(code);
  return model::is_known(encoding) ? model::to_string(encoding) : nullptr;
}
const char* model_kind_name(std::uint8_t code) {
  const auto kind = static_cast<model::ImageModelKind>(code);
  return model::is_known(kind) ? model::to_string(kind) : nullptr;
}

// A v1 header has no model kind: its byte is reserved and the model exact.
bool is_v1(const ImageHeaderFields& h) { return h.version_major == 1; }
std::uint8_t model_kind_code(const ImageHeaderFields& h) {
  return is_v1(h) ? static_cast<std::uint8_t>(model::ImageModelKind::exact_gp) : h.model_kind;
}
bool is_sparse(const ImageHeaderFields& h) {
  return model_kind_code(h) == static_cast<std::uint8_t>(model::ImageModelKind::sparse_gp);
}

std::string input_name(const ImageHeaderFields& h, std::size_t dim) {
  const std::uint8_t encoding = h.input_encoding;
  if (dim >= std::size_t{2} * h.segment_count) return "payload (kg)";
  const std::size_t segment = dim / 2 + 1;
  if (encoding == static_cast<std::uint8_t>(model::InputEncoding::joint_angles)) {
    return fmt::format("{}_{} (rad)", dim % 2 == 0 ? "alpha" : "theta", segment);
  }
  return fmt::format("b{}_{} (rad)", segment, dim % 2 == 0 ? "x" : "y");
}

const char* result_text(CheckResult result) {
  switch (result) {
    case CheckResult::passed: return "pass";
    case CheckResult::failed: return "FAIL";
    case CheckResult::not_checked: return "not checked";
  }
  return "";
}

std::string hex32(std::uint32_t value) { return fmt::format("0x{:08x}", value); }

std::string verdict(const ImageReport& r) {
  if (r.valid()) return "valid";
  const ImageCheck* failed = r.failed_check();
  return fmt::format("invalid: {} check failed ({}: {})", failed != nullptr ? failed->name : "?",
                     image_status_name(r.status), model::to_string(r.status));
}

// --- text ----------------------------------------------------------------------

// One "label value" line of the text report.
void add_row(std::string& t, const char* label, const std::string& value) {
  t += fmt::format("  {:<20}{}\n", label, value);
}

void add_header_text(std::string& t, const ImageReport& r) {
  const auto row = [&t](const char* label, const std::string& value) { add_row(t, label, value); };

  t += "header\n";
  if (r.magic) row("magic", fmt::format("0x{:08x}{}", *r.magic, *r.magic == model::kImageMagic ? " (CDGP)" : ""));
  if (r.header) {
    const ImageHeaderFields& h = *r.header;
    row("version", fmt::format("{}.{}", h.version_major, h.version_minor));
    row("header size", fmt::format("{} bytes", h.header_size));
    row("total size", fmt::format("{} bytes", h.total_size));
    if (r.trailing_bytes) row("trailing bytes", fmt::format("{} (in the file after total_size, not part of the image)", *r.trailing_bytes));
    if (r.stored_crc) row("crc32", fmt::format("stored {}, computed {}", hex32(*r.stored_crc), hex32(*r.computed_crc)));

    if (!is_v1(h)) {
      row("variance factor", h.variance_offset == 0 && h.variance_rank == 0
                                 ? std::string("none")
                                 : fmt::format("offset {}, rank {}", h.variance_offset, h.variance_rank));
      if (h.hysteresis_cables != 0 || h.hysteresis_operators != 0) {
        row("hysteresis", fmt::format("{} cables, {} operators each", h.hysteresis_cables, h.hysteresis_operators));
      }
      if (h.compliance_segments != 0) row("compliance", fmt::format("{} segments", h.compliance_segments));
    }

    t += "dims\n";
    // The points are the training inputs of an exact model, the inducing
    // inputs of a sparse one.
    row(is_sparse(h) ? "inducing points" : "training points", fmt::format("{}", h.training_points));
    if (r.fitted_rows) {
      row("fitted rows", fmt::format("{}{}", *r.fitted_rows, is_v1(h) ? " (v1: the training points)" : ""));
    }
    row("input dims", fmt::format("{}", h.input_dims));
    if (!is_v1(h)) row("extra inputs", fmt::format("{}", h.extra_inputs));
    row("output dims", fmt::format("{}", h.output_dims));
    row("segments", fmt::format("{}", h.segment_count));

    const auto named = [](std::uint8_t code, const char* name) {
      return fmt::format("{} ({})", code, name != nullptr ? name : "unknown");
    };
    t += "kind\n";
    row("model kind", named(model_kind_code(h), model_kind_name(model_kind_code(h))));
    row("scalar type", named(h.scalar_type, scalar_name(h.scalar_type)));
    row("kernel", named(h.kernel_kind, kernel_name(h.kernel_kind)));
    row("input encoding", named(h.input_encoding, encoding_name(h.input_encoding)));
  } else if (r.version_major) {
    row("version major", fmt::format("{}", *r.version_major));
  }
}

void add_geometry_and_parameters_text(std::string& t, const ImageReport& r) {
  if (r.geometry) {
    t += "geometry\n";
    t += fmt::format("  {:<9}{:>16}{:>16}{:>18}\n", "segment", "length (mm)", "radius (mm)", "theta max (rad)");
    for (std::size_t s = 0; s < r.geometry->size() && s < kMaxListedRows; ++s) {
      const auto& g = (*r.geometry)[s];
      t += fmt::format("  {:<9}{:>16}{:>16}{:>18}\n", s + 1, g[0], g[1], g[2]);
    }
    if (r.geometry->size() > kMaxListedRows) t += fmt::format("  ({} more not listed)\n", r.geometry->size() - kMaxListedRows);
  }
  if (r.cables) {
    // Without the block, every segment has the paper's four at 0, -90, -180 and -270 degrees.
    t += "cables (anchor angles in the segment's base frame, deg)\n";
    for (std::size_t s = 0; s < r.cables->size() && s < kMaxListedRows; ++s) {
      const ImageSegmentCables& c = (*r.cables)[s];
      std::string angles;
      for (int j = 0; j < 4 && j < c.count; ++j) {
        angles += fmt::format("{}{:.2f}", j > 0 ? ", " : "", c.angles_rad[j] * 57.29577951308232);
      }
      t += fmt::format("  {:<9}{} cables at {}\n", s + 1, c.count, angles);
    }
  }

  if (r.parameters) {
    const ImageParameters& p = *r.parameters;
    // v2 carries the range of the fitted rows, in raw input units.
    const bool ranges = !p.input_min.empty();
    t += fmt::format("input normalisation and length scales (x_n = (x - mean) / scale){}\n",
                     ranges ? "; range of the fitted rows" : "");
    t += fmt::format("  {:<16}{:>16}{:>16}{:>16}", "input", "mean", "scale", "length scale");
    t += ranges ? fmt::format("{:>16}{:>16}\n", "min", "max") : "\n";
    for (std::size_t i = 0; i < p.input_mean.size() && i < kMaxListedRows; ++i) {
      t += fmt::format("  {:<16}{:>16}{:>16}{:>16}", input_name(*r.header, i), p.input_mean[i],
                       p.input_scale[i], p.length_scale[i]);
      t += ranges ? fmt::format("{:>16}{:>16}\n", p.input_min[i], p.input_max[i]) : "\n";
    }
    if (p.input_mean.size() > kMaxListedRows) t += fmt::format("  ({} more not listed)\n", p.input_mean.size() - kMaxListedRows);
    if (!p.extra_input_default.empty()) {
      t += fmt::format("default payload (until the runtime receives one): {} kg\n", p.extra_input_default[0]);
    }
    t += "outputs, error twist (v, omega) (y = mean + scale y_n; variances in normalised units)\n";
    t += fmt::format("  {:<16}{:>16}{:>16}{:>16}{:>16}\n", "output", "mean", "scale", "signal var", "noise var");
    for (std::size_t k = 0; k < 6; ++k) {
      t += fmt::format("  {:<16}{:>16}{:>16}{:>16}{:>16}\n", fmt::format("{} ({})", kOutputNames[k], kOutputUnits[k]),
                       p.output_mean[k], p.output_scale[k], p.signal_variance[k], p.noise_variance[k]);
    }
  }
}

void add_optional_blocks_text(std::string& t, const ImageReport& r) {
  const auto row = [&t](const char* label, const std::string& value) { add_row(t, label, value); };
  if (r.hysteresis) {
    // effective length = commanded - sum_k weight_k lag_k, each lag within
    // +-width (model/include/cdcr/model/hysteresis.hpp).
    const ImageHysteresis& b = *r.hysteresis;
    t += fmt::format("cable hysteresis ({} play operators per cable; lags at home after the homing move)\n",
                     b.operators);
    t += fmt::format("  {:<9}{:>4}{:>16}{:>12}{:>18}\n", "cable", "k", "width (mm)", "weight", "homing lag (mm)");
    for (int c = 0; c < b.cables && c < static_cast<int>(kMaxListedRows); ++c) {
      for (int k = 0; k < b.operators; ++k) {
        const std::size_t i = static_cast<std::size_t>(c * b.operators + k);
        t += fmt::format("  {:<9}{:>4}{:>16}{:>12}{:>18}\n", k == 0 ? fmt::format("{}", c + 1) : std::string(), k + 1,
                         b.widths_mm[i], b.weights[i], b.homing_lags_mm[i]);
      }
    }
    if (b.cables > static_cast<int>(kMaxListedRows)) {
      t += fmt::format("  ({} more cables not listed)\n", b.cables - static_cast<int>(kMaxListedRows));
    }
  }
  if (r.compliance) {
    // b_i' = b_i + c_i (1 + s |b_i|) (m_y, -m_x), m the moment of the tip
    // load (model/include/cdcr/model/payload_compliance.hpp).
    const ImageCompliance& c = *r.compliance;
    t += "payload compliance (the sag of the tip load in the nominal model)\n";
    row("weight x c_0", fmt::format("({}, {}, {}) rad per kg mm, base frame", c.weighted_gravity[0],
                                    c.weighted_gravity[1], c.weighted_gravity[2]));
    std::string ratios;
    for (std::size_t i = 0; i < c.ratios.size(); ++i) ratios += fmt::format("{}{}", i ? ", " : "", c.ratios[i]);
    row("ratios c_i/c_0", ratios);
    row("softening", fmt::format("{} per rad", c.softening_per_rad));
    row("unloaded mass", fmt::format("{} kg", c.unloaded_mass_kg));
  }
  if (r.max_abs_input || r.max_abs_alpha) {
    const bool sparse = r.header && is_sparse(*r.header);
    t += sparse ? "inducing points\n" : "training set\n";
    if (r.max_abs_input) row("max |z|", fmt::format("{} (points in kernel coordinates)", *r.max_abs_input));
    if (r.max_abs_alpha) row(sparse ? "max |beta|" : "max |alpha|", fmt::format("{}", *r.max_abs_alpha));
  }

  if (!r.blocks.empty()) {
    t += "blocks\n";
    t += fmt::format("  {:<12}{:>12}{:>12}\n", "block", "offset", "size");
    for (const ImageBlock& b : r.blocks) {
      t += fmt::format("  {:<12}{:>12}{:>12}{}\n", b.name, b.offset, b.size, b.inside_file ? "" : "  beyond the end of the file");
    }
  }
}

void add_metadata_and_checks_text(std::string& t, const ImageReport& r) {
  const auto row = [&t](const char* label, const std::string& value) { add_row(t, label, value); };
  if (r.metadata) {
    const ImageMetadata& m = *r.metadata;
    const model::ImageMetrics& e = m.metrics;
    t += "metadata\n";
    row("dataset hash", fmt::format("0x{:016x} (FNV-1a 64 of the training data file)", m.dataset_hash));
    const std::optional<std::string> created = iso8601_utc(m.created_unix_s);
    row("created", fmt::format("{} (unix {})", created.value_or("out of range"), m.created_unix_s));
    row("validation samples", fmt::format("{}", m.validation_samples));
    if (m.validation_samples > 0) {
      row("initial error", fmt::format("{} mm, {} deg (mean over the validation samples)", e.initial_position_mm,
                                       e.initial_orientation_deg));
      row("compensated error",
          fmt::format("{} mm, {} deg", e.compensated_position_mm, e.compensated_orientation_deg));
    } else {
      row("initial error", "none held out (trained with --holdout 0)");
      row("compensated error", "none held out");
    }
    row("float32 fidelity", fmt::format("max {} mm, {} deg; mean {} mm, {} deg (image path vs double trainer)",
                                        e.float32_max_position_diff_mm, e.float32_max_orientation_diff_deg,
                                        e.float32_mean_position_diff_mm, e.float32_mean_orientation_diff_deg));
    row("trainer", fmt::format("\"{}\"", m.trainer));
  }

  t += "checks\n";
  for (const ImageCheck& c : r.checks) {
    // An image without a hysteresis block reads as it did before v2.2.
    const bool no_block = !r.header || (r.header->hysteresis_cables == 0 && r.header->hysteresis_operators == 0);
    if (c.id == model::ImageCheckId::hysteresis && no_block && c.result != CheckResult::failed) continue;
    // Likewise without a compliance block before v2.3.
    const bool no_compliance = !r.header || r.header->compliance_segments == 0;
    if (c.id == model::ImageCheckId::compliance && no_compliance && c.result != CheckResult::failed) continue;
    // And without a cables block before v2.7.
    const bool no_cables = !r.header || !model::image_has_cables_block(r.header->version_major, r.header->version_minor);
    if (c.id == model::ImageCheckId::cables && no_cables && c.result != CheckResult::failed) continue;
    std::string line = fmt::format("  {:<12}{:<13}{}", c.name, result_text(c.result), c.detail);
    while (line.back() == ' ') line.pop_back();
    t += line + "\n";
  }
  t += verdict(r) + "\n";
}

std::string format_text(const std::string& path, const ImageReport& r) {
  std::string t = fmt::format("{}: {} bytes\n", path, r.file_size);
  add_header_text(t, r);
  add_geometry_and_parameters_text(t, r);
  add_optional_blocks_text(t, r);
  add_metadata_and_checks_text(t, r);
  return t;
}

// --- JSON -----------------------------------------------------------------------

// The shortest decimal that reads back as the same float, so 0.1f shows as
// 0.1; JSON has no NaN or Inf, which become null.
Json float_json(float value) {
  if (!std::isfinite(value)) return nullptr;
  return std::strtod(fmt::format("{}", value).c_str(), nullptr);
}

Json floats_json(const std::vector<float>& values) {
  Json array = Json::array();
  for (float v : values) array.push_back(float_json(v));
  return array;
}

Json kind_json(std::uint8_t code, const char* name) {
  Json j;
  j["code"] = code;
  j["name"] = name != nullptr ? Json(name) : Json(nullptr);
  return j;
}

void add_header_json(Json& j, const std::string& path, const ImageReport& r) {
  j["file"] = path;
  j["file_size"] = r.file_size;
  j["valid"] = r.valid();
  j["status"] = image_status_name(r.status);
  j["message"] = model::to_string(r.status);
  const ImageCheck* failed = r.failed_check();
  j["failed_check"] = failed != nullptr ? Json(failed->name) : Json(nullptr);

  Json header = Json::object();
  if (r.magic) {
    header["magic"] = hex32(*r.magic);
    header["magic_ok"] = *r.magic == model::kImageMagic;
  }
  if (r.version_major) header["version_major"] = *r.version_major;
  if (r.header) {
    const ImageHeaderFields& h = *r.header;
    header["version_minor"] = h.version_minor;
    header["header_size"] = h.header_size;
    header["total_size"] = h.total_size;
    if (!is_v1(h)) {
      header["variance_offset"] = h.variance_offset;
      header["variance_rank"] = h.variance_rank;
      header["hysteresis_cables"] = h.hysteresis_cables;
      header["hysteresis_operators"] = h.hysteresis_operators;
      if (h.compliance_segments != 0) header["compliance_segments"] = h.compliance_segments;
    }
  }
  header["trailing_bytes"] = r.trailing_bytes ? Json(*r.trailing_bytes) : Json(nullptr);
  header["crc32_stored"] = r.stored_crc ? Json(hex32(*r.stored_crc)) : Json(nullptr);
  header["crc32_computed"] = r.computed_crc ? Json(hex32(*r.computed_crc)) : Json(nullptr);
  j["header"] = header;

  if (r.header) {
    const ImageHeaderFields& h = *r.header;
    j["dims"] = {{"training_points", h.training_points},
                 {"input_dims", h.input_dims},
                 {"output_dims", h.output_dims},
                 {"segments", h.segment_count}};
    j["version"] = fmt::format("{}.{}", h.version_major, h.version_minor);
    j["model_kind"] = kind_json(model_kind_code(h), model_kind_name(model_kind_code(h)));
    j["extra_inputs"] = h.extra_inputs;
    j["fitted_rows"] = r.fitted_rows ? Json(*r.fitted_rows) : Json(nullptr);
    j["scalar_type"] = kind_json(h.scalar_type, scalar_name(h.scalar_type));
    j["kernel"] = kind_json(h.kernel_kind, kernel_name(h.kernel_kind));
    j["input_encoding"] = kind_json(h.input_encoding, encoding_name(h.input_encoding));
  } else {
    j["dims"] = nullptr;
    j["version"] = nullptr;
    j["model_kind"] = nullptr;
    j["extra_inputs"] = nullptr;
    j["fitted_rows"] = nullptr;
    j["scalar_type"] = nullptr;
    j["kernel"] = nullptr;
    j["input_encoding"] = nullptr;
  }
}

void add_model_json(Json& j, const ImageReport& r) {
  if (r.geometry) {
    Json segments = Json::array();
    for (const auto& g : *r.geometry) {
      segments.push_back({{"backbone_length_mm", float_json(g[0])},
                          {"anchor_radius_mm", float_json(g[1])},
                          {"theta_max_rad", float_json(g[2])}});
    }
    j["geometry"] = segments;
  } else {
    j["geometry"] = nullptr;
  }
  if (r.cables) {
    Json segments = Json::array();
    for (const ImageSegmentCables& c : *r.cables) {
      Json angles = Json::array();
      for (int j = 0; j < 4 && j < c.count; ++j) angles.push_back(float_json(c.angles_rad[j]));
      segments.push_back({{"count", float_json(c.count)}, {"angles_rad", angles}});
    }
    j["cables"] = segments;
  } else {
    j["cables"] = nullptr;
  }

  if (r.parameters) {
    const ImageParameters& p = *r.parameters;
    j["normalisation"] = {{"input_mean", floats_json(p.input_mean)},
                          {"input_scale", floats_json(p.input_scale)},
                          {"output_mean", floats_json(p.output_mean)},
                          {"output_scale", floats_json(p.output_scale)}};
    j["hyperparameters"] = {{"length_scales", floats_json(p.length_scale)},
                            {"signal_variance", floats_json(p.signal_variance)},
                            {"noise_variance", floats_json(p.noise_variance)}};
    j["input_range"] = p.input_min.empty()
                           ? Json(nullptr)
                           : Json{{"input_min", floats_json(p.input_min)}, {"input_max", floats_json(p.input_max)}};
    j["default_payload_kg"] = p.extra_input_default.empty() ? Json(nullptr) : Json(p.extra_input_default[0]);
  } else {
    j["normalisation"] = nullptr;
    j["hyperparameters"] = nullptr;
    j["input_range"] = nullptr;
    j["default_payload_kg"] = nullptr;
  }
  if (r.hysteresis) {
    const ImageHysteresis& b = *r.hysteresis;
    j["hysteresis"] = {{"cables", b.cables},
                       {"operators", b.operators},
                       {"widths_mm", floats_json(b.widths_mm)},
                       {"weights", floats_json(b.weights)},
                       {"homing_lags_mm", floats_json(b.homing_lags_mm)}};
  } else {
    j["hysteresis"] = nullptr;
  }
  // Only an image with the block has the key: the output of every other
  // image stays as it was.
  if (r.compliance) {
    const ImageCompliance& c = *r.compliance;
    j["compliance"] = {{"weighted_gravity", floats_json(std::vector<float>(c.weighted_gravity.begin(), c.weighted_gravity.end()))},
                       {"ratios", floats_json(c.ratios)},
                       {"softening_per_rad", float_json(c.softening_per_rad)},
                       {"unloaded_mass_kg", float_json(c.unloaded_mass_kg)}};
  }
}

void add_contents_json(Json& j, const ImageReport& r) {
  j["training_set"] = {{"max_abs_kernel_coordinate", r.max_abs_input ? float_json(*r.max_abs_input) : Json(nullptr)},
                       {"max_abs_alpha", r.max_abs_alpha ? float_json(*r.max_abs_alpha) : Json(nullptr)}};

  Json blocks = Json::array();
  for (const ImageBlock& b : r.blocks) {
    blocks.push_back({{"name", b.name}, {"offset", b.offset}, {"size", b.size}, {"inside_file", b.inside_file}});
  }
  j["blocks"] = blocks;

  if (r.metadata) {
    const ImageMetadata& m = *r.metadata;
    const model::ImageMetrics& e = m.metrics;
    const std::optional<std::string> created = iso8601_utc(m.created_unix_s);
    j["metadata"] = {
        {"dataset_hash", fmt::format("{:016x}", m.dataset_hash)},
        {"created_unix_s", m.created_unix_s},
        {"created_utc", created ? Json(*created) : Json(nullptr)},
        {"validation_samples", m.validation_samples},
        {"metrics",
         {{"initial_position_mm", float_json(e.initial_position_mm)},
          {"initial_orientation_deg", float_json(e.initial_orientation_deg)},
          {"compensated_position_mm", float_json(e.compensated_position_mm)},
          {"compensated_orientation_deg", float_json(e.compensated_orientation_deg)},
          {"float32_max_position_diff_mm", float_json(e.float32_max_position_diff_mm)},
          {"float32_mean_position_diff_mm", float_json(e.float32_mean_position_diff_mm)},
          {"float32_max_orientation_diff_deg", float_json(e.float32_max_orientation_diff_deg)},
          {"float32_mean_orientation_diff_deg", float_json(e.float32_mean_orientation_diff_deg)}}},
        {"trainer", m.trainer}};
  } else {
    j["metadata"] = nullptr;
  }

  Json checks = Json::object();
  for (const ImageCheck& c : r.checks) {
    const Json passed = c.result == CheckResult::not_checked ? Json(nullptr) : Json(c.result == CheckResult::passed);
    checks[c.name] = {{"passed", passed}, {"detail", c.detail}};
  }
  j["checks"] = checks;
}

Json format_json(const std::string& path, const ImageReport& r) {
  Json j;
  add_header_json(j, path, r);
  add_model_json(j, r);
  add_contents_json(j, r);
  return j;
}

}  // namespace

void register_inspect_command(CLI::App& app, CommandOutput& output) {
  auto options = std::make_shared<InspectCommandOptions>();
  CLI::App* command = app.add_subcommand(
      "inspect", "Show the contents of a flash image and the outcome of every check of the firmware's parser");
  command->add_option("model", options->model_path, "Flash image file")->type_name("MODEL.img")->required();
  command->add_flag("--json", options->json, "Print one JSON object instead of text");
  command->callback([options, &output] { output = run_inspect(*options); });
}

CommandOutput run_inspect(const InspectCommandOptions& options) {
  std::vector<std::uint8_t> bytes;
  try {
    bytes = exporting::read_binary_file(options.model_path);
  } catch (const std::runtime_error& error) {
    throw InputError(error.what());
  }
  const ImageReport report = inspect_image(bytes.data(), bytes.size());

  CommandOutput output;
  output.text = options.json ? format_json(options.model_path, report).dump(-1, ' ', false, Json::error_handler_t::replace) + "\n"
                             : format_text(options.model_path, report);
  if (!report.valid()) {
    output.failure = fmt::format("{}: {} ({})", options.model_path, model::to_string(report.status),
                                 image_status_name(report.status));
  }
  return output;
}

}  // namespace cdcr::cli
