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
            model_.cables == model.geometry.cable_count();
  if (!active_) model_ = model::HysteresisModel<Scalar>{};
  // The chord D (l3 - l1, l2 - l4 for the paper's cables) is at most
  // 4 r sin(theta_max / 2) (segment.hpp), a little less here so the
  // kinematics' rounding allowance is not needed.
  geometry_ = model.geometry;
  within_limit_ = !model::takes_cable_residuals(model.image.encoding);
  for (int s = 0; s < geometry_.segment_count; ++s) {
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
  for (int s = 0, first = 0; s < geometry_.segment_count; first += geometry_.segments[s].cables.count, ++s) {
    // The chord D shrinks to the limit; what the fit leaves beyond D (the
    // mean, the pairs' imbalance) stays: l_j = m - (D / 2) . e_j + rest.
    const model::CableLayout<Scalar>& layout = geometry_.segments[s].cables;
    Scalar* e = effective_mm_.data() + first;
    const auto cables = effective_mm_.segment(first, layout.count);
    const Scalar dx = model::layout_sum(layout.chord_x_weights, cables, layout.count);
    const Scalar dy = model::layout_sum(layout.chord_y_weights, cables, layout.count);
    const Scalar chord = std::hypot(dx, dy);
    const Scalar limit = chord_limit_mm_[s];
    if (!(chord > limit)) continue;
    const Scalar shrink = Scalar(0.5) * (Scalar(1) - limit / chord);
    for (int j = 0; j < layout.count; ++j) e[j] += shrink * (dx * layout.anchor_x[j] + dy * layout.anchor_y[j]);
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

// The bend of segment i follows its cables as (u, w) = D / (2 r s) with
// s = sinc(theta / 2) and D the layout's chord, sum_j W_j l_j (for the
// paper's cables (l3 - l1, l2 - l4); segment.hpp), so each bend
// coordinate's variance is that of a chord coordinate over (2 r s)^2, the
// chord's the largest its bound sum_j |W_j| u_j allows (the header says
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
  for (int s = 0, first = 0; s < geometry.segment_count; first += geometry.segments[s].cables.count, ++s) {
    const Scalar lever = Scalar(2) * geometry.segments[s].anchor_radius_mm *
                         model::series::sinc(Scalar(0.5) * estimate.joints[2 * s + 1]);
    const model::CableLayout<Scalar>& layout = geometry.segments[s].cables;
    const Scalar* u = uncertainty_mm_.data() + first;
    Scalar chord_bound[2] = {Scalar(0), Scalar(0)};
    for (int j = 0; j < layout.count; ++j) {
      chord_bound[0] += std::abs(layout.chord_x_weights[j]) * u[j];
      chord_bound[1] += std::abs(layout.chord_y_weights[j]) * u[j];
    }
    const Scalar bend_variance[2] = {chord_bound[0] * chord_bound[0] / (lever * lever),
                                     chord_bound[1] * chord_bound[1] / (lever * lever)};
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
