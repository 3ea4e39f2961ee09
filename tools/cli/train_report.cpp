#include "train_report.hpp"

#include <vector>

#include <fmt/format.h>

#include "cdcr/model/cable_fit.hpp"
#include "json_output.hpp"

namespace cdcr::cli {
namespace {

std::string check_mark(bool ok) { return ok ? "meets target" : "MISSES target"; }

Json errors_json(const training::MeanErrors& e) {
  Json j;
  j["position_mm"] = e.position_mm;
  j["orientation_deg"] = e.orientation_deg;
  return j;
}

// Per cable, the K values of one of the model's arrays.
Json per_cable(const model::HysteresisModel<double>& m, const double (*values)[model::kMaxHysteresisOperators]) {
  Json cables = Json::array();
  for (int c = 0; c < m.cables; ++c) cables.push_back(std::vector<double>(values[c], values[c] + m.operators));
  return cables;
}

std::string structure_name(training::HysteresisSharing sharing, int operators) {
  if (sharing == training::HysteresisSharing::none) return "none";
  return fmt::format("{}, {} play operator{} per cable", training::to_string(sharing), operators,
                     operators == 1 ? "" : "s");
}

const char* sharing_key(training::HysteresisSharing sharing) {
  switch (sharing) {
    case training::HysteresisSharing::none: return "none";
    case training::HysteresisSharing::all_cables: return "all_cables";
    case training::HysteresisSharing::per_segment: return "per_segment";
    case training::HysteresisSharing::per_cable: return "per_cable";
  }
  return "?";
}

// What an identification before the GP did: tried, or why not; kept.
Json identification_json(bool attempted, const std::string& skipped_reason, bool used) {
  Json j;
  j["identified"] = attempted;
  j["skipped_reason"] = attempted ? Json(nullptr) : Json(skipped_reason);
  j["used"] = used;
  return j;
}

Json hysteresis_json(const TrainRun& run) {
  if (run.sequence == nullptr) return nullptr;
  const training::SequenceExport& s = *run.sequence;
  const training::HysteresisIdentification& id = s.identification;
  Json j = identification_json(id.attempted, id.skipped_reason, s.uses_hysteresis());
  j["structure"] = sharing_key(id.sharing);
  j["operators"] = id.model.operators;
  const model::HysteresisModel<double>& m = s.result.model.hysteresis;
  j["widths_mm"] = per_cable(m, m.widths_mm);
  j["weights"] = per_cable(m, m.weights);
  j["homing_lag_mm"] = per_cable(m, m.homing_lag_mm);
  Json candidates = Json::array();
  for (const training::HysteresisCandidate& c : id.candidates) {
    candidates.push_back({{"structure", sharing_key(c.sharing)},
                          {"operators", c.operators},
                          {"parameters", c.parameters},
                          {"log_marginal_likelihood", c.log_marginal_likelihood},
                          {"criterion", c.criterion},
                          {"likelihood_evaluations", c.likelihood_evaluations}});
  }
  j["candidates"] = candidates;
  j["likelihood_rows"] = id.rows;
  j["likelihood_evaluations"] = id.likelihood_evaluations;
  j["hyperparameter_searches"] = id.hyperparameter_searches;
  j["refinement_gain"] = id.refinement_gain;
  const training::HistoryChoice& h = s.history;
  Json history_candidates = Json::array();
  for (const training::HistoryCandidate& c : h.candidates) {
    history_candidates.push_back({{"width_mm", c.width_mm}, {"log_marginal_likelihood", c.log_marginal_likelihood}});
  }
  j["history"] = {{"searched", h.searched},
                  {"chosen", h.chosen},
                  {"width_mm", h.chosen ? Json(h.width_mm) : Json(nullptr)},
                  {"without_log_likelihood", h.searched ? Json(h.without_log_likelihood) : Json(nullptr)},
                  {"candidates", history_candidates},
                  {"extra_parameters", h.extra_parameters},
                  {"penalty", h.penalty},
                  {"search_rows", h.search_rows},
                  {"reason", h.reason}};
  j["noise_variance_floor"] = s.noise_variance_floor > 0.0 ? Json(s.noise_variance_floor) : Json(nullptr);
  if (s.joints_only_validation.samples > 0) {
    j["validation"] = {{"nominal_commanded", errors_json(s.joints_only_validation.initial)},
                       {"joints_only", errors_json(s.joints_only_validation.compensated)},
                       {"with_hysteresis", errors_json(s.result.validation.compensated)}};
  } else {
    j["validation"] = nullptr;
  }
  return j;
}

std::string hysteresis_text(const TrainRun& run) {
  if (run.sequence == nullptr) {
    return run.data_has_time ? "hysteresis: not identified (--no-hysteresis); joints-only model\n" : "";
  }
  const training::SequenceExport& s = *run.sequence;
  const training::HysteresisIdentification& id = s.identification;
  std::string t;
  if (!id.attempted) {
    return fmt::format("hysteresis: not identified ({}); joints-only model\n", id.skipped_reason);
  }
  t += fmt::format("hysteresis identified on {} training rows of the sequence: {}\n", id.rows,
                   structure_name(id.sharing, id.model.operators));
  t += "  structure        parameters  log likelihood  criterion (less 1 per parameter)\n";
  for (const training::HysteresisCandidate& c : id.candidates) {
    t += fmt::format("  {:<16} {:10d}  {:14.2f}  {:10.2f}{}\n",
                     c.sharing == training::HysteresisSharing::none ? std::string("none")
                                                                    : fmt::format("{} K={}", sharing_key(c.sharing), c.operators),
                     c.parameters, c.log_marginal_likelihood, c.criterion,
                     c.sharing == id.sharing && c.operators == id.model.operators ? "  chosen" : "");
  }
  if (id.refinement_evaluations > 0) {
    t += fmt::format("  the chosen one refined with its own hyperparameters: {:+.2f} in log likelihood\n",
                     id.refinement_gain);
  }
  t += fmt::format("  cost: {} GP likelihoods with the hyperparameters held and {} hyperparameter searches, "
                   "besides the joints-only model's\n",
                   id.likelihood_evaluations, id.hyperparameter_searches);
  const model::HysteresisModel<double>& m = s.result.model.hysteresis;
  if (!m.empty()) {
    t += "  widths (mm) per cable:";
    // A bar before each segment's cables.
    const model::RobotGeometry<double>& geometry = s.result.model.geometry;
    for (int c = 0, segment = 0; c < m.cables; ++c) {
      if (segment < geometry.segment_count && c == geometry.first_cable(segment)) {
        t += " |";
        ++segment;
      }
      for (int k = 0; k < m.operators; ++k) t += fmt::format("{}{:.3f}", k == 0 ? " " : "/", m.widths_mm[c][k]);
    }
    t += "\n  weights:";
    for (int k = 0; k < m.operators; ++k) t += fmt::format(" {:.3f}", m.weights[0][k]);
    t += " (every cable)\n";
  }
  if (s.history.searched) {
    t += fmt::format("  where each cable last moved, as inputs: {} ({})\n", s.history.chosen ? "yes" : "no",
                     s.history.reason);
  }
  if (s.noise_variance_floor > 0.0) {
    t += fmt::format("  noise variance kept at {:.4g} or more (normalised) for the float32 image's fidelity\n",
                     s.noise_variance_floor);
  }
  if (s.joints_only_validation.samples > 0) {
    t += "held-out: hysteresis or not  position (mm)   orientation (deg)\n";
    t += fmt::format("  nominal model (commanded)  {:13.4f}   {:17.4f}\n", s.joints_only_validation.initial.position_mm,
                     s.joints_only_validation.initial.orientation_deg);
    t += fmt::format("  joints-only model          {:13.4f}   {:17.4f}\n",
                     s.joints_only_validation.compensated.position_mm,
                     s.joints_only_validation.compensated.orientation_deg);
    t += fmt::format("  with the hysteresis model  {:13.4f}   {:17.4f}\n", s.result.validation.compensated.position_mm,
                     s.result.validation.compensated.orientation_deg);
  }
  return t;
}

Json compliance_structure_json(const training::ComplianceCandidate& c) {
  if (c.none) return "none";
  return c.structure.name();
}

Json compliance_model_json(const training::ComplianceModel& m) {
  if (m.empty()) return nullptr;
  const Eigen::Vector3d direction = m.gravity_direction();
  return Json{{"weighted_gravity", std::vector<double>(m.weighted_gravity.data(), m.weighted_gravity.data() + 3)},
              {"gravity_direction", std::vector<double>(direction.data(), direction.data() + 3)},
              {"compliance_rad_per_n_mm", m.compliance_rad_per_n_mm(0)},
              {"ratios", m.ratio},
              {"softening_per_rad", m.softening_per_rad},
              {"unloaded_mass_kg", m.unloaded_mass_kg}};
}

Json compliance_json(const TrainRun& run) {
  if (run.payload == nullptr) return nullptr;
  const training::PayloadExport& p = *run.payload;
  const training::ComplianceChoice& choice = p.choice;
  Json j = identification_json(choice.attempted, choice.skipped_reason, p.uses_compliance());
  j["structure"] = p.uses_compliance() ? Json(choice.structure.name()) : Json("none");
  j["model"] = compliance_model_json(choice.model);
  Json candidates = Json::array();
  for (const training::ComplianceCandidate& c : choice.candidates) {
    candidates.push_back({{"structure", compliance_structure_json(c)},
                          {"parameters", c.parameters},
                          {"plausible", c.plausible},
                          {"log_marginal_likelihood", c.log_marginal_likelihood},
                          {"criterion", c.criterion}});
  }
  j["candidates"] = candidates;
  j["validation_nominal_unsagged"] =
      p.unsagged_validation.samples > 0 ? errors_json(p.unsagged_validation.initial) : Json(nullptr);
  return j;
}

std::string compliance_text(const TrainRun& run) {
  if (run.payload == nullptr) {
    return run.payload_input && !run.data_has_time
               ? "payload compliance: not identified (--no-compliance); payload-as-an-input model\n"
               : "";
  }
  const training::PayloadExport& p = *run.payload;
  const training::ComplianceChoice& choice = p.choice;
  if (!choice.attempted) {
    return fmt::format("payload compliance: not identified ({}); payload-as-an-input model\n", choice.skipped_reason);
  }
  std::string t = fmt::format("payload compliance chosen on the {} training rows: {}\n", run.train_rows,
                              p.uses_compliance() ? choice.structure.name() : std::string("none (no sag)"));
  t += "  structure                             parameters  log likelihood  criterion (less 1 per parameter)\n";
  for (const training::ComplianceCandidate& c : choice.candidates) {
    const bool chosen = c.none ? !p.uses_compliance()
                               : p.uses_compliance() && c.structure.per_segment == choice.structure.per_segment &&
                                     c.structure.softening == choice.structure.softening &&
                                     c.structure.unloaded_mass == choice.structure.unloaded_mass;
    t += fmt::format("  {:<37} {:10d}  {:14.2f}  {:10.2f}{}{}\n", c.none ? std::string("none") : c.structure.name(),
                     c.parameters, c.log_marginal_likelihood, c.criterion, c.plausible ? "" : "  (implausible)",
                     chosen ? "  chosen" : "");
  }
  if (p.uses_compliance()) {
    const training::ComplianceModel& m = choice.model;
    const Eigen::Vector3d g = m.gravity_direction();
    t += fmt::format("  gravity direction ({:.4f}, {:.4f}, {:.4f}); segment 1 compliance {:.4e} rad/(N mm)\n", g[0],
                     g[1], g[2], m.compliance_rad_per_n_mm(0));
    t += "  ratios c_i/c_1:";
    for (const double r : m.ratio) t += fmt::format(" {:.4f}", r);
    t += fmt::format("; softening {:.4f} per rad; unloaded mass {:.4f} kg\n", m.softening_per_rad,
                     m.unloaded_mass_kg);
    if (p.unsagged_validation.samples > 0) {
      t += fmt::format("  held-out nominal model without the sag: {:.4f} mm, {:.4f} deg\n",
                       p.unsagged_validation.initial.position_mm, p.unsagged_validation.initial.orientation_deg);
    }
  }
  return t;
}

// The radii's calibration and the extrapolation threshold the image
// carries, and the radii's coverage of the held-out samples.
Json uncertainty_json(const training::ExportResult& r) {
  const training::VarianceFactor& v = r.model.variance;
  if (v.rank() == 0) return nullptr;
  const training::CoverageCheck& c = r.validation_coverage;
  return {{"variance_points", v.rank()},
          {"calibration_rows", r.radius_calibration.rows},
          {"position_scale", v.position_scale},
          {"orientation_scale", v.orientation_scale},
          {"extrapolation_share", v.extrapolation_variance},
          {"validation_coverage", c.samples > 0 ? Json{{"r95_mm", c.position_coverage}, {"r95_deg", c.orientation_coverage}}
                                                : Json(nullptr)}};
}

std::string uncertainty_text(const training::ExportResult& r) {
  const training::VarianceFactor& v = r.model.variance;
  if (v.rank() == 0) return "";
  std::string t = fmt::format(
      "  r95 from {} variance points, calibrated on {} rows each held out: position x{:.3g}, orientation x{:.3g}\n"
      "  extrapolating above a latent share of {:.3g} (from the held-out rows' 99th percentile)\n",
      v.rank(), r.radius_calibration.rows, v.position_scale, v.orientation_scale, v.extrapolation_variance);
  const training::CoverageCheck& c = r.validation_coverage;
  if (c.samples > 0) {
    t += fmt::format("  r95 covers {:.1f} % of the held-out positions, {:.1f} % of the orientations (goal 95 %)\n",
                     100.0 * c.position_coverage, 100.0 * c.orientation_coverage);
  }
  return t;
}

}  // namespace

Json cable_inputs_json(const TrainRun& run) {
  Json j = {{"data_rows", run.data_rows},
            {"far_from_consistent_rows", run.far_from_consistent_rows},
            {"beyond_limit_rows", run.beyond_limit_rows}};
  if (run.cable_inputs == nullptr) {
    j["choice"] = nullptr;
    return j;
  }
  const training::CableInputChoice& c = *run.cable_inputs;
  j["choice"] = {{"encoding", model::to_string(c.encoding)},
                 {"searched", c.searched},
                 {"bend_only_log_likelihood", c.searched ? Json(c.bend_only_log_likelihood) : Json(nullptr)},
                 {"with_residuals_log_likelihood", c.searched ? Json(c.with_residuals_log_likelihood) : Json(nullptr)},
                 {"extra_parameters", c.extra_parameters},
                 {"search_rows", c.search_rows},
                 {"largest_residual_mm", c.largest_residual_mm},
                 {"reason", c.reason}};
  return j;
}

// Said only when the cables are not all consistent: data that are stay
// reported as they were.
std::string cable_inputs_text(const TrainRun& run) {
  std::string t;
  if (run.far_from_consistent_rows > 0 || run.beyond_limit_rows > 0) {
    t += fmt::format("  cable fit: {} of {} rows far from constant curvature (a residual over {} mm), {} beyond the "
                     "bend limit or the anchors' reach\n",
                     run.far_from_consistent_rows, run.data_rows, model::kFarFromConsistentMm, run.beyond_limit_rows);
  }
  if (run.cable_inputs != nullptr && (run.cable_inputs->searched || run.beyond_limit_rows > 0)) {
    t += fmt::format("  cable residuals as inputs: {} ({})\n",
                     model::takes_cable_residuals(run.cable_inputs->encoding) ? "yes" : "no",
                     run.cable_inputs->reason);
  }
  return t;
}

std::string train_report_json(const TrainRun& run) {
  const training::ExportResult& r = *run.result;
  const training::TrainedModel& m = r.model;
  Json j;
  j["training_samples"] = run.train_rows;
  j["validation_samples"] = run.validation_rows;
  j["fitted_rows"] = r.fitted_rows;
  const training::ModelSelection& selection = r.report.selection;
  j["model"] = {{"kind", training::to_string(selection.kind)},
                {"points", selection.points},
                {"largest_points", selection.largest_points},
                {"image_bytes", selection.image_bytes},
                {"forward_cycle_instructions_m7", selection.forward_cycle_instructions},
                {"reason", selection.reason}};
  j["search_rows"] = r.report.search_rows;
  if (run.calibration) {
    Json segments = Json::array();
    for (int i = 0; i < run.geometry.segment_count; ++i) {
      segments.push_back({{"backbone_length_mm", run.geometry.segments[i].backbone_length_mm},
                          {"anchor_radius_mm", run.geometry.segments[i].anchor_radius_mm}});
    }
    j["calibration"] = {{"segments", segments},
                        {"nominal_before", errors_json(run.calibration->before)},
                        {"nominal_after", errors_json(run.calibration->after)},
                        {"evaluations", run.calibration->evaluations}};
  } else {
    j["calibration"] = nullptr;
  }
  j["calibration_skipped"] = run.calibration_skipped.empty() ? Json(nullptr) : Json(run.calibration_skipped);
  j["encoding"] = model::to_string(m.encoding);
  j["cable_inputs"] = cable_inputs_json(run);
  j["payload_input"] = m.has_payload_input();
  j["default_payload_kg"] = m.has_payload_input() ? Json(m.default_payload_kg) : Json(nullptr);
  j["kernel"] = run.kernel;
  j["length_scales"] = std::vector<double>(m.length_scales.data(), m.length_scales.data() + m.length_scales.size());
  j["signal_variance"] = m.signal_variance[0];
  j["noise_variance"] = m.noise_variance[0];
  j["log_marginal_likelihood"] = r.report.log_marginal_likelihood;
  j["likelihood_evaluations"] = r.report.likelihood_evaluations;
  j["seconds"] = run.seconds;
  if (r.validation.samples > 0) {
    j["validation"] = {{"initial", errors_json(r.validation.initial)},
                       {"compensated", errors_json(r.validation.compensated)},
                       {"compensated_float32_image", errors_json(r.firmware.compensated)}};
  } else {
    j["validation"] = nullptr;
  }
  Json fidelity = Json::object();
  for (const auto& [accumulator, f] : r.fidelity_by_accumulator) {
    fidelity[training::to_string(accumulator)] = {{"max_position_mm", f.max_position_mm},
                                                  {"mean_position_mm", f.mean_position_mm},
                                                  {"max_orientation_deg", f.max_orientation_deg},
                                                  {"mean_orientation_deg", f.mean_orientation_deg},
                                                  {"target_met", training::ExportResult::meets_target(f)}};
  }
  j["float32_fidelity"] = fidelity;
  j["float32_fidelity_target_met"] = r.fidelity_met();
  j["uncertainty"] = uncertainty_json(r);
  if (run.data_has_time) j["hysteresis"] = hysteresis_json(run);
  // Only payload data have the key: every other report stays as it was.
  if (run.payload_input && !run.data_has_time) j["compliance"] = compliance_json(run);
  j["image"] = {{"path", run.out_path}, {"bytes", r.image.size()}};
  return j.dump() + "\n";
}

std::string train_report_text(const TrainRun& run) {
  const training::ExportResult& r = *run.result;
  const training::TrainedModel& m = r.model;
  std::string t;
  if (run.validation_rows > 0) {
    t += fmt::format("trained on {} samples, validated on {} held-out samples ({:.1f} s)\n", run.train_rows,
                     run.validation_rows, run.seconds);
  } else {
    t += fmt::format("trained on {} samples, none held out ({:.1f} s)\n", run.train_rows, run.seconds);
  }
  const training::ModelSelection& selection = r.report.selection;
  t += fmt::format("  model: {}\n", selection.reason);
  t += fmt::format("  image {} bytes (budget {}), Cortex-M7 forward cycle about {} instructions (budget {})\n",
                   selection.image_bytes, run.board.flash_budget_bytes, selection.forward_cycle_instructions,
                   run.board.forward_cycle_instructions);
  if (r.report.search_rows < run.train_rows) {
    t += fmt::format("  hyperparameters searched on {} of the {} rows\n", r.report.search_rows, run.train_rows);
  }
  if (run.calibration) {
    t += fmt::format("  geometry calibrated on the {} training rows: nominal model {:.3f} mm, {:.3f} deg -> {:.3f} mm, "
                     "{:.3f} deg\n    (L, r) per segment in mm:",
                     run.train_rows, run.calibration->before.position_mm, run.calibration->before.orientation_deg,
                     run.calibration->after.position_mm, run.calibration->after.orientation_deg);
    for (int i = 0; i < run.geometry.segment_count; ++i) {
      t += fmt::format(" ({:.2f}, {:.2f})", run.geometry.segments[i].backbone_length_mm,
                       run.geometry.segments[i].anchor_radius_mm);
    }
    t += "\n";
  } else if (!run.calibration_skipped.empty()) {
    t += fmt::format("  design geometry: not calibrated ({})\n", run.calibration_skipped);
  }
  t += cable_inputs_text(run);
  t += fmt::format("  encoding {}, kernel {} squared exponential, hyperparameters shared by the 6 outputs\n",
                   model::to_string(m.encoding), run.kernel);
  if (m.has_payload_input()) {
    t += fmt::format("  inputs: the bend vector and the payload (the last length scale; {:.3f} kg until the "
                     "runtime receives one)\n",
                     m.default_payload_kg);
  } else if (run.data_has_payload) {
    t += "  inputs: the bend vector; the payload_kg column is ignored (--ignore-payload)\n";
  }
  t += "  length scales (normalised inputs):";
  for (Eigen::Index i = 0; i < m.length_scales.size(); ++i) t += fmt::format(" {:.4g}", m.length_scales[i]);
  t += fmt::format("\n  signal variance {:.4g}, noise variance {:.4g} (normalised outputs)\n",
                   m.signal_variance[0], m.noise_variance[0]);
  t += fmt::format("  log marginal likelihood {:.6g} after {} evaluations\n", r.report.log_marginal_likelihood,
                   r.report.likelihood_evaluations);
  t += uncertainty_text(r);
  t += hysteresis_text(run);
  t += compliance_text(run);
  if (r.validation.samples > 0) {
    t += "held-out mean error          position (mm)   orientation (deg)\n";
    const bool effective = run.sequence != nullptr && run.sequence->uses_hysteresis();
    const bool sagged = run.payload != nullptr && run.payload->uses_compliance();
    t += fmt::format("  nominal model{}{:13.4f}   {:17.4f}\n",
                     effective ? " (effective)  " : sagged ? " (sagged)     " : "              ",
                     r.validation.initial.position_mm,
                     r.validation.initial.orientation_deg);
    t += fmt::format("  compensated (double)       {:13.4f}   {:17.4f}\n", r.validation.compensated.position_mm,
                     r.validation.compensated.orientation_deg);
    t += fmt::format("  compensated (float32 image){:13.4f}   {:17.4f}\n", r.firmware.compensated.position_mm,
                     r.firmware.compensated.orientation_deg);
  } else {
    t += "no held-out figures (--holdout 0): measure the image with cdcr eval on data collected apart\n";
  }
  if (run.validation_rows > 0 && run.validation_path.empty()) {
    t += fmt::format("exported model fitted on all {} rows, the held-out ones included\n", r.fitted_rows);
  }
  t += fmt::format("float32 fidelity on the {} (image path vs double trainer; target 0.01 mm, 0.001 deg):\n",
                   run.validation_rows > 0 ? "held-out samples" : "fitted rows");
  for (const auto& [accumulator, f] : r.fidelity_by_accumulator) {
    const bool firmware = accumulator != training::FirmwareAccumulator::float32;
    t += fmt::format("  {:<31} max {:.2e} mm, mean {:.2e} mm, max {:.2e} deg, mean {:.2e} deg: {}\n",
                     training::to_string(accumulator), f.max_position_mm, f.mean_position_mm,
                     f.max_orientation_deg, f.mean_orientation_deg,
                     firmware ? check_mark(training::ExportResult::meets_target(f)) : "(not used by firmware)");
  }
  t += fmt::format("wrote {} ({} bytes)\n", run.out_path, r.image.size());
  return t;
}

}  // namespace cdcr::cli
