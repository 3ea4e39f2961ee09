#include "calibration.hpp"
#include "least_squares_functor.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include <unsupported/Eigen/NonLinearOptimization>
#include <unsupported/Eigen/NumericalDiff>

#include "cdcr/model/chain.hpp"
#include "cdcr/model/compensation.hpp"

namespace cdcr::training {

namespace {

// A row whose cables the candidate geometry cannot map to joints counts as
// this far off (mm), so the search turns back.
constexpr double kUnmappedResidual = 1e3;

// The parameters are ratios to the design's values: [L_1 .. L_n, r_1 .. r_n].
model::RobotGeometry<double> geometry_at(const model::RobotGeometry<double>& design, const Eigen::VectorXd& ratios) {
  model::RobotGeometry<double> g = design;
  for (int s = 0; s < design.segment_count; ++s) {
    g.segments[s].backbone_length_mm = design.segments[s].backbone_length_mm * ratios[s];
    g.segments[s].anchor_radius_mm = design.segments[s].anchor_radius_mm * ratios[design.segment_count + s];
  }
  return g;
}

// The nominal tip pose for commanded cables, or false when `g` cannot map
// them to joints.
bool nominal_pose(const TrainingSet& set, int row, const model::RobotGeometry<double>& g,
                  model::Pose<double>& pose) {
  const model::CableVector<double> cables = set.cables_mm.row(row).transpose();
  model::JointVector<double> joints;
  if (model::joints_from_cables(cables, g, joints) != model::Status::ok) return false;
  pose = model::forward_kinematics_bend(model::bend_from_joints(joints), g);
  return true;
}

struct TwistResiduals : DynamicSizeResiduals {
  const TrainingSet* set = nullptr;
  model::RobotGeometry<double> design;
  double rotation_weight_mm = 1.0;
  int* evaluations = nullptr;

  int inputs() const { return 2 * design.segment_count; }
  int values() const { return 6 * set->size(); }

  int operator()(const Eigen::VectorXd& ratios, Eigen::VectorXd& residuals) const {
    ++*evaluations;
    const model::RobotGeometry<double> g = geometry_at(design, ratios);
    residuals.resize(values());
    const bool valid = g.validate() == model::Status::ok;
    for (int i = 0; i < set->size(); ++i) {
      model::Pose<double> nominal;
      if (!valid || !nominal_pose(*set, i, g, nominal)) {
        residuals.segment<6>(6 * i).setConstant(kUnmappedResidual);
        continue;
      }
      const model::Twist<double> twist = model::tip_error_twist(set->measured[i], nominal);
      residuals.segment<3>(6 * i) = twist.head<3>();
      residuals.segment<3>(6 * i + 3) = rotation_weight_mm * twist.tail<3>();
    }
    return 0;
  }
};

std::vector<model::Pose<double>> nominal_poses(const TrainingSet& set, const model::RobotGeometry<double>& g) {
  std::vector<model::Pose<double>> poses;
  for (int i = 0; i < set.size(); ++i) {
    model::Pose<double> pose;
    if (!nominal_pose(set, i, g, pose)) {
      throw std::invalid_argument("the calibrated geometry rejects the cables of sample " + std::to_string(i + 1));
    }
    poses.push_back(pose);
  }
  return poses;
}

}  // namespace

Calibration calibrate_geometry(const TrainingSet& set, const model::RobotGeometry<double>& design) {
  const int parameters = 2 * design.segment_count;
  if (set.size() < 2 * parameters) {
    throw std::invalid_argument("calibration needs at least " + std::to_string(2 * parameters) + " samples, got " +
                                std::to_string(set.size()));
  }
  Calibration c;
  TwistResiduals residuals;
  residuals.set = &set;
  residuals.design = design;
  for (int s = 0; s < design.segment_count; ++s) residuals.rotation_weight_mm += design.segments[s].backbone_length_mm;
  residuals.evaluations = &c.evaluations;

  Eigen::VectorXd ratios = Eigen::VectorXd::Ones(parameters);
  Eigen::NumericalDiff<TwistResiduals> differentiated(residuals);
  Eigen::LevenbergMarquardt<Eigen::NumericalDiff<TwistResiduals>> solver(differentiated);
  solver.parameters.maxfev = 100 * (parameters + 1);
  solver.minimize(ratios);
  if (!ratios.allFinite() || (ratios.array() < 0.5).any() || (ratios.array() > 2.0).any()) {
    throw std::invalid_argument("the geometry calibration left the plausible range (within 2x of the design)");
  }
  c.geometry = geometry_at(design, ratios);
  c.before = mean_errors(set.measured, set.nominal);
  c.after = mean_errors(set.measured, nominal_poses(set, c.geometry));
  return c;
}

}  // namespace cdcr::training
