#pragma once
// How far the measured tip may lie from the compensated pose, and whether a
// query lies outside what the model was fitted on: the predictive variance
// of flash image v2.1 (model/flash-image-v2.md, "Variance").
//
// The GP's latent variance at a query, as a share of the signal variance s,
// is the variational (VFE) posterior's on R variance points u, fitted on
// every data row:
//   share(z) = 1 - |a|^2 + |L_c^-1 a|^2,  a = L_u^-1 r,  r_j = exp(-|z - u_j|^2 / 2),
// L_u = chol(R_uu), L_c = chol(I + (s / n) L_u^-1 R_uf R_fu L_u^-T), with R
// the kernel without its amplitude. With the variance points at the data
// rows this is the exact GP's variance. Per query it costs R kernel values
// and two triangular solves: R (R + 1) multiply-adds and 2 R divisions. The
// solves, not a stored inverse, keep float rounding bounded when the
// variance points are close together and R_uu is ill-conditioned.
//
// Output k's predictive variance, the measurement noise n the model learned
// included, is output_scale_k^2 (s share + n). A twist perturbation (dv,
// domega) moves the compensated tip by dv + domega x p, so the tip's
// covariance is S_v + [p]x S_omega [p]x^T; the outputs are independent GPs.
// The radius holding 95 % of a zero-mean Gaussian with covariance S comes
// from tr S and tr S^2: a scaled chi-square with the same two moments
// (Patnaik), its quantile by Wilson and Hilferty's cube root; it is within
// 3 % of the exact radius for every shape of S. The image's calibration
// scales the radii (the trainer measures it on held-out rows).

#include <cmath>
#include <cstdint>

#include "cdcr/model/flash_image.hpp"
#include "cdcr/model/kernel_exp.hpp"
#include "cdcr/model/limits.hpp"
#include "cdcr/model/status.hpp"
#include "cdcr/model/types.hpp"
#include "cdcr/model/units.hpp"

namespace cdcr::model {

template <typename S>
struct PoseUncertainty {
  S r95_mm = S(0);
  S r95_deg = S(0);
  S latent_share = S(0);       // latent variance / signal variance, 0 (known) to 1 (prior)
  bool outside_range = false;  // some input beyond the range of the rows the model was fitted on
  bool extrapolating = false;  // latent_share above the image's threshold, or (before 2.6) outside_range
};

// The radius of the ball around 0 that holds 95 % of N(0, S), from
// trace = tr S and trace_of_square = tr S^2 of the 3 x 3 covariance S.
template <typename S>
S gaussian_radius_95(S trace, S trace_of_square) {
  if (!(trace > S(0)) || !(trace_of_square > S(0))) return S(0);
  const S scale = trace_of_square / trace;             // c in c chi^2_nu
  const S dof = trace * trace / trace_of_square;       // nu, 1 to 3
  const S h = S(2) / (S(9) * dof);
  const S cube_root = S(1) - h + S(1.6448536) * std::sqrt(h);  // z_0.95
  return std::sqrt(scale * dof * cube_root * cube_root * cube_root);
}

// A symmetric 3 x 3 covariance as xx, yy, zz, xy, xz, yz.
template <typename S>
using SymmetricCovariance3 = S[6];

// The radius of gaussian_radius_95 for a covariance given as above.
template <typename S>
S gaussian_radius_95(const SymmetricCovariance3<S>& c) {
  const S trace = c[0] + c[1] + c[2];
  const S trace_of_square = c[0] * c[0] + c[1] * c[1] + c[2] * c[2] + S(2) * (c[3] * c[3] + c[4] * c[4] + c[5] * c[5]);
  return gaussian_radius_95(trace, trace_of_square);
}

// The tip position's covariance for independent error-twist variances
// (v in mm^2, then omega in rad^2) at tip_mm: S_p = diag(v) + P diag(w) P^T
// with P = [p]x.
template <typename S>
void tip_position_covariance(const S (&variances)[kImageOutputs], const Vec3<S>& tip_mm, SymmetricCovariance3<S>& c) {
  const S* v = variances;
  const S* w = variances + 3;
  const S px = tip_mm.x();
  const S py = tip_mm.y();
  const S pz = tip_mm.z();
  c[0] = v[0] + w[1] * pz * pz + w[2] * py * py;
  c[1] = v[1] + w[0] * pz * pz + w[2] * px * px;
  c[2] = v[2] + w[0] * py * py + w[1] * px * px;
  c[3] = -w[2] * px * py;
  c[4] = -w[1] * px * pz;
  c[5] = -w[0] * py * pz;
}

// The uncalibrated radii (mm, deg) for independent error-twist variances
// (v in mm^2, then omega in rad^2) at a compensated tip position.
template <typename S>
void gaussian_radii_95(const S (&variances)[kImageOutputs], const Vec3<S>& tip_mm, S& r95_mm, S& r95_deg) {
  const S* w = variances + 3;
  SymmetricCovariance3<S> position;
  tip_position_covariance(variances, tip_mm, position);
  r95_mm = gaussian_radius_95(position);
  r95_deg = gaussian_radius_95(w[0] + w[1] + w[2], w[0] * w[0] + w[1] * w[1] + w[2] * w[2]) * S(kDegreesPerRadian);
}

template <typename S, int MaxInputs = kMaxInputs>
class GpUncertainty {
 public:
  static constexpr int kMaxRank = static_cast<int>(kMaxVarianceRank);

