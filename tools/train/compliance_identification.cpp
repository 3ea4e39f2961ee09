#include "compliance_identification.hpp"
#include "least_squares_functor.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/QR>
#include <unsupported/Eigen/NonLinearOptimization>
#include <unsupported/Eigen/NumericalDiff>

#include "cdcr/model/chain.hpp"
#include "cdcr/model/compensation.hpp"
#include "cdcr/model/segment.hpp"

namespace cdcr::training {

namespace {

// The background (see background_basis) is projected out of the residuals
// only with at least this many rows per column of it (180 for 4 segments).
constexpr int kBackgroundRowsPerColumn = 4;

ComplianceModel compliance_at(const ComplianceStructure& s, int segments, const Eigen::VectorXd& p) {
  ComplianceModel c;
  c.weighted_gravity = p.head<3>();
  c.ratio.assign(static_cast<std::size_t>(segments), 1.0);
  int next = 3;
  if (s.per_segment) {
    for (int i = 1; i < segments; ++i) c.ratio[static_cast<std::size_t>(i)] = p[next++];
  }
  if (s.softening) c.softening_per_rad = p[next++];
  if (s.unloaded_mass) c.unloaded_mass_kg = p[next++];
  return c;
}

struct SagResiduals : DynamicSizeResiduals {
  const TrainingSet* set = nullptr;
  model::RobotGeometry<double> geometry;
  ComplianceStructure structure;
  double rotation_weight_mm = 1.0;
  // Orthonormal columns spanning the background features of the rows (see
  // background_basis); empty: none.
  Eigen::MatrixXd background;

  int inputs() const { return structure.parameter_count(geometry.segment_count); }
  int values() const { return 6 * set->size(); }

