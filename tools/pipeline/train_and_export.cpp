#include "pipeline/train_and_export.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "cdcr/model/flash_image.hpp"
#include "export/image_writer.hpp"
#include "train/predictive_variance.hpp"

namespace cdcr::training {

namespace {

model::ImageMetrics metrics_of(const Evaluation& validation, const Fidelity& fidelity) {
  model::ImageMetrics m{};
  m.initial_position_mm = static_cast<float>(validation.initial.position_mm);
  m.initial_orientation_deg = static_cast<float>(validation.initial.orientation_deg);
  m.compensated_position_mm = static_cast<float>(validation.compensated.position_mm);
  m.compensated_orientation_deg = static_cast<float>(validation.compensated.orientation_deg);
  m.float32_max_position_diff_mm = static_cast<float>(fidelity.max_position_mm);
  m.float32_mean_position_diff_mm = static_cast<float>(fidelity.mean_position_mm);
  m.float32_max_orientation_diff_deg = static_cast<float>(fidelity.max_orientation_deg);
  m.float32_mean_orientation_diff_deg = static_cast<float>(fidelity.mean_orientation_deg);
  return m;
}

model::ImageView parsed(const std::vector<std::uint8_t>& image) {
  model::ImageView view{};
  if (const model::ImageStatus s = model::parse_image(image.data(), image.size(), view); s != model::ImageStatus::ok) {
    throw std::runtime_error(std::string("exported image does not parse: ") + model::to_string(s));
  }
  return view;
}

bool same_rows(const TrainingSet& a, const TrainingSet& b) {
  return a.size() == b.size() && a.inputs == b.inputs && a.error_twists == b.error_twists;
}

}  // namespace

ExportResult train_and_export(const TrainingSet& train_set, const TrainingSet& validation_set,
                              const TrainingSet& fitted_set, const model::RobotGeometry<double>& geometry,
                              const TrainingOptions& options, std::uint64_t dataset_hash,
                              std::int64_t created_unix_s, const model::HysteresisModel<double>& hysteresis,
                              const model::PayloadCompliance<double>& compliance) {
  ExportResult r;
  // The shipped model's kind and size are those for the rows it is fitted
  // on; the search's model on fewer rows is of the same kind.
  BoardLimits limits = options.board;
  limits.variance_rank = static_cast<std::uint32_t>(std::clamp(options.variance_rank, 0, fitted_set.size()));
  // The payload's sag runs in every forward cycle beside the GP's points.
  const std::uint32_t sag_instructions = compliance.empty() ? 0 : limits.forward_cycle.compliance_sag;
  limits.forward_cycle_instructions -= std::min(limits.forward_cycle_instructions, sag_instructions);
  const ModelSelection shipped =
      select_model(fitted_set.size(), static_cast<int>(fitted_set.inputs.cols()), geometry.segment_count,
                   options.model, options.inducing_points, limits);
  TrainingOptions search_options = options;
  search_options.board = limits;
  search_options.model = shipped.kind == ModelKind::exact ? ModelChoice::exact : ModelChoice::sparse;
  search_options.inducing_points = shipped.kind == ModelKind::exact ? 0 : std::min(shipped.points, train_set.size());
  TrainedModel searched = train(train_set, geometry, search_options, &r.report);
  searched.hysteresis = hysteresis;
  searched.compliance = compliance;
  r.report.selection = shipped;
  r.report.selection.forward_cycle_instructions += sag_instructions;
  const auto add_variance = [&](TrainedModel& m, const TrainingSet& rows) {
    if (options.variance_rank <= 0) return;
    const int rank = std::min(options.variance_rank, rows.size());
    m.variance = fit_variance_factor(m, rows.inputs, variance_points(m, rows.inputs, rank, options.search.seed));
    const RadiusCalibration calibration = calibrate_radii(m, rows, 0.95, 1000, options.search.seed);
    m.variance.position_scale = calibration.position_scale;
    m.variance.orientation_scale = calibration.orientation_scale;
    m.variance.extrapolation_variance = extrapolation_threshold(m, rows.inputs, 4000, options.search.seed);
    r.radius_calibration = calibration;
  };
  add_variance(searched, train_set);
  if (validation_set.size() > 0) {
    const Eigen::MatrixXd predicted = predict_error_twists(searched, validation_set);
    r.validation = evaluate(validation_set, predicted);
    const std::vector<std::uint8_t> image = exporting::write_image(searched);
    r.firmware.samples = validation_set.size();
    r.firmware.initial = r.validation.initial;
    r.firmware.compensated = mean_errors(
        validation_set.measured,
        firmware_poses(parsed(image), validation_set.cables_mm, FirmwareAccumulator::float64,
                       validation_set.payload_kg, validation_set.history_inputs));
    if (searched.variance.rank() > 0) {
      r.validation_coverage =
          check_coverage(validation_set.measured,
                         firmware_estimates(parsed(image), validation_set.cables_mm, validation_set.payload_kg,
                                            validation_set.history_inputs));
    }
  }

  if (same_rows(fitted_set, train_set)) {
    r.model = searched;
  } else {
    r.model = refit(searched, shipped.kind, fitted_set);
    add_variance(r.model, fitted_set);
  }
  r.fitted_rows = fitted_set.size();
  r.model.dataset_hash = dataset_hash;
  r.model.created_unix_s = created_unix_s;
  r.model.validation_samples = static_cast<std::uint32_t>(r.validation.samples);

  // The metrics live inside the image, so measure on a first image and
  // write the final one with the figures; the payload is identical.
  // A cable-fit model's rows may bend to near pi, where the bend's last bits
  // follow the cables' last bit (asin near 1): its image is measured against
  // the double path on the same float32 lengths, so that the figure is the
  // image's arithmetic, not the float rounding of its input. (The board
  // reads lengths in 0.01 mm steps in any case.)
  const TrainingSet& measured_set = r.validation.samples > 0 ? validation_set : fitted_set;
  const bool same_float_cables = model::takes_cable_residuals(r.model.encoding) && compliance.empty();
  const TrainingSet rounded_set =
      same_float_cables ? with_float_cables(measured_set, geometry, r.model.encoding) : TrainingSet{};
  const TrainingSet& fidelity_set = same_float_cables ? rounded_set : measured_set;
  const std::vector<model::Pose<double>> double_poses =
      compensated_poses(fidelity_set, predict_error_twists(r.model, fidelity_set));
  const std::vector<std::uint8_t> first_image = exporting::write_image(r.model);
  const model::ImageView view = parsed(first_image);
  for (const FirmwareAccumulator accumulator :
       {FirmwareAccumulator::float64, FirmwareAccumulator::compensated_float32, FirmwareAccumulator::float32}) {
    const std::vector<model::Pose<double>> float_poses = firmware_poses(
        view, fidelity_set.cables_mm, accumulator, fidelity_set.payload_kg, fidelity_set.history_inputs);
    const Fidelity f = compare_poses(double_poses, float_poses);
    r.fidelity_by_accumulator.emplace_back(accumulator, f);
    if (accumulator == FirmwareAccumulator::float32) continue;  // no firmware build sums this way
    r.fidelity.max_position_mm = std::max(r.fidelity.max_position_mm, f.max_position_mm);
    r.fidelity.mean_position_mm = std::max(r.fidelity.mean_position_mm, f.mean_position_mm);
    r.fidelity.max_orientation_deg = std::max(r.fidelity.max_orientation_deg, f.max_orientation_deg);
    r.fidelity.mean_orientation_deg = std::max(r.fidelity.mean_orientation_deg, f.mean_orientation_deg);
  }

  r.model.metrics = metrics_of(r.validation, r.fidelity);
  r.image = exporting::write_image(r.model);
  return r;
}

PayloadExport train_and_export_payload(const TrainingSet& train_set, const TrainingSet& validation_set,
                                       const TrainingSet& fitted_set, const model::RobotGeometry<double>& geometry,
                                       const TrainingOptions& options, std::uint64_t dataset_hash,
                                       std::int64_t created_unix_s) {
  if (!train_set.has_payload() || !fitted_set.has_payload() ||
      (validation_set.size() > 0 && !validation_set.has_payload())) {
    throw std::invalid_argument("the payload model's rows need a payload_kg column");
  }
  PayloadExport out;
  out.choice = choose_compliance(train_set, geometry, options);
  if (validation_set.size() > 0) {
    out.unsagged_validation.samples = validation_set.size();
    out.unsagged_validation.initial = mean_errors(validation_set.measured, validation_set.nominal);
  }
  if (out.choice.model.empty()) {
    out.result = train_and_export(train_set, validation_set, fitted_set, geometry, options, dataset_hash,
                                  created_unix_s);
    return out;
  }
  const ComplianceModel& c = out.choice.model;
  const TrainingSet sagged_train = with_compliance(train_set, geometry, c);
  const TrainingSet sagged_validation =
      validation_set.size() > 0 ? with_compliance(validation_set, geometry, c) : validation_set;
  const TrainingSet sagged_fitted =
      same_rows(fitted_set, train_set) ? sagged_train : with_compliance(fitted_set, geometry, c);
  out.result = train_and_export(sagged_train, sagged_validation, sagged_fitted, geometry, options, dataset_hash,
                                created_unix_s, {}, c.for_model(geometry.segment_count));
  return out;
}

SequenceExport train_and_export_sequence(const dataset::Dataset& data, const std::vector<int>& train_rows,
                                         const std::vector<int>& validation_rows,
                                         const dataset::Dataset* validation_data,
                                         const model::RobotGeometry<double>& geometry, const TrainingOptions& options,
                                         bool with_payload, std::uint64_t dataset_hash, std::int64_t created_unix_s,
                                         const HysteresisSearchOptions& search) {
  if (!data.has_time) throw std::invalid_argument("the data are not a motion sequence (no t_s column)");
  if (validation_data != nullptr && !validation_data->has_time) {
    throw std::invalid_argument(
        "the validation data have no t_s column; a model of a sequence is validated on a sequence");
  }
  SequenceExport out;
  const TrainingSet all = make_training_set(data, geometry, options.encoding, with_payload);
  const TrainingSet train_set = all.subset(train_rows);
  const TrainingSet validation_set = validation_data != nullptr
                                         ? make_training_set(*validation_data, geometry, options.encoding, with_payload)
                                         : all.subset(validation_rows);
  out.identification = identify_hysteresis(data, train_rows, geometry, options, with_payload, search);
  TrainingOptions sequence_options = options;
  if (options.offer_history && out.identification.attempted) {
    out.history =
        choose_history_inputs(data, train_rows, out.identification.model, geometry, options, with_payload);
  } else {
    out.history.model = out.identification.model;
    out.history.reason = options.offer_history ? "not offered: the hysteresis was not identified" : "not offered";
  }
  if (out.history.chosen) sequence_options.encoding = model::with_history(options.encoding, true);
  const model::HysteresisModel<double>& hysteresis = out.history.model;
  if (hysteresis.empty()) {
    out.result = train_and_export(train_set, validation_set, all, geometry, options, dataset_hash, created_unix_s);
    if (out.identification.attempted) out.joints_only_validation = out.result.validation;
    return out;
  }
  const TrainingSet effective_all =
      make_sequence_training_set(data, hysteresis, geometry, sequence_options.encoding, with_payload);
  const TrainingSet effective_validation =
      validation_data != nullptr
          ? make_sequence_training_set(*validation_data, hysteresis, geometry, sequence_options.encoding, with_payload)
          : effective_all.subset(validation_rows);
  out.result = train_and_export(effective_all.subset(train_rows), effective_validation, effective_all, geometry,
                                sequence_options, dataset_hash, created_unix_s, hysteresis);
  // On the effective lengths the GP may explain the data down to a noise
  // variance ten thousand times below its signal's; its weights are then so
  // large that the image's float32 sums lose the target (0.07 mm on the
  // simulator's hysteresis session). The search's noise floor is raised,
  // fourfold at a time, until the image meets it (there, twice: 0.734 ->
  // 0.747 mm held out, 0.070 -> 0.0015 mm float32).
  // Where no floor meets it (an orientation correction of tens of degrees
  // has float32 sums good to about 0.001 deg whatever the weights), the
  // unraised model is kept: a raised floor would only have thrown its
  // accuracy away.
  TrainingOptions raised = sequence_options;
  ExportResult unraised;
  for (int attempt = 0; attempt < kNoiseFloorAttempts && !out.result.fidelity_met(); ++attempt) {
    if (attempt == 0) unraised = out.result;
    raised.search.bounds.noise_variance_min =
        std::min(raised.search.bounds.noise_variance_max,
                 4.0 * std::max(raised.search.bounds.noise_variance_min, out.result.model.noise_variance[0]));
    out.result = train_and_export(effective_all.subset(train_rows), effective_validation, effective_all, geometry,
                                  raised, dataset_hash, created_unix_s, hysteresis);
    out.noise_variance_floor = raised.search.bounds.noise_variance_min;
  }
  if (!out.result.fidelity_met() && out.noise_variance_floor > 0.0) {
    out.result = std::move(unraised);
    out.noise_variance_floor = 0.0;
  }
  if (validation_set.size() > 0) {
    const TrainedModel& joints_only = out.identification.joints_only;
    out.joints_only_validation =
        evaluate(validation_set, predict_error_twists(joints_only, validation_set));
  }
  return out;
}

}  // namespace cdcr::training
