#pragma once
// The learned correction: the GP posterior mean of the tip error twist
// (eq. 16, mean only) evaluated from a validated flash image, and its
// analytic gradient for compensated inverse kinematics.
//
// Per cycle the cost is one pass over the N training points: D differences
// and multiply-adds for the squared distance, one exp, and 6 multiply-adds
// into the output accumulators. Everything that does not depend on the query
// (input normalisation combined with the length scales, output scaling
// combined with the signal variance) is folded once in bind().
//
// Accumulator is the type of the six running sums. The terms k_i alpha_i can
// be large with alternating signs, so the sums are where single precision
// loses digits first; double accumulation costs the same instruction count on
// an FPU with double support (host, Cortex-M7), and a compensated float sum
// serves FPUs without it.

#include <array>
#include <cmath>
#include <cstdint>
#include <type_traits>

#include "cdcr/model/chain.hpp"
#include "cdcr/model/flash_image.hpp"
#include "cdcr/model/input_encoding.hpp"
#include "cdcr/model/status.hpp"
#include "cdcr/model/types.hpp"

namespace cdcr::model {

// Neumaier's compensated sum: a float accumulator that carries its own
// rounding error.
struct CompensatedFloat {
  float sum = 0.0f;
  float compensation = 0.0f;

  CompensatedFloat& operator+=(float term) {
    const float t = sum + term;
    if (std::abs(sum) >= std::abs(term)) {
      compensation += (sum - t) + term;
    } else {
      compensation += (term - t) + sum;
    }
    sum = t;
    return *this;
  }
  float value() const { return sum + compensation; }
};

template <typename S, typename Accumulator = double, int MaxSegments = kMaxSegments>
class GpCorrection {
 public:
  static constexpr int kMaxInputs = 2 * MaxSegments;
  using Input = Eigen::Matrix<S, Eigen::Dynamic, 1, Eigen::ColMajor, kMaxInputs, 1>;

  // Takes a view from parse_image(); the image bytes must outlive this object.
  Status bind(const ImageView& image) {
    if (image.segment_count < 1 || image.segment_count > MaxSegments) return Status::invalid_segment_count;
    inputs_ = image.inputs;
    alpha_ = image.alpha;
    training_points_ = image.training_points;
    input_dims_ = image.input_dims;
    encoding_ = image.encoding;
    for (int d = 0; d < input_dims_; ++d) {
      input_mean_[d] = S(image.input_mean[d]);
      input_gain_[d] = S(1) / (S(image.input_scale[d]) * S(image.length_scale[d]));
    }
    for (int k = 0; k < kImageOutputs; ++k) {
      output_mean_[k] = S(image.output_mean[k]);
      output_gain_[k] = S(image.output_scale[k]) * S(image.signal_variance[k]);
    }
    return Status::ok;
  }

  bool bound() const { return alpha_ != nullptr; }
  int input_dims() const { return input_dims_; }
  InputEncoding encoding() const { return encoding_; }

  // The error twist eps (v, omega) for a stacked bend vector.
  Twist<S> predict(const JointVector<S, MaxSegments>& bend) const {
    S z[kMaxInputs];
    kernel_coordinates(bend, z);
    Accumulator sums[kImageOutputs] = {};
    for (std::uint32_t i = 0; i < training_points_; ++i) {
      const S r = kernel_value(z, inputs_ + i * static_cast<std::uint32_t>(input_dims_));
      const float* a = alpha_ + i * kImageOutputs;
      for (int k = 0; k < kImageOutputs; ++k) accumulate(sums[k], r * S(a[k]));
    }
    return outputs(sums);
  }

