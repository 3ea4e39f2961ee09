#pragma once
// The segments' compliance under a tip payload, identified from the measured
// poses before the GP sees them, so that the GP learns only what the sag
// cannot explain (issue 25, "the payload's load").
//
// The nominal model with sag: each segment bends further by the moment of the
// tip load's weight about its base, times the segment's compliance,
//   b_i' = b_i + c_i (1 + s |b_i|) (m_y, -m_x),
//   m = R_i^T (m_tip (p_tip - p_i) x g),   m_tip = payload + m_0,
// in the segment's base frame R_i, p_i of the sagged shape (the fixed point,
// found by Newton steps from the nominal shape: the sag moves its own lever
// arms). g is the weight of a kilogram (9.81 N) in an identified direction, c_i the
// compliance (rad per N mm), s a softening with the segment's own bend and
// m_0 an unloaded tip mass, which stands for the end platform's and the
// segments' own weight (they sag the robot without payload the same way,
// and left out they pull the identified direction towards their sag).
//
// Identified by Levenberg-Marquardt (Eigen's) on the tip error twists, the
// rotation weighted by the robot's length as in calibration.hpp, less their
// projection on smooth functions of the bends alone (1, b, b_j b_k) when
// there are rows enough: the errors that do not depend on the payload (the
// geometry's, the robot's own sag) would otherwise pull the identified
// direction and compliances towards themselves, while the payload, drawn
// independently of the configuration, keeps its sag out of that span. The
// structure (which of the parameters beyond g c_0 are free) and whether the
// sag is used at all are chosen by the GP's log marginal likelihood less one
// per parameter (Akaike's criterion, as hysteresis_identification.hpp does),
// with the hyperparameters searched again for every candidate.
//
// Data without a payload column is not identified: its training set is the
// one it always was.
//
// The sag itself is the model library's (model/include/cdcr/model/
// payload_compliance.hpp), the one the board runs; `cdcr train` on payload
// data ships the chosen model in the image's compliance block
// (pipeline/train_and_export.hpp).

#include <string>
#include <vector>

#include <Eigen/Core>

#include "cdcr/model/geometry.hpp"
#include "cdcr/model/payload_compliance.hpp"
#include "cdcr/model/se3.hpp"
#include "trainer.hpp"
#include "training_set.hpp"

namespace cdcr::training {

inline constexpr double kStandardGravityM_per_s2 = 9.81;

// Which parameters besides the weight vector times segment 0's compliance (3)
// are identified.
struct ComplianceStructure {
  bool per_segment = false;    // the other segments' compliances, as ratios to segment 0's (n - 1)
  bool softening = false;      // s (1)
  bool unloaded_mass = false;  // m_0 (1)

  int parameter_count(int segments) const;
  std::string name() const;
};

struct ComplianceModel {
  // g c_0: the weight of one kilogram times segment 0's compliance, in the
  // base frame (rad per kg mm of lever arm). Zero: no sag (the empty model).
  Eigen::Vector3d weighted_gravity = Eigen::Vector3d::Zero();
  std::vector<double> ratio;  // c_i / c_0 per segment (empty: all 1)
  double softening_per_rad = 0.0;
  double unloaded_mass_kg = 0.0;

  bool empty() const { return weighted_gravity.isZero(0.0); }
  Eigen::Vector3d gravity_direction() const { return weighted_gravity.normalized(); }
  double compliance_rad_per_n_mm(int segment) const;
  // The model library's form for a robot of `segments` segments (empty for
  // the empty model).
  model::PayloadCompliance<double> for_model(int segments) const;
};

// The stacked bend vectors with the sag of a tip load of payload_kg (plus the
// model's m_0); the bends themselves for the empty model.
Eigen::VectorXd sagged_bends(const Eigen::VectorXd& bends, const model::RobotGeometry<double>& geometry,
                             double payload_kg, const ComplianceModel& compliance);

// The nominal tip pose of stacked bends with that sag.
model::Pose<double> sagged_pose(const Eigen::VectorXd& bends, const model::RobotGeometry<double>& geometry,
                                double payload_kg, const ComplianceModel& compliance);

// The set with its nominal poses and error twists those of the sagged model
// (inputs, bends and payload unchanged). The empty model returns the set as
// it is. Throws std::invalid_argument for a set without payload and a model
// that is not empty.
TrainingSet with_compliance(const TrainingSet& set, const model::RobotGeometry<double>& geometry,
                            const ComplianceModel& compliance);

// Levenberg-Marquardt from no sag. Throws std::invalid_argument for a set
// without payload, fewer rows than twice the parameters, or a result that is
// not finite.
ComplianceModel identify_compliance(const TrainingSet& set, const model::RobotGeometry<double>& geometry,
                                    const ComplianceStructure& structure);

struct ComplianceCandidate {
  bool none = true;  // the payload model without sag (today's)
  ComplianceStructure structure;
  ComplianceModel model;
  int parameters = 0;
  // A compliance ratio not above zero, a negative unloaded mass or a
  // softening that turns the compliance negative within a quarter turn:
  // reported, never chosen.
  bool plausible = true;
  // The GP's, in the outputs' own units (the normalised likelihood less
  // rows * sum of the log output scales), so candidates with different
  // residuals compare; criterion = log_marginal_likelihood - parameters.
  double log_marginal_likelihood = 0.0;
  double criterion = 0.0;
};

struct ComplianceChoice {
  bool attempted = false;
  std::string skipped_reason;
  ComplianceModel model;  // the winner's; empty when "none" wins
  ComplianceStructure structure;
  std::vector<ComplianceCandidate> candidates;  // "none" first
};

// The structures tried by choose_compliance: every combination of the three
// switches.
std::vector<ComplianceStructure> compliance_structures();

// Identifies every structure on `set` (the training rows) and ranks them and
// "none" by the criterion above (implausible candidates are not chosen), each with its own hyperparameter search
// (train() with `options`). A set without payload is skipped with the reason.
ComplianceChoice choose_compliance(const TrainingSet& set, const model::RobotGeometry<double>& geometry,
                                   const TrainingOptions& options,
                                   const std::vector<ComplianceStructure>& structures = compliance_structures());

}  // namespace cdcr::training