  // Takes a view from parse_image(); the image bytes must outlive this
  // object. An image without a variance block (v1, v2.0) still gives the
  // range check, where it has ranges; its radii stay 0.
  Status bind(const ImageView& image) {
    if (image.input_dims < 1 || image.input_dims > MaxInputs ||
        image.variance_rank > static_cast<std::uint32_t>(kMaxRank)) {
      return Status::correction_failed;
    }
    dims_ = image.input_dims;
    has_range_ = image.input_min != nullptr && image.input_max != nullptr;
    for (int d = 0; d < dims_; ++d) {
      // Kernel coordinates grow with x (the gain is positive), so the range
      // maps bound to bound.
      const S gain = S(1) / (S(image.input_scale[d]) * S(image.length_scale[d]));
      if (has_range_) {
        range_min_[d] = (S(image.input_min[d]) - S(image.input_mean[d])) * gain;
        range_max_[d] = (S(image.input_max[d]) - S(image.input_mean[d])) * gain;
      }
    }
    rank_ = static_cast<int>(image.variance_rank);
    // A box around the fitted rows is too tight where the inputs spread
    // with the cables' state (the hysteresis' lag, the history): rows that
    // repeat a visited command fall just outside it. From 2.6 the latent
    // share, the data's density in the kernel's own metric, decides alone.
    range_flags_ = rank_ == 0 || image.version_major < 2 || image.version_minor < kImageVersionMinorHeldOutThreshold;
    if (rank_ > 0) {
      points_ = image.variance_points;
      inducing_factor_ = image.variance_inducing_factor;
      posterior_factor_ = image.variance_posterior_factor;
      position_scale_ = S(image.variance_calibration[image_variance_field::position_scale]);
      orientation_scale_ = S(image.variance_calibration[image_variance_field::orientation_scale]);
      threshold_ = S(image.variance_calibration[image_variance_field::extrapolation_variance]);
      signal_ = S(image.signal_variance[0]);
      noise_ = S(image.noise_variance[0]);
      for (int k = 0; k < kImageOutputs; ++k) {
        const S scale = S(image.output_scale[k]);
        output_scale_sq_[k] = scale * scale;
      }
    }
    bound_ = true;
    return Status::ok;
  }

  bool bound() const { return bound_; }
  bool has_variance() const { return rank_ > 0; }
  int rank() const { return rank_; }

  // The evaluation in slices, for a runtime that spreads it over cycles:
  // its whole state lives here. Work is counted in the cycle's units (a GP
  // mean point's instructions, model/work_costs.hpp): a variance point's
  // kernel value costs kKernelUnits, row i of a triangular solve
  // kKernelUnits + i / kSolveMacsPerUnit; measured on the Cortex-M7 and M4F
  // under QEMU (about 100 instructions for each pair of units charged
  // before, at one unit per kernel and 16 multiply-adds per unit).
  static constexpr std::uint32_t kKernelUnits = 2;
  static constexpr std::uint32_t kSolveMacsPerUnit = 8;

  struct Evaluation {
    S z[MaxInputs] = {};
    Vec3<S> tip_mm = Vec3<S>::Zero();
    S a[kMaxRank] = {};
    S known = S(0);      // |L_u^-1 r|^2
    S recovered = S(0);  // |L_c^-1 L_u^-1 r|^2
    int stage = 0;       // 0: kernel values, 1: the solve with L_u, 2: with L_c, 3: done
    int next = 0;        // the next point or row of the stage
    const float* row = nullptr;
    bool outside_range = false;
  };

  // The units a whole evaluation costs: what a caller that runs it in one
  // cycle must budget.
  std::uint32_t evaluation_units() const {
    std::uint32_t units = kKernelUnits * static_cast<std::uint32_t>(rank_);
    for (int i = 0; i < rank_; ++i) units += 2 * (kKernelUnits + static_cast<std::uint32_t>(i) / kSolveMacsPerUnit);
    return units;
  }

