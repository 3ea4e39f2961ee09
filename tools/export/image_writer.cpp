#include "image_writer.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

#include "cdcr/model/crc32.hpp"
#include "cdcr/model/flash_image.hpp"

namespace cdcr::exporting {

namespace {

class ImageBuffer {
 public:
  explicit ImageBuffer(std::uint32_t size) : bytes_(size, 0) {}

  template <typename T>
  void put(std::size_t offset, T value) {
    std::memcpy(bytes_.data() + offset, &value, sizeof(T));
  }

  // A header field, in the field's own size (little-endian: the low bytes).
  void put_field(const model::ImageHeaderField& field, std::uint32_t value) {
    std::memcpy(bytes_.data() + field.offset, &value, field.size());
  }

  void put_float(std::size_t offset, double value) {
    const auto f = static_cast<float>(value);
    if (!std::isfinite(f)) throw std::invalid_argument("model value does not fit in float32: " + std::to_string(value));
    put(offset, f);
  }

  std::vector<std::uint8_t> take() { return std::move(bytes_); }
  std::uint8_t* data() { return bytes_.data(); }

 private:
  std::vector<std::uint8_t> bytes_;
};

// The counts a trained hysteresis model must have for a robot of
// `cables` cables; parse_image() judges its values.
void check_hysteresis_counts(const model::HysteresisModel<double>& hysteresis, int cables) {
  if (hysteresis.empty()) return;
  if (hysteresis.cables != cables || hysteresis.cables > model::kMaxCables || hysteresis.operators < 1 ||
      hysteresis.operators > model::kMaxHysteresisOperators) {
    throw std::invalid_argument("trained model's hysteresis has " + std::to_string(hysteresis.cables) +
                                " cables and " + std::to_string(hysteresis.operators) +
                                " operators per cable; a robot of " + std::to_string(cables) + " cables needs " +
                                std::to_string(cables) + " cables and 1 to " +
                                std::to_string(model::kMaxHysteresisOperators) + " operators");
  }
}

// The cables block (v2.7) of a robot whose segments are not all the
// paper's four at 90 degrees; none for those.
std::uint32_t cables_floats(const model::RobotGeometry<double>& geometry) {
  return geometry.paper_cables() ? 0 : model::image_cables_floats(static_cast<std::uint32_t>(geometry.segment_count));
}

void put_cables(ImageBuffer& image, std::size_t block, const model::RobotGeometry<double>& geometry) {
  if (cables_floats(geometry) == 0) return;
  using namespace model::image_cables_field;
  for (int i = 0; i < geometry.segment_count; ++i) {
    const model::CableLayout<double>& layout = geometry.segments[i].cables;
    const std::size_t at = block + 4 * static_cast<std::size_t>(i) * per_segment;
    image.put_float(at + 4 * count, layout.count);
    for (int j = 0; j < model::kMaxCablesPerSegment; ++j) {
      image.put_float(at + 4 * (angles + j),
                      // + 0.0: the angle on the x axis is 0, not -0.
                      j < layout.count ? std::atan2(layout.anchor_y[j], layout.anchor_x[j]) + 0.0 : 0.0);
    }
  }
}

std::uint32_t hysteresis_floats(const model::HysteresisModel<double>& hysteresis) {
  return hysteresis.empty() ? 0
                            : model::image_hysteresis_floats(static_cast<std::uint32_t>(hysteresis.cables),
                                                             static_cast<std::uint32_t>(hysteresis.operators));
}

// The header's counts and the block, for a model with a hysteresis model.
void put_hysteresis(ImageBuffer& image, std::uint32_t block, const model::HysteresisModel<double>& hysteresis) {
  if (hysteresis.empty()) return;
  image.put_field(model::image_field::version_minor,
                  model::image_block(model::ImageBlockId::hysteresis).version_minor);
  image.put_field(model::image_field::hysteresis_cables, static_cast<std::uint32_t>(hysteresis.cables));
  image.put_field(model::image_field::hysteresis_operators, static_cast<std::uint32_t>(hysteresis.operators));
  std::size_t at = block + 4 * model::image_hysteresis_field::widths;
  for (const auto* values : {&hysteresis.widths_mm, &hysteresis.weights, &hysteresis.homing_lag_mm}) {
    for (int c = 0; c < hysteresis.cables; ++c) {
      for (int k = 0; k < hysteresis.operators; ++k) {
        image.put_float(at, (*values)[c][k]);
        at += 4;
      }
    }
  }
}

// The count a trained compliance model must have, and the payload input it
// needs; parse_image() judges its values.
void check_compliance_counts(const model::PayloadCompliance<double>& compliance, int segments, int extra_inputs) {
  if (compliance.empty()) return;
  if (compliance.segments != segments) {
    throw std::invalid_argument("trained model's compliance has " + std::to_string(compliance.segments) +
                                " segments; the robot has " + std::to_string(segments));
  }
  if (extra_inputs != 1) throw std::invalid_argument("a compliance block needs a model with the payload input");
}

std::uint32_t compliance_floats(const model::PayloadCompliance<double>& compliance) {
  return compliance.empty() ? 0 : model::image_compliance_floats(static_cast<std::uint32_t>(compliance.segments));
}

// The header's count and the block, for a model with a compliance model.
void put_compliance(ImageBuffer& image, std::uint32_t block, const model::PayloadCompliance<double>& compliance) {
  if (compliance.empty()) return;
  using namespace model::image_compliance_field;
  image.put_field(model::image_field::version_minor,
                  model::image_block(model::ImageBlockId::compliance).version_minor);
  image.put_field(model::image_field::compliance_segments, static_cast<std::uint32_t>(compliance.segments));
  for (int k = 0; k < 3; ++k) image.put_float(block + 4 * (weighted_gravity + k), compliance.weighted_gravity[k]);
  std::size_t at = block + 4 * ratios;
  for (int i = 0; i < compliance.segments; ++i, at += 4) image.put_float(at, compliance.ratio[static_cast<std::size_t>(i)]);
  image.put_float(at, compliance.softening_per_rad);
  image.put_float(at + 4, compliance.unloaded_mass_kg);
}

// Whatever is written must parse (a non-positive scale, for one, is only
// caught here). Capacity is a property of the firmware build, not of the
// image, so none is imposed.
void check_parses(ImageBuffer& image, std::uint32_t size) {
  model::ImageView view{};
  const model::ImageCapacity any_capacity{std::numeric_limits<std::uint32_t>::max(),
                                          std::numeric_limits<std::uint16_t>::max(),
                                          std::numeric_limits<std::uint16_t>::max()};
  if (const model::ImageStatus status = model::parse_image(image.data(), size, view, any_capacity);
      status != model::ImageStatus::ok) {
    throw std::invalid_argument(std::string("trained model cannot be exported: ") + model::to_string(status));
  }
}

// The cable-fit encoding is 2.4's, the history's 2.5, the variance block's
// threshold alone flagging extrapolation 2.6, the cables block 2.7; the
// other blocks' minor versions are older, so it is put after them.
void put_newest_version(ImageBuffer& image, model::InputEncoding encoding, int variance_rank, bool cables_block) {
  if (cables_block) {
    image.put_field(model::image_field::version_minor, model::kImageVersionMinorCables);
  } else if (variance_rank > 0) {
    image.put_field(model::image_field::version_minor, model::kImageVersionMinorHeldOutThreshold);
  } else if (model::takes_history(encoding)) {
    image.put_field(model::image_field::version_minor, model::kImageVersionMinorHistory);
  } else if (model::takes_cable_residuals(encoding)) {
    image.put_field(model::image_field::version_minor, model::kImageVersionMinorCableFit);
  }
}

// The counts the image is laid out for, once the model has them consistently.
struct ModelDims {
  int points;
  int input_dims;
  int segments;
  int extra_inputs;  // 1: the payload input
  int variance_rank;
  std::uint32_t rows_fitted;
};

ModelDims checked_dims(const training::TrainedModel& model) {
  const int n = model.training_points();
  const int d = model.input_dims();
  const int segments = model.geometry.segment_count;
  const int extra = d - model::encoded_input_count(model.encoding, model.geometry);
  if (n < 1 || extra < 0 || extra > model::kMaxExtraInputs || model.alpha.rows() != n || model.alpha.cols() != model::kImageOutputs ||
      model.input_mean.size() != d || model.input_scale.size() != d || model.length_scales.size() != d) {
    throw std::invalid_argument("trained model has inconsistent dimensions");
  }
  const bool range_given = model.input_min.size() > 0 || model.input_max.size() > 0;
  if (range_given && (model.input_min.size() != d || model.input_max.size() != d)) {
    throw std::invalid_argument("trained model's input range has the wrong dimension");
  }
  // An exact model's points are the rows it was fitted on; a sparse model's
  // rows cannot be told from its inducing points.
  if (model.kind == model::ImageModelKind::sparse_gp && model.fitted_rows == 0) {
    throw std::invalid_argument("a sparse model must give the number of rows it was fitted on");
  }
  const std::uint32_t rows_fitted = model.fitted_rows != 0 ? model.fitted_rows : static_cast<std::uint32_t>(n);
  // The format's offsets are 32-bit; far beyond any flash, but the layout
  // arithmetic must not wrap.
  if (static_cast<std::uint64_t>(n) * static_cast<std::uint64_t>(d + model::kImageOutputs) * 4 > (1ull << 31)) {
    throw std::invalid_argument("trained model is too large for a flash image");
  }
  const training::VarianceFactor& variance = model.variance;
  const int rank = variance.rank();
  if (rank > 0 && (variance.points.cols() != d || variance.inducing_factor.rows() != rank ||
                   variance.inducing_factor.cols() != rank || variance.posterior_factor.rows() != rank ||
                   variance.posterior_factor.cols() != rank)) {
    throw std::invalid_argument("trained model's variance factor has inconsistent dimensions");
  }
  if (rank > 0xFFFF) throw std::invalid_argument("trained model's variance factor is too large for a flash image");
  check_hysteresis_counts(model.hysteresis, model.geometry.cable_count());
  check_compliance_counts(model.compliance, segments, extra);
  return ModelDims{n, d, segments, extra, rank, rows_fitted};
}

// The header of a 2.1 image; put_hysteresis(), put_compliance() and
// put_newest_version() raise the minor version for what the image holds.
void put_header(ImageBuffer& image, const training::TrainedModel& model, const ModelDims& dims,
                const model::ImageLayout& layout) {
  namespace field = model::image_field;
  const auto count = [](int value) { return static_cast<std::uint32_t>(value); };
  image.put_field(field::magic, model::kImageMagic);
  image.put_field(field::version_major, model::kImageVersionMajor);
  image.put_field(field::version_minor, model::kImageVersionMinor);
  image.put_field(field::header_size, model::kImageHeaderSize);
  image.put_field(field::total_size, layout.total_size);
  image.put_field(field::training_points, count(dims.points));
  image.put_field(field::input_dims, count(dims.input_dims));
  image.put_field(field::output_dims, count(model::kImageOutputs));
  image.put_field(field::segment_count, count(dims.segments));
  image.put_field(field::scalar_type, static_cast<std::uint32_t>(model::ImageScalar::float32));
  image.put_field(field::kernel_kind, static_cast<std::uint32_t>(model::ImageKernel::squared_exponential_ard));
  image.put_field(field::input_encoding, static_cast<std::uint32_t>(model.encoding));
  image.put_field(field::model_kind, static_cast<std::uint32_t>(model.kind));
  image.put_field(field::extra_inputs, count(dims.extra_inputs));
  // Every block offset the header holds, where the layout puts the block.
  for (const model::ImageHeaderField& f : model::kImageHeaderFields) {
    if (f.locates != model::ImageBlockId::none) image.put_field(f, layout.*model::image_block(f.locates).offset);
  }
  image.put_field(field::metadata_size, model::kImageMetadataSize);
  image.put_field(field::variance_rank, count(dims.variance_rank));
}

void put_geometry(ImageBuffer& image, std::size_t at, const model::RobotGeometry<double>& geometry) {
  for (int i = 0; i < geometry.segment_count; ++i) {
    const auto& s = geometry.segments[i];
    for (double v : {s.backbone_length_mm, s.anchor_radius_mm, s.theta_max_rad}) {
      image.put_float(at, v);
      at += 4;
    }
  }
}

void put_parameters(ImageBuffer& image, std::size_t at, const training::TrainedModel& model, const ModelDims& dims) {
  const auto put_all = [&](const auto& values) {
    for (Eigen::Index i = 0; i < values.size(); ++i) {
      image.put_float(at, values[i]);
      at += 4;
    }
  };
  put_all(model.input_mean);
  put_all(model.input_scale);
  put_all(model.length_scales);
  put_all(model.output_mean);
  put_all(model.output_scale);
  put_all(model.signal_variance);
  put_all(model.noise_variance);
  if (model.input_min.size() > 0 || model.input_max.size() > 0) {
    put_all(model.input_min);
    put_all(model.input_max);
  } else {
    put_all(Eigen::VectorXd(model.inputs.colwise().minCoeff().transpose()));
    put_all(Eigen::VectorXd(model.inputs.colwise().maxCoeff().transpose()));
  }
  if (dims.extra_inputs > 0) put_all(Eigen::VectorXd::Constant(1, model.default_payload_kg));
}

// Training inputs go in as kernel coordinates, computed in double and
// rounded once; then the weights.
void put_points(ImageBuffer& image, const model::ImageLayout& layout, const training::TrainedModel& model,
                const ModelDims& dims) {
  std::size_t at = layout.inputs_offset;
  for (int i = 0; i < dims.points; ++i) {
    for (int k = 0; k < dims.input_dims; ++k) {
      image.put_float(at, (model.inputs(i, k) - model.input_mean[k]) / (model.input_scale[k] * model.length_scales[k]));
      at += 4;
    }
  }
  at = layout.alpha_offset;
  for (int i = 0; i < dims.points; ++i) {
    for (int k = 0; k < model::kImageOutputs; ++k) {
      image.put_float(at, model.alpha(i, k));
      at += 4;
    }
  }
}

void put_variance(ImageBuffer& image, std::size_t block, const training::VarianceFactor& variance, int input_dims) {
  const int rank = variance.rank();
  if (rank == 0) return;
  using namespace model::image_variance_field;
  image.put_float(block + 4 * position_scale, variance.position_scale);
  image.put_float(block + 4 * orientation_scale, variance.orientation_scale);
  image.put_float(block + 4 * extrapolation_variance, variance.extrapolation_variance);
  std::size_t at = block + 4 * points;
  for (int i = 0; i < rank; ++i) {
    for (int k = 0; k < input_dims; ++k) {
      image.put_float(at, variance.points(i, k));
      at += 4;
    }
  }
  for (const Eigen::MatrixXd* factor : {&variance.inducing_factor, &variance.posterior_factor}) {
    for (int i = 0; i < rank; ++i) {
      for (int j = 0; j <= i; ++j) {
        image.put_float(at, (*factor)(i, j));
        at += 4;
      }
    }
  }
}

void put_metadata(ImageBuffer& image, std::size_t meta, const training::TrainedModel& model,
                  std::uint32_t rows_fitted) {
  using namespace model::image_metadata_field;
  image.put<std::uint64_t>(meta + dataset_hash, model.dataset_hash);
  image.put<std::int64_t>(meta + created_unix_s, model.created_unix_s);
  image.put<std::uint32_t>(meta + validation_samples, model.validation_samples);
  image.put<std::uint32_t>(meta + fitted_rows, rows_fitted);
  image.put<model::ImageMetrics>(meta + metrics, model.metrics);
  std::memcpy(image.data() + meta + trainer, model.trainer.data(), std::min<std::size_t>(model.trainer.size(), 32));
}

// The CRC-32 trailer over everything before it.
void put_checksum(ImageBuffer& image, std::uint32_t total_size) {
  const std::uint32_t checksum = model::crc32(image.data(), total_size - model::kImageTrailerSize);
  image.put<std::uint32_t>(total_size - model::kImageTrailerSize, checksum);
}

}  // namespace

std::vector<std::uint8_t> write_image(const training::TrainedModel& model) {
  const ModelDims dims = checked_dims(model);
  const model::ImageLayout layout =
      model::image_layout(static_cast<std::uint32_t>(dims.points), static_cast<std::uint32_t>(dims.input_dims),
                          static_cast<std::uint32_t>(dims.segments), model::kImageVersionMajor,
                          static_cast<std::uint32_t>(dims.variance_rank), static_cast<std::uint32_t>(dims.extra_inputs),
                          hysteresis_floats(model.hysteresis), compliance_floats(model.compliance),
                          cables_floats(model.geometry));
  ImageBuffer image(layout.total_size);
  put_header(image, model, dims, layout);
  put_geometry(image, layout.geometry_offset, model.geometry);
  put_parameters(image, layout.parameters_offset, model, dims);
  put_points(image, layout, model, dims);
  put_variance(image, layout.variance_offset, model.variance, dims.input_dims);
  put_hysteresis(image, layout.hysteresis_offset, model.hysteresis);
  put_compliance(image, layout.compliance_offset, model.compliance);
  put_cables(image, layout.cables_offset, model.geometry);
  put_newest_version(image, model.encoding, dims.variance_rank, cables_floats(model.geometry) > 0);
  put_metadata(image, layout.metadata_offset, model, dims.rows_fitted);
  put_checksum(image, layout.total_size);
  check_parses(image, layout.total_size);
  return image.take();
}

namespace {

// `image` (a valid v2 image without either block) with the blocks given
// added between its last block and its metadata, which moves.
std::vector<std::uint8_t> with_blocks(const std::vector<std::uint8_t>& image,
                                      const model::HysteresisModel<double>& hysteresis,
                                      const model::PayloadCompliance<double>& compliance) {
  model::ImageView view{};
  const model::ImageCapacity any_capacity{std::numeric_limits<std::uint32_t>::max(),
                                          std::numeric_limits<std::uint16_t>::max(),
                                          std::numeric_limits<std::uint16_t>::max()};
  if (const model::ImageStatus status = model::parse_image(image.data(), image.size(), view, any_capacity);
      status != model::ImageStatus::ok) {
    throw std::invalid_argument(std::string("image to add a block to: ") + model::to_string(status));
  }
  if (view.version_major != model::kImageVersionMajor || view.hysteresis_cables != 0 ||
      view.compliance_segments != 0 || view.cables != nullptr) {
    throw std::invalid_argument("only a v2 image without a hysteresis, compliance or cables block can take one");
  }
  check_hysteresis_counts(hysteresis, view.cable_count);
  check_compliance_counts(compliance, view.segment_count, view.extra_inputs);
  const auto layout_with = [&](std::uint32_t hysteresis_block, std::uint32_t compliance_block) {
    return model::image_layout(view.training_points, static_cast<std::uint32_t>(view.input_dims),
                               static_cast<std::uint32_t>(view.segment_count), view.version_major, view.variance_rank,
                               static_cast<std::uint32_t>(view.extra_inputs), hysteresis_block, compliance_block);
  };
  const model::ImageLayout old_layout = layout_with(0, 0);
  const model::ImageLayout layout = layout_with(hysteresis_floats(hysteresis), compliance_floats(compliance));
  ImageBuffer out(layout.total_size);
  std::memcpy(out.data(), image.data(), old_layout.metadata_offset);
  std::memcpy(out.data() + layout.metadata_offset, image.data() + old_layout.metadata_offset,
              model::kImageMetadataSize);
  out.put_field(model::image_field::total_size, layout.total_size);
  out.put_field(model::image_field::metadata_offset, layout.metadata_offset);
  put_hysteresis(out, layout.hysteresis_offset, hysteresis);
  put_compliance(out, layout.compliance_offset, compliance);
  // The variance block's threshold keeps the meaning it was written with.
  put_newest_version(out, view.encoding,
                     view.version_minor >= model::kImageVersionMinorHeldOutThreshold ? int(view.variance_rank) : 0,
                     false);
  put_checksum(out, layout.total_size);
  check_parses(out, layout.total_size);
  return out.take();
}

}  // namespace

std::vector<std::uint8_t> with_hysteresis_block(const std::vector<std::uint8_t>& image,
                                                const model::HysteresisModel<double>& hysteresis) {
  return with_blocks(image, hysteresis, {});
}

std::vector<std::uint8_t> with_compliance_block(const std::vector<std::uint8_t>& image,
                                                const model::PayloadCompliance<double>& compliance) {
  return with_blocks(image, {}, compliance);
}

}  // namespace cdcr::exporting
