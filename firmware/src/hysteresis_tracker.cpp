#include "cdcr/firmware/hysteresis_tracker.hpp"

#include <cmath>

#include "cdcr/model/chain.hpp"
#include "cdcr/model/image_hysteresis.hpp"
#include "cdcr/model/input_encoding.hpp"
#include "cdcr/model/series.hpp"
#include "cdcr/model/units.hpp"

namespace cdcr::firmware {

namespace {

void add_outer(Scalar (&covariance)[6], const model::Vec3<Scalar>& v, Scalar variance) {
  covariance[0] += variance * v.x() * v.x();
  covariance[1] += variance * v.y() * v.y();
  covariance[2] += variance * v.z() * v.z();
  covariance[3] += variance * v.x() * v.y();
  covariance[4] += variance * v.x() * v.z();
  covariance[5] += variance * v.y() * v.z();
}

}  // namespace

void HysteresisTracker::bind(const RobotModel& model) {
  active_ = model.compensated && model::hysteresis_from_image(model.image, model_) &&
            model_.cables == 4 * model.geometry.segment_count;
  if (!active_) model_ = model::HysteresisModel<Scalar>{};
  // l3 - l1 and l2 - l4 span a chord of at most 4 r sin(theta_max / 2)
  // (segment.hpp), a little less here so the kinematics' rounding allowance
  // is not needed.
  segments_ = model.geometry.segment_count;
  within_limit_ = !model::takes_cable_residuals(model.image.encoding);
  for (int s = 0; s < segments_; ++s) {
    chord_limit_mm_[s] = Scalar(4) * model.geometry.segments[s].anchor_radius_mm *
                         std::sin(Scalar(0.5) * model.geometry.segments[s].theta_max_rad) * Scalar(0.999999);
  }
  model::reset_unknown(state_, model_);
  known_ = state_.known();
  widening_ = false;
  uncertainty_mm_.setZero(model_.cables);
}

const Cables& HysteresisTracker::track(const Cables& commanded_mm) {
  if (!active_ || !commanded_mm.allFinite()) return commanded_mm;
  model::update_hysteresis(state_, model_, commanded_mm);
  // The lag intervals only shrink: once known, the state stays known.
  if (!known_) known_ = state_.known();
  model::effective_lengths(state_, model_, effective_mm_, &uncertainty_mm_);
  if (!within_limit_) return effective_mm_;
  for (int s = 0; s < segments_; ++s) {
    // The means of the two pairs stay.
    Scalar* e = effective_mm_.data() + 4 * s;
    const Scalar limit = chord_limit_mm_[s];
    const Scalar chord = std::hypot(e[2] - e[0], e[1] - e[3]);
    if (!(chord > limit)) continue;
    const Scalar scale = limit / chord;
    const Scalar mean_13 = Scalar(0.5) * (e[0] + e[2]), half_31 = Scalar(0.5) * scale * (e[2] - e[0]);
    const Scalar mean_24 = Scalar(0.5) * (e[1] + e[3]), half_24 = Scalar(0.5) * scale * (e[1] - e[3]);
    e[0] = mean_13 - half_31;
    e[2] = mean_13 + half_31;
    e[1] = mean_24 + half_24;
    e[3] = mean_24 - half_24;
  }
  return effective_mm_;
}

void HysteresisTracker::homed(const Geometry& geometry) {
  if (!active_ || model::start_at_home(state_, model_, geometry) != model::Status::ok) return;
  known_ = state_.known();
  uncertainty_mm_.setZero(model_.cables);
}

void HysteresisTracker::hold_history(Correction& correction) const {
  if (!active_ || !correction.takes_history()) return;
  Scalar history[model::kMaxCables];
  model::history_inputs(state_, model_, history);
  correction.set_history_inputs(history);
}

void HysteresisTracker::commanded_for(Cables& cables_mm) const {
  if (!active_ || !state_.has_position) return;
  for (int c = 0; c < model_.cables; ++c) cables_mm[c] = model::commanded_for_effective(state_, model_, c, cables_mm[c]);
}

// The bend of segment i follows its cables as u = (l3 - l1) / (2 r s),
// w = (l2 - l4) / (2 r s) with s = sinc(theta / 2) (segment.hpp), so each
// bend coordinate's variance is that of a cable difference over (2 r s)^2,
// the difference's the largest its bound u_a + u_b allows (the header says
// why); the spatial Jacobian in the bend moves the tip position p by
// v + omega x p.
void HysteresisTracker::begin_variance(const RobotModel& model, const PoseEstimate& estimate) {
  widening_ = active_ && !known_;
  if (!widening_) return;
  const Geometry& geometry = model.geometry;
  const Joints bend = model::bend_from_joints(estimate.joints);
  model::Pose<Scalar> tip;
  model::Jacobian<Scalar, kMaxSegments> jacobian;
  model::tip_jacobian_bend(bend, geometry, tip, jacobian);
  for (int i = 0; i < 6; ++i) position_covariance_[i] = orientation_covariance_[i] = Scalar(0);
  for (int s = 0; s < geometry.segment_count; ++s) {
    const Scalar lever = Scalar(2) * geometry.segments[s].anchor_radius_mm *
                         model::series::sinc(Scalar(0.5) * estimate.joints[2 * s + 1]);
    const Scalar* u = uncertainty_mm_.data() + 4 * s;
    const Scalar bend_variance[2] = {(u[0] + u[2]) * (u[0] + u[2]) / (lever * lever),
                                     (u[1] + u[3]) * (u[1] + u[3]) / (lever * lever)};
    for (int k = 0; k < 2; ++k) {
      const model::Vec3<Scalar> v = jacobian.col(2 * s + k).head<3>();
      const model::Vec3<Scalar> omega = jacobian.col(2 * s + k).tail<3>();
      add_outer(position_covariance_, v + omega.cross(tip.position_mm), bend_variance[k]);
      add_outer(orientation_covariance_, omega, bend_variance[k]);
    }
  }
  tip_mm_ = estimate.pose.position_mm;
}

// The GP's covariance as model::GpUncertainty forms it (from its latent
// share and the image's scales and calibration), plus the one kept.
void HysteresisTracker::widen(const RobotModel& model, model::PoseUncertainty<Scalar>& radii) const {
  const model::ImageView& image = model.image;
  if (!widening_ || image.variance_calibration == nullptr) return;
  const Scalar normalised = Scalar(image.signal_variance[0]) * radii.latent_share + Scalar(image.noise_variance[0]);
  Scalar v[6];
  for (int k = 0; k < 6; ++k) v[k] = Scalar(image.output_scale[k]) * Scalar(image.output_scale[k]) * normalised;
  const Scalar ps = Scalar(image.variance_calibration[model::image_variance_field::position_scale]);
  const Scalar os = Scalar(image.variance_calibration[model::image_variance_field::orientation_scale]);
  const Scalar ps2 = ps * ps;
  const Scalar os2 = os * os;
  // The GP's covariance, as gaussian_radii_95 forms it, calibrated; the
  // unknown state's added on top.
  model::SymmetricCovariance3<Scalar> position, orientation = {};
  model::tip_position_covariance(v, tip_mm_, position);
  for (int i = 0; i < 6; ++i) position[i] = ps2 * position[i] + position_covariance_[i];
  for (int i = 0; i < 3; ++i) orientation[i] = os2 * v[3 + i];
  for (int i = 0; i < 6; ++i) orientation[i] += orientation_covariance_[i];
  radii.r95_mm = model::gaussian_radius_95(position);
  radii.r95_deg = model::gaussian_radius_95(orientation) * Scalar(model::kDegreesPerRadian);
}

}  // namespace cdcr::firmware