  void begin_evaluation(const S* z, const Vec3<S>& tip_mm, Evaluation& e) const {
    for (int d = 0; d < dims_; ++d) e.z[d] = z[d];
    e.tip_mm = tip_mm;
    e.known = S(0);
    e.recovered = S(0);
    e.stage = rank_ > 0 ? 0 : 3;
    e.next = 0;
    e.row = inducing_factor_;
    e.outside_range = outside_range(z);
  }

  bool evaluation_finished(const Evaluation& e) const { return e.stage == 3; }

  // Goes on for at most max_units (and at least one step, so that any
  // budget ends the evaluation); returns the units spent.
  std::uint32_t continue_evaluation(Evaluation& e, std::uint32_t max_units) const {
    std::uint32_t spent = 0;
    while (e.stage < 3) {
      if (e.stage == 0) {
        if (spent > 0 && spent + kKernelUnits > max_units) break;
        const float* u = points_ + static_cast<std::size_t>(e.next) * static_cast<std::size_t>(dims_);
        S distance_sq = S(0);
        for (int d = 0; d < dims_; ++d) {
          const S difference = e.z[d] - S(u[d]);
          distance_sq = multiply_add(difference, difference, distance_sq);
        }
        e.a[e.next] = gaussian(distance_sq);
        spent += kKernelUnits;
      } else {
        const std::uint32_t cost = kKernelUnits + static_cast<std::uint32_t>(e.next) / kSolveMacsPerUnit;
        if (spent > 0 && spent + cost > max_units) break;
        // Row i of x = L^-1 x, in place: x_i = (x_i - sum_j<i L_ij x_j) / L_ii.
        const int i = e.next;
        S sum = e.a[i];
        for (int j = 0; j < i; ++j) sum = multiply_add(-S(e.row[j]), e.a[j], sum);
        e.a[i] = sum / S(e.row[i]);
        S& norm_sq = e.stage == 1 ? e.known : e.recovered;
        norm_sq = multiply_add(e.a[i], e.a[i], norm_sq);
        e.row += i + 1;
        spent += cost;
      }
      if (++e.next == rank_) {
        e.next = 0;
        e.stage += 1;
        e.row = e.stage == 1 ? inducing_factor_ : posterior_factor_;
      }
    }
    return spent;
  }

  PoseUncertainty<S> evaluation_result(const Evaluation& e) const {
    PoseUncertainty<S> result;
    result.outside_range = e.outside_range;
    result.extrapolating = range_flags_ && e.outside_range;
    if (rank_ == 0) return result;
    const S share = S(1) - e.known + e.recovered;
    result.latent_share = share < S(0) ? S(0) : (share > S(1) ? S(1) : share);
    result.extrapolating = result.extrapolating || result.latent_share > threshold_;
    const S normalised = signal_ * result.latent_share + noise_;
    S variances[kImageOutputs];
    for (int k = 0; k < kImageOutputs; ++k) variances[k] = output_scale_sq_[k] * normalised;
    gaussian_radii_95(variances, e.tip_mm, result.r95_mm, result.r95_deg);
    result.r95_mm *= position_scale_;
    result.r95_deg *= orientation_scale_;
    return result;
  }

  // Whether a query outside the fitted rows' range extrapolates by that
  // alone (images before 2.6, or without a variance block).
  bool range_flags() const { return range_flags_; }

  bool outside_range(const S* z) const {
    if (!has_range_) return false;
    for (int d = 0; d < dims_; ++d) {
      if (z[d] < range_min_[d] || z[d] > range_max_[d]) return true;
    }
    return false;
  }

  // The radii around the compensated pose whose tip is at tip_mm, and the
  // extrapolation flag, for the query with kernel coordinates z: the same
  // steps as the slices, in one go.
  PoseUncertainty<S> evaluate(const S* z, const Vec3<S>& tip_mm) const {
    Evaluation e;
    begin_evaluation(z, tip_mm, e);
    continue_evaluation(e, 0xFFFFFFFFu);
    return evaluation_result(e);
  }

 private:
  bool bound_ = false;
  int dims_ = 0;
  int rank_ = 0;
  bool has_range_ = false;
  bool range_flags_ = true;
  S range_min_[MaxInputs] = {};
  S range_max_[MaxInputs] = {};
  const float* points_ = nullptr;
  const float* inducing_factor_ = nullptr;
  const float* posterior_factor_ = nullptr;
  S position_scale_ = S(1);
  S orientation_scale_ = S(1);
  S threshold_ = S(1);
  S signal_ = S(0);
  S noise_ = S(0);
  S output_scale_sq_[kImageOutputs] = {};
};

}  // namespace cdcr::model