  int operator()(const Eigen::VectorXd& p, Eigen::VectorXd& residuals) const {
    const ComplianceModel c = compliance_at(structure, geometry.segment_count, p);
    residuals.resize(values());
    for (int i = 0; i < set->size(); ++i) {
      const model::Pose<double> nominal = sagged_pose(set->bends.row(i).transpose(), geometry, set->payload_kg[i], c);
      const model::Twist<double> twist = model::tip_error_twist(set->measured[static_cast<std::size_t>(i)], nominal);
      residuals.segment<3>(6 * i) = twist.head<3>();
      residuals.segment<3>(6 * i + 3) = rotation_weight_mm * twist.tail<3>();
    }
    if (background.cols() > 0) {
      Eigen::Map<Eigen::Matrix<double, 6, Eigen::Dynamic>> by_row(residuals.data(), 6, set->size());
      by_row -= (by_row * background) * background.transpose();
    }
    return 0;
  }
};

// The errors that do not depend on the payload (the geometry's, the robot's
// own sag) are smooth in the bends; left in the residuals they pull the
// identified direction and compliances towards themselves. The payload is
// drawn independently of the configuration, so its sag is nearly orthogonal
// to functions of the bends alone: the fit sees the residuals less their
// least-squares projection on 1, b and the products b_j b_k.
Eigen::Index background_columns(const TrainingSet& set) {
  const Eigen::Index n = set.bends.cols();
  return 1 + n + n * (n + 1) / 2;
}

Eigen::MatrixXd background_basis(const TrainingSet& set) {
  const Eigen::Index n = set.bends.cols();
  Eigen::MatrixXd features(set.size(), 1 + n + n * (n + 1) / 2);
  features.col(0).setOnes();
  features.middleCols(1, n) = set.bends;
  Eigen::Index column = 1 + n;
  for (Eigen::Index j = 0; j < n; ++j) {
    for (Eigen::Index k = j; k < n; ++k) features.col(column++) = set.bends.col(j).cwiseProduct(set.bends.col(k));
  }
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(features);
  return qr.householderQ() * Eigen::MatrixXd::Identity(set.size(), features.cols());
}

}  // namespace

int ComplianceStructure::parameter_count(int segments) const {
  return 3 + (per_segment ? segments - 1 : 0) + (softening ? 1 : 0) + (unloaded_mass ? 1 : 0);
}

std::string ComplianceStructure::name() const {
  std::string name = per_segment ? "per segment" : "shared";
  if (softening) name += ", softening";
  if (unloaded_mass) name += ", unloaded mass";
  return name;
}

double ComplianceModel::compliance_rad_per_n_mm(int segment) const {
  const double r = ratio.empty() ? 1.0 : ratio[static_cast<std::size_t>(segment)];
  return r * weighted_gravity.norm() / kStandardGravityM_per_s2;
}

model::PayloadCompliance<double> ComplianceModel::for_model(int segments) const {
  model::PayloadCompliance<double> c;
  if (empty()) return c;
  c.segments = segments;
  c.weighted_gravity = weighted_gravity;
  for (int i = 0; i < segments && !ratio.empty(); ++i) c.ratio[static_cast<std::size_t>(i)] = ratio[static_cast<std::size_t>(i)];
  c.softening_per_rad = softening_per_rad;
  c.unloaded_mass_kg = unloaded_mass_kg;
  return c;
}

Eigen::VectorXd sagged_bends(const Eigen::VectorXd& bends, const model::RobotGeometry<double>& geometry,
                             double payload_kg, const ComplianceModel& compliance) {
  const model::JointVector<double> commanded = bends;
  return model::sagged_bends(commanded, geometry, payload_kg, compliance.for_model(geometry.segment_count));
}

model::Pose<double> sagged_pose(const Eigen::VectorXd& bends, const model::RobotGeometry<double>& geometry,
                                double payload_kg, const ComplianceModel& compliance) {
  const model::JointVector<double> commanded = bends;
  return model::sagged_pose(commanded, geometry, payload_kg, compliance.for_model(geometry.segment_count));
}

TrainingSet with_compliance(const TrainingSet& set, const model::RobotGeometry<double>& geometry,
                            const ComplianceModel& compliance) {
  if (compliance.empty()) return set;
  if (!set.has_payload()) throw std::invalid_argument("a compliance model needs rows with a payload_kg column");
  TrainingSet sagged = set;
  for (int i = 0; i < set.size(); ++i) {
    const auto row = static_cast<std::size_t>(i);
    sagged.nominal[row] = sagged_pose(set.bends.row(i).transpose(), geometry, set.payload_kg[i], compliance);
    sagged.error_twists.row(i) = model::tip_error_twist(set.measured[row], sagged.nominal[row]).transpose();
  }
  return sagged;
}

ComplianceModel identify_compliance(const TrainingSet& set, const model::RobotGeometry<double>& geometry,
                                    const ComplianceStructure& structure) {
  if (!set.has_payload()) throw std::invalid_argument("compliance identification needs a payload_kg column");
  const int parameters = structure.parameter_count(geometry.segment_count);
  if (set.size() < 2 * parameters) {
    throw std::invalid_argument("compliance identification needs at least " + std::to_string(2 * parameters) +
                                " samples, got " + std::to_string(set.size()));
  }
  SagResiduals residuals;
  residuals.set = &set;
  residuals.geometry = geometry;
  residuals.structure = structure;
  for (int s = 0; s < geometry.segment_count; ++s) residuals.rotation_weight_mm += geometry.segments[s].backbone_length_mm;
  // Too few rows to spare the background's columns: the residuals as they are.
  if (set.size() >= kBackgroundRowsPerColumn * background_columns(set)) {
    residuals.background = background_basis(set);
  }
  // From no sag; the ratios from equal compliances (at zero weight their
  // gradients vanish, so they must not start at zero too).
  Eigen::VectorXd p = Eigen::VectorXd::Zero(parameters);
  if (structure.per_segment) p.segment(3, geometry.segment_count - 1).setOnes();
  Eigen::NumericalDiff<SagResiduals> differentiated(residuals);
  Eigen::LevenbergMarquardt<Eigen::NumericalDiff<SagResiduals>> solver(differentiated);
  solver.parameters.maxfev = 100 * (parameters + 1);
  solver.minimize(p);
  if (!p.allFinite()) throw std::invalid_argument("the compliance identification did not converge");
  return compliance_at(structure, geometry.segment_count, p);
}

std::vector<ComplianceStructure> compliance_structures() {
  std::vector<ComplianceStructure> structures;
  for (int variant = 0; variant < 8; ++variant) {
    ComplianceStructure s;
    s.per_segment = (variant & 1) != 0;
    s.softening = (variant & 2) != 0;
    s.unloaded_mass = (variant & 4) != 0;
    structures.push_back(s);
  }
  return structures;
}

namespace {

// The likelihood of the candidate's residuals in their own units: the search
// works on outputs divided by their scale, whose Jacobian is the product of
// the scales over every row the search saw.
double likelihood_in_output_units(const TrainingSet& set, const model::RobotGeometry<double>& geometry,
                                  const TrainingOptions& options) {
  TrainingReport report;
  const TrainedModel m = train(set, geometry, options, &report);
  return report.log_marginal_likelihood - double(report.search_rows) * m.output_scale.array().log().sum();
}

// A segment that bends against the load, or a tip that weighs less than
// nothing, is not a stiffness: the fit has traded the sag for other errors.
bool plausible(const ComplianceModel& m) {
  for (const double r : m.ratio) {
    if (!(r > 0.0)) return false;
  }
  return m.unloaded_mass_kg >= 0.0 && model::plausible_softening(m.softening_per_rad);
}

}  // namespace

ComplianceChoice choose_compliance(const TrainingSet& set, const model::RobotGeometry<double>& geometry,
                                   const TrainingOptions& options, const std::vector<ComplianceStructure>& structures) {
  ComplianceChoice choice;
  if (!set.has_payload()) {
    choice.skipped_reason = "the data have no payload_kg column";
    return choice;
  }
  int most_parameters = 0;
  for (const ComplianceStructure& s : structures) {
    most_parameters = std::max(most_parameters, s.parameter_count(geometry.segment_count));
  }
  if (set.size() < 2 * most_parameters) {
    choice.skipped_reason = "fewer than " + std::to_string(2 * most_parameters) + " training rows";
    return choice;
  }
  choice.attempted = true;
  ComplianceCandidate none;
  none.log_marginal_likelihood = likelihood_in_output_units(set, geometry, options);
  none.criterion = none.log_marginal_likelihood;
  choice.candidates.push_back(none);
  for (const ComplianceStructure& s : structures) {
    ComplianceCandidate c;
    c.none = false;
    c.structure = s;
    c.parameters = s.parameter_count(geometry.segment_count);
    c.model = identify_compliance(set, geometry, s);
    c.plausible = plausible(c.model);
    c.log_marginal_likelihood = likelihood_in_output_units(with_compliance(set, geometry, c.model), geometry, options);
    c.criterion = c.log_marginal_likelihood - double(c.parameters);
    choice.candidates.push_back(c);
  }
  const ComplianceCandidate* best = &choice.candidates.front();
  for (const ComplianceCandidate& c : choice.candidates) {
    if (c.plausible && c.criterion > best->criterion) best = &c;
  }
  choice.model = best->model;
  choice.structure = best->structure;
  return choice;
}

}  // namespace cdcr::training