  // eps and d(eps)/d(bend), 6 x D.
  void predict_with_gradient(const JointVector<S, MaxSegments>& bend, Twist<S>& eps,
                             Jacobian<S, MaxSegments>& d_eps_d_bend) const {
    S z[kMaxInputs];
    kernel_coordinates(bend, z);
    Accumulator sums[kImageOutputs] = {};
    // d/dz of sum_i alpha_ik r_i = sum_i alpha_ik r_i (z_i - z)
    Eigen::Matrix<S, kImageOutputs, Eigen::Dynamic, Eigen::ColMajor, kImageOutputs, kMaxInputs> dz(kImageOutputs,
                                                                                                  input_dims_);
    dz.setZero();
    for (std::uint32_t i = 0; i < training_points_; ++i) {
      const float* zi = inputs_ + i * static_cast<std::uint32_t>(input_dims_);
      const S r = kernel_value(z, zi);
      const float* a = alpha_ + i * kImageOutputs;
      for (int k = 0; k < kImageOutputs; ++k) {
        const S weight = r * S(a[k]);
        accumulate(sums[k], weight);
        for (int d = 0; d < input_dims_; ++d) dz(k, d) += weight * (S(zi[d]) - z[d]);
      }
    }
    eps = outputs(sums);
    // Chain rule: eps_k = mean_k + gain_k sum(...), z_d = (x_d - mean_d) gain_d,
    // and x = encode(bend) block by block.
    d_eps_d_bend.setZero(6, input_dims_);
    for (int k = 0; k < kImageOutputs; ++k) {
      for (int d = 0; d < input_dims_; ++d) dz(k, d) *= output_gain_[k] * input_gain_[d];
    }
    for (int s = 0; s < input_dims_ / 2; ++s) {
      const Eigen::Matrix<S, 2, 2> block = encoding_jacobian_block<S>(encoding_, bend.template segment<2>(2 * s));
      d_eps_d_bend.template middleCols<2>(2 * s) = dz.template middleCols<2>(2 * s) * block;
    }
  }

  // The correction-term interface of solve_ik(): the twist alone, for trial
  // steps, and with its derivative.
  Status value(const JointVector<S, MaxSegments>& bend, Twist<S>& eps) const {
    if (!bound() || bend.size() != input_dims_) return Status::correction_failed;
    eps = predict(bend);
    return Status::ok;
  }

  Status operator()(const JointVector<S, MaxSegments>& bend, Twist<S>& eps,
                    Jacobian<S, MaxSegments>& d_eps_d_bend) const {
    if (!bound() || bend.size() != input_dims_) return Status::correction_failed;
    predict_with_gradient(bend, eps, d_eps_d_bend);
    return Status::ok;
  }

 private:
  void kernel_coordinates(const JointVector<S, MaxSegments>& bend, S* z) const {
    Input x(input_dims_);
    encode_inputs(encoding_, bend, x);
    for (int d = 0; d < input_dims_; ++d) z[d] = (x[d] - input_mean_[d]) * input_gain_[d];
  }

  S kernel_value(const S* z, const float* zi) const {
    S distance_sq = S(0);
    for (int d = 0; d < input_dims_; ++d) {
      const S diff = z[d] - S(zi[d]);
      distance_sq += diff * diff;
    }
    return std::exp(S(-0.5) * distance_sq);
  }

  static void accumulate(Accumulator& sum, S term) {
    if constexpr (std::is_same_v<Accumulator, CompensatedFloat>) {
      sum += static_cast<float>(term);
    } else {
      sum += static_cast<Accumulator>(term);
    }
  }

  static S value_of(const Accumulator& sum) {
    if constexpr (std::is_same_v<Accumulator, CompensatedFloat>) {
      return S(sum.value());
    } else {
      return S(sum);
    }
  }

  Twist<S> outputs(const Accumulator* sums) const {
    Twist<S> eps;
    for (int k = 0; k < kImageOutputs; ++k) eps[k] = output_mean_[k] + output_gain_[k] * value_of(sums[k]);
    return eps;
  }

  const float* inputs_ = nullptr;
  const float* alpha_ = nullptr;
  std::uint32_t training_points_ = 0;
  int input_dims_ = 0;
  InputEncoding encoding_ = InputEncoding::bend_vector;
  std::array<S, kMaxInputs> input_mean_{};
  std::array<S, kMaxInputs> input_gain_{};
  std::array<S, kImageOutputs> output_mean_{};
  std::array<S, kImageOutputs> output_gain_{};
};

}  // namespace cdcr::model
