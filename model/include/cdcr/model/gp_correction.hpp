#pragma once
// The learned correction: the GP posterior mean of the tip error twist
// (eq. 16, mean only) evaluated from a validated flash image, and its
// analytic gradient for compensated inverse kinematics.
//
// Per cycle the cost is one pass over the N training points: D differences
// and multiply-adds for the squared distance, one exp (gaussian() in kernel_exp.hpp), and
// 6 multiply-adds into the output sums. Everything that does not depend on
// the query (input normalisation combined with the length scales, output
// scaling combined with the signal variance) is folded once in bind().
//
// Accumulator is the type of the six running sums. The terms k_i alpha_i can
// be large with alternating signs, so the sums are where single precision
// loses digits first: the terms are added in S over blocks of kBlockPoints
// training points, and each block into the Accumulator, double where the FPU
// has it (host, Cortex-M7) and a compensated float sum where it does not
// (Cortex-M4F).
//
// Arch holds the loops' architecture hooks (block loads, a hand-written mean
// loop; model/arch/): arch::Selected, the one the build picks with
// CDCR_MODEL_ARCH, by default, and arch::Portable for the plain C++
// reference, which a board program compares its own loops against.
//
// An image with a payload input (extra_inputs 1) takes the tip payload as its
// last input, after the bend pairs. The payload is state of the correction:
// the image's default until set_payload_kg(), and every evaluation that
// begins after a set uses the new value, the forward path's and IK's alike.
// An image with the cable-fit encoding takes the cables' residuals after the
// bend pairs (cable_fit.hpp): the forward path passes the measured ones with
// the bend; IK's evaluations use those set_cable_residuals() held (the last
// measured: IK moves the bend, not what the cables do beyond it). The bend
// vector stays the only variable: the gradient is d(eps)/d(bend). An image
// with a history encoding takes where each cable last moved after the
// residuals, held like the payload (set_history_inputs).

#include <array>
#include <cmath>
#include <cstdint>
#include <type_traits>

#include "cdcr/model/arch/selected.hpp"
#include "cdcr/model/cable_fit.hpp"
#include "cdcr/model/chain.hpp"
#include "cdcr/model/compensated_float.hpp"
#include "cdcr/model/flash_image.hpp"
#include "cdcr/model/input_encoding.hpp"
#include "cdcr/model/kernel_exp.hpp"
#include "cdcr/model/status.hpp"
#include "cdcr/model/types.hpp"

namespace cdcr::model {

namespace detail {

// The per-point arithmetic of GpCorrection's loops, and how a block's sum
// goes into the accumulator.
template <typename S, typename Accumulator, typename Arch>
struct GpPointTerms {
  // The loops over a training point's inputs and outputs have a handful of
  // iterations known at compile time; unrolled, their values stay in
  // registers at any optimisation level a board build uses (-O2 does not
  // unroll them). `#pragma GCC unroll` says so to GCC and clang alike and,
  // unlike a macro, reaches no includer. (A template helper calling a lambda
  // per iteration cost the Cortex-M4F 9 % more instructions in the mean:
  // GCC then keeps the sums in memory.)

  // One training point's six terms k(z, z_i) alpha_i, added to `block`;
  // advances zi and a past the point and returns k(z, z_i).
  template <int Dims>
  static S add_point(const S* query, int dims, const float*& zi, const float*& a, S* block) {
    S distance_sq = S(0);
    if constexpr (Arch::kBlockLoads && std::is_same_v<S, float> && Dims > 0) {
      float row[Dims];
      Arch::template load_block<Dims>(zi, row);
#pragma GCC unroll 16
      for (int d = 0; d < Dims; ++d) {
        const S difference = query[d] - row[d];
        distance_sq = Arch::multiply_add(difference, difference, distance_sq);
      }
    } else {
      for (int d = 0; d < dims; ++d) {
        const S difference = query[d] - S(zi[d]);
        distance_sq = Arch::multiply_add(difference, difference, distance_sq);
      }
      zi += dims;
    }
    const S r = Arch::gaussian(distance_sq);
    if constexpr (Arch::kBlockLoads && std::is_same_v<S, float>) {
      float alpha[kImageOutputs];
      Arch::template load_block<kImageOutputs>(a, alpha);
#pragma GCC unroll 16
      for (int k = 0; k < kImageOutputs; ++k) block[k] = Arch::multiply_add(r, alpha[k], block[k]);
    } else {
#pragma GCC unroll 16
      for (int k = 0; k < kImageOutputs; ++k) block[k] = Arch::multiply_add(r, S(a[k]), block[k]);
      a += kImageOutputs;
    }
    return r;
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
};

// One evaluation of GpCorrection in progress (begin_evaluation).
template <typename S, typename Accumulator, int MaxInputs, int MaxSegments>
struct GpEvaluation {
  S z[MaxInputs] = {};
  Accumulator sums[kImageOutputs] = {};
  // sum_i alpha_ik r_i z_i, for the gradient.
  S weighted[kImageOutputs][MaxInputs] = {};
  JointVector<S, MaxSegments> bend;
  std::uint32_t next_point = 0;
  bool with_gradient = false;
};

}  // namespace detail

template <typename S, typename Accumulator = double, int MaxSegments = kMaxSegments, typename Arch = arch::Selected>
class GpCorrection {
 public:
  static constexpr int kMaxInputs = max_model_inputs(MaxSegments);
  // Training points summed in S before a sum goes into the accumulator.
  static constexpr std::uint32_t kBlockPoints = 8;
  // Large enough for any whole evaluation in one slice.
  static constexpr std::uint32_t kMaxUnitsPerSlice = 0xFFFFFFFFu / 4;
  using Input = Eigen::Matrix<S, Eigen::Dynamic, 1, Eigen::ColMajor, kMaxInputs, 1>;

  // Takes a view from parse_image(); the image bytes must outlive this object.
  Status bind(const ImageView& image) {
    if (image.segment_count < 1 || image.segment_count > MaxSegments) return Status::invalid_segment_count;
    inputs_ = image.inputs;
    alpha_ = image.alpha;
    training_points_ = image.training_points;
    input_dims_ = image.input_dims;
    bend_dims_ = 2 * image.segment_count;
    // Per segment its common mode, and with four cables its pairs'
    // imbalance (input_encoding.hpp); a history input per cable.
    segment_count_ = image.segment_count;
    for (int i = 0; i < segment_count_; ++i) four_cables_[i] = image_segment_cables(image, i) == 4;
    residual_dims_ = model::takes_cable_residuals(image.encoding) ? image.cable_count - 2 * segment_count_ : 0;
    history_dims_ = model::takes_history(image.encoding) ? image.cable_count : 0;
    extra_inputs_ = image.extra_inputs;
    held_inputs_ = residual_dims_ + history_dims_ + extra_inputs_;
    if (bend_dims_ + held_inputs_ != input_dims_ || extra_inputs_ > kMaxExtraInputs || input_dims_ > kMaxInputs) {
      return Status::correction_failed;
    }
    // Residuals and history zero (consistent cables; nothing known of the
    // history) until set.
    for (int e = 0; e < residual_dims_ + history_dims_; ++e) held_[e] = S(0);
    for (int e = 0; e < extra_inputs_; ++e) held_[payload_index() + e] = S(image.extra_input_default[e]);
    // A model with held inputs may take the run-time loop, which costs more
    // per point; its work is counted at that price.
    mean_point_units_ = held_inputs_ > 0 ? Arch::kWorkCosts.run_time_loop_point : 1;
    gradient_point_units_ = held_inputs_ > 0 ? Arch::kWorkCosts.run_time_loop_gradient_point : kGradientPointUnits;
    gradient_granule_ = held_inputs_ > 0 ? kBlockPoints : kChunkPoints;
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
  // Inputs of the bend vector, 2 per segment: the inputs before the extra ones.
  int bend_dims() const { return bend_dims_; }
  bool has_payload_input() const { return extra_inputs_ > 0; }
  // The payload the next evaluations use (0 for a model without the input).
  S payload_kg() const { return extra_inputs_ > 0 ? held_[payload_index()] : S(0); }
  // Range checks are the caller's (the runtime's); a model without a payload
  // input ignores it.
  void set_payload_kg(S payload_kg) {
    if (extra_inputs_ > 0) held_[payload_index()] = payload_kg;
  }
  bool takes_cable_residuals() const { return residual_dims_ > 0; }
  // The residuals IK's evaluations use (zero until set); a model without
  // the inputs, or residuals of another robot, leave them as they are.
  void set_cable_residuals(const CableResiduals<S, MaxSegments>& residuals) {
    if (residual_dims_ == 0 || residuals.size() != kCableResidualsPerSegment * segment_count_) return;
    residual_inputs(residuals, segment_count_, four_cables_, held_);
  }
  bool takes_history() const { return history_dims_ > 0; }
  int history_dims() const { return history_dims_; }
  // Where each cable last moved (hysteresis.hpp, history_inputs; zero until
  // set), for every evaluation that begins after the set: the forward path's
  // and IK's alike. A model without the inputs ignores them.
  void set_history_inputs(const S* history) {
    for (int e = 0; e < history_dims_; ++e) held_[residual_dims_ + e] = history[e];
  }
  InputEncoding encoding() const { return encoding_; }

  std::uint32_t training_points() const { return training_points_; }
  // Work units of a point (work_costs.hpp): 1 and kGradientPointUnits, or
  // the run-time loop's for a payload model.
  std::uint32_t mean_point_units() const { return mean_point_units_; }
  std::uint32_t gradient_point_units() const { return gradient_point_units_; }
  // The fewest units a slice with the gradient needs to advance.
  std::uint32_t smallest_gradient_slice_units() const { return gradient_granule_ * gradient_point_units_; }

  // z = (x - input_mean) / (input_scale * length_scale) for x = encode(bend)
  // followed by the held inputs (the cable residuals, the history, the payload): the
  // coordinates the points are stored in (input_dims() values).
  void kernel_coordinates(const JointVector<S, MaxSegments>& bend, S* z) const {
    Input x(bend_dims_);
    encode_inputs(encoding_, bend, x);
    for (int d = 0; d < bend_dims_; ++d) z[d] = (x[d] - input_mean_[d]) * input_gain_[d];
    for (int d = bend_dims_; d < input_dims_; ++d) z[d] = (held_[d - bend_dims_] - input_mean_[d]) * input_gain_[d];
  }

  // The same with measured cable residuals in place of the held ones (a
  // model without the inputs ignores them).
  void kernel_coordinates(const JointVector<S, MaxSegments>& bend, const CableResiduals<S, MaxSegments>& residuals,
                          S* z) const {
    kernel_coordinates(bend, z);
    if (residual_dims_ == 0 || residuals.size() != kCableResidualsPerSegment * segment_count_) return;
    S measured[kMaxInputs];
    residual_inputs(residuals, segment_count_, four_cables_, measured);
    for (int e = 0; e < residual_dims_; ++e) {
      const int d = bend_dims_ + e;
      z[d] = (measured[e] - input_mean_[d]) * input_gain_[d];
    }
  }

  // The error twist eps (v, omega) for a stacked bend vector.
  Twist<S> predict(const JointVector<S, MaxSegments>& bend) const {
    S z[kMaxInputs];
    kernel_coordinates(bend, z);
    return mean_at(z);
  }

  // ... and for the cables' measured residuals beside it (empty ones for a
  // model without them).
  Twist<S> predict(const JointVector<S, MaxSegments>& bend, const CableResiduals<S, MaxSegments>& residuals) const {
    S z[kMaxInputs];
    kernel_coordinates(bend, residuals, z);
    return mean_at(z);
  }

  // eps and d(eps)/d(bend), 6 x D.
  void predict_with_gradient(const JointVector<S, MaxSegments>& bend, Twist<S>& eps,
                             Jacobian<S, MaxSegments>& d_eps_d_bend) const {
    Evaluation evaluation;
    if (begin_evaluation(bend, evaluation, true) != Status::ok) return;
    while (!evaluation_finished(evaluation)) continue_evaluation(evaluation, kMaxUnitsPerSlice);
    evaluation_result(evaluation, eps, d_eps_d_bend);
  }

  // The mean, and optionally its gradient, in slices, for a caller that
  // spreads one evaluation over several fixed-rate cycles (the resumable IK
  // solver). The slices add the same blocks in the same order as a whole
  // pass, so the result has the same bits. Work is counted in units: a
  // training point of the mean is one unit, of the mean with the gradient
  // kGradientPointUnits (the ratio of their instruction counts, measured on
  // the architecture's core, model/arch/<arch>).
  static constexpr std::uint32_t kGradientPointUnits = Arch::kWorkCosts.gradient_point;
  // The gradient pass goes over chunks of this many training points.
  static constexpr std::uint32_t kChunkPoints = 8 * kBlockPoints;

  using Evaluation = detail::GpEvaluation<S, Accumulator, kMaxInputs, MaxSegments>;

  Status begin_evaluation(const JointVector<S, MaxSegments>& bend, Evaluation& evaluation,
                          bool with_gradient = false) const {
    if (!bound() || bend.size() != bend_dims_) return Status::correction_failed;
    kernel_coordinates(bend, evaluation.z);
    for (auto& sum : evaluation.sums) sum = Accumulator{};
    for (auto& row : evaluation.weighted) {
      for (auto& value : row) value = S(0);
    }
    evaluation.bend = bend;
    evaluation.next_point = 0;
    evaluation.with_gradient = with_gradient;
    return Status::ok;
  }

  // Adds training points worth at most max_units, in whole blocks (chunks
  // with the gradient; the ragged end only together with the rest); returns
  // the units spent, 0 when not even one block fits.
  std::uint32_t continue_evaluation(Evaluation& evaluation, std::uint32_t max_units) const {
    // A payload model's gradient goes in blocks rather than chunks, so that
    // its dearer points still fit a cycle's slice; the sums' order, and so
    // their bits, are the same.
    const std::uint32_t unit = evaluation.with_gradient ? gradient_point_units_ : mean_point_units_;
    const std::uint32_t granule = evaluation.with_gradient ? gradient_granule_ : kBlockPoints;
    const std::uint32_t left = training_points_ - evaluation.next_point;
    const std::uint32_t affordable = max_units / unit;
    std::uint32_t count = left;
    if (affordable < left) {
      count = affordable / granule * granule;
      if (count == 0) return 0;
    }
    with_input_count([&](auto dims) {
      constexpr int kDims = decltype(dims)::value;
      if (evaluation.with_gradient) {
        accumulate_mean_and_gradient<kDims>(evaluation.z, evaluation.next_point, count, evaluation.sums,
                                            evaluation.weighted);
      } else {
        accumulate_mean<kDims>(evaluation.z, evaluation.next_point, count, evaluation.sums);
      }
    });
    evaluation.next_point += count;
    return count * unit;
  }

  bool evaluation_finished(const Evaluation& evaluation) const {
    return evaluation.next_point >= training_points_;
  }
  bool evaluation_has_gradient(const Evaluation& evaluation) const { return evaluation.with_gradient; }

  Twist<S> evaluation_result(const Evaluation& evaluation) const { return outputs(evaluation.sums); }

  // eps and, for an evaluation with the gradient, d(eps)/d(bend) (6 x 2n;
  // the payload is no variable of the solver).
  void evaluation_result(const Evaluation& evaluation, Twist<S>& eps, Jacobian<S, MaxSegments>& d_eps_d_bend) const {
    eps = outputs(evaluation.sums);
    const int dims = input_dims_;
    d_eps_d_bend.setZero(6, bend_dims_);
    if (!evaluation.with_gradient) return;
    // d/dz of sum_i alpha_ik r_i = sum_i alpha_ik r_i (z_i - z)
    //                            = sum_i alpha_ik r_i z_i - z sum_i alpha_ik r_i.
    // The first sum is `weighted`; the second is the mean's own sum. The
    // gradient only steers the IK iteration, so S sums are enough for it.
    // Chain rule: eps_k = mean_k + gain_k sum(...), z_d = (x_d - mean_d) gain_d,
    // and x = encode(bend) block by block.
    Eigen::Matrix<S, kImageOutputs, Eigen::Dynamic, Eigen::ColMajor, kImageOutputs, kMaxInputs> scaled(kImageOutputs,
                                                                                                      dims);
    for (int k = 0; k < kImageOutputs; ++k) {
      const S total = Terms::value_of(evaluation.sums[k]);
      for (int d = 0; d < dims; ++d) {
        scaled(k, d) = (evaluation.weighted[k][d] - evaluation.z[d] * total) * output_gain_[k] * input_gain_[d];
      }
    }
    for (int s = 0; s < bend_dims_ / 2; ++s) {
      const Eigen::Matrix<S, 2, 2> jacobian =
          encoding_jacobian_block<S>(encoding_, evaluation.bend.template segment<2>(2 * s));
      d_eps_d_bend.template middleCols<2>(2 * s) = scaled.template middleCols<2>(2 * s) * jacobian;
    }
  }

  // The correction-term interface of solve_ik(): the twist alone, for trial
  // steps, and with its derivative.
  Status value(const JointVector<S, MaxSegments>& bend, Twist<S>& eps) const {
    if (!bound() || bend.size() != bend_dims_) return Status::correction_failed;
    eps = predict(bend);
    return Status::ok;
  }

  Status operator()(const JointVector<S, MaxSegments>& bend, Twist<S>& eps,
                    Jacobian<S, MaxSegments>& d_eps_d_bend) const {
    if (!bound() || bend.size() != bend_dims_) return Status::correction_failed;
    predict_with_gradient(bend, eps, d_eps_d_bend);
    return Status::ok;
  }

 private:
  using Terms = detail::GpPointTerms<S, Accumulator, Arch>;

  Twist<S> mean_at(const S* z) const {
    Accumulator sums[kImageOutputs] = {};
    with_input_count([&](auto dims) { accumulate_mean<decltype(dims)::value>(z, 0, training_points_, sums); });
    return outputs(sums);
  }

  // Calls work(std::integral_constant<int, D>) with the input count D as a
  // constant for the paper's robots (2 to 4 segments), which lets the
  // compiler unroll the distance, and with 0 (count read at run time)
  // otherwise: a payload model's odd count takes the run-time loop, whose
  // extra cost per point the cycle's accounting charges (work_costs.hpp).
  template <typename Work>
  void with_input_count(Work&& work) const {
    switch (input_dims_) {
      case 4: work(std::integral_constant<int, 4>{}); break;
      case 6: work(std::integral_constant<int, 6>{}); break;
      case 8: work(std::integral_constant<int, 8>{}); break;
      default: work(std::integral_constant<int, 0>{}); break;
    }
  }


  // The mean's loop: Dims inputs (0: input_dims_ at run time). The terms are
  // summed in S over blocks of kBlockPoints training points and each block
  // into the accumulator, which keeps the accumulator's cost (a conversion to
  // double, or a compensated sum) out of the per-point work; a block's float
  // sum loses no more than a few ulp of its largest terms.
  // Points [first, first + count): first is a multiple of kBlockPoints, and
  // count is too unless the range ends at the last point.
  template <int Dims>
  void accumulate_mean(const S* z, std::uint32_t first, std::uint32_t count, Accumulator* sums) const {
    const int dims = Dims > 0 ? Dims : input_dims_;
    // A copy the loop owns: through `z` GCC reloads the query on the
    // Cortex-M4F (about 700 instructions more per call, measured).
    S query[kMaxInputs];
    for (int d = 0; d < dims; ++d) query[d] = z[d];
    const float* zi = inputs_ + std::size_t(first) * std::size_t(dims);
    const float* a = alpha_ + std::size_t(first) * kImageOutputs;
    if constexpr (Arch::template has_vector_loops<S, Accumulator>()) {
      if (Arch::vector_loops_available()) {
        Arch::template mean_range<Dims>(query, dims, zi, a, count, sums);
        return;
      }
    }
    const std::uint32_t full_blocks = count / kBlockPoints;
    if constexpr (Arch::template has_mean_blocks<Dims, S, Accumulator, kBlockPoints>()) {
      if (full_blocks > 0) Arch::mean_blocks(query, zi, a, full_blocks, sums);
    } else {
      for (std::uint32_t b = 0; b < full_blocks; ++b) {
        S block[kImageOutputs] = {};
        for (std::uint32_t j = 0; j < kBlockPoints; ++j) Terms::template add_point<Dims>(query, dims, zi, a, block);
        for (int k = 0; k < kImageOutputs; ++k) Terms::accumulate(sums[k], block[k]);
      }
    }
    if (full_blocks * kBlockPoints == count) return;
    S rest[kImageOutputs] = {};
    for (std::uint32_t i = full_blocks * kBlockPoints; i < count; ++i) Terms::template add_point<Dims>(query, dims, zi, a, rest);
    for (int k = 0; k < kImageOutputs; ++k) Terms::accumulate(sums[k], rest[k]);
  }

  // The mean and the gradient's weighted sums over chunks of kChunkPoints
  // training points: one pass computes the chunk's kernel values and the
  // mean's terms (add_point), then one pass per pair of outputs adds
  // alpha_ik r_i z_i for both, so that a pair's 2 D sums stay in registers.
  // Points [first, first + points): first is a multiple of kChunkPoints (of
  // kBlockPoints for a payload model, whose slices go in blocks).
  template <int Dims>
  void accumulate_mean_and_gradient(const S* query, std::uint32_t first_point, std::uint32_t points, Accumulator* sums,
                                    S (&weighted)[kImageOutputs][kMaxInputs]) const {
    const int dims = Dims > 0 ? Dims : input_dims_;
    const float* zi = inputs_ + std::size_t(first_point) * std::size_t(dims);
    const float* a = alpha_ + std::size_t(first_point) * kImageOutputs;
    if constexpr (Arch::template has_vector_loops<S, Accumulator>()) {
      if (Arch::vector_loops_available()) {
        Arch::template mean_and_gradient_range<Dims>(query, dims, zi, a, points, sums, &weighted[0][0], kMaxInputs);
        return;
      }
    }
    const std::uint32_t end_point = first_point + points;
    for (std::uint32_t begin = first_point; begin < end_point; begin += kChunkPoints) {
      const std::uint32_t count = end_point - begin < kChunkPoints ? end_point - begin : kChunkPoints;
      const float* chunk_inputs = zi;
      const float* chunk_alpha = a;
      S r[kChunkPoints];
      for (std::uint32_t j = 0; j < count; j += kBlockPoints) {
        S block[kImageOutputs] = {};
        const std::uint32_t end = j + kBlockPoints < count ? j + kBlockPoints : count;
        for (std::uint32_t i = j; i < end; ++i) r[i] = Terms::template add_point<Dims>(query, dims, zi, a, block);
        for (int k = 0; k < kImageOutputs; ++k) Terms::accumulate(sums[k], block[k]);
      }
      for (int pair = 0; pair < kImageOutputs; pair += 2) {
        S first[kMaxInputs];
        S second[kMaxInputs];
        for (int d = 0; d < dims; ++d) {
          first[d] = weighted[pair][d];
          second[d] = weighted[pair + 1][d];
        }
        const float* row_pointer = chunk_inputs;
        const float* alpha_pair = chunk_alpha + pair;
        for (std::uint32_t j = 0; j < count; ++j) {
          const S w_first = r[j] * S(alpha_pair[0]);
          const S w_second = r[j] * S(alpha_pair[1]);
          alpha_pair += kImageOutputs;
          if constexpr (Arch::kBlockLoads && std::is_same_v<S, float> && Dims > 0) {
            float row[Dims];
            Arch::template load_block<Dims>(row_pointer, row);
#pragma GCC unroll 16
            for (int d = 0; d < Dims; ++d) {
              first[d] = Arch::multiply_add(w_first, row[d], first[d]);
              second[d] = Arch::multiply_add(w_second, row[d], second[d]);
            }
          } else {
            for (int d = 0; d < dims; ++d) {
              first[d] = Arch::multiply_add(w_first, S(row_pointer[d]), first[d]);
              second[d] = Arch::multiply_add(w_second, S(row_pointer[d]), second[d]);
            }
            row_pointer += dims;
          }
        }
        for (int d = 0; d < dims; ++d) {
          weighted[pair][d] = first[d];
          weighted[pair + 1][d] = second[d];
        }
      }
    }
  }

  Twist<S> outputs(const Accumulator* sums) const {
    Twist<S> eps;
    for (int k = 0; k < kImageOutputs; ++k) eps[k] = output_mean_[k] + output_gain_[k] * Terms::value_of(sums[k]);
    return eps;
  }

  const float* inputs_ = nullptr;
  const float* alpha_ = nullptr;
  std::uint32_t training_points_ = 0;
  int input_dims_ = 0;
  int bend_dims_ = 0;
  int residual_dims_ = 0;
  int history_dims_ = 0;
  int segment_count_ = 0;
  bool four_cables_[MaxSegments] = {};
  int extra_inputs_ = 0;
  int held_inputs_ = 0;
  std::uint32_t mean_point_units_ = 1;
  std::uint32_t gradient_point_units_ = kGradientPointUnits;
  std::uint32_t gradient_granule_ = kChunkPoints;
  // The cable residuals, the history, then the payload.
  S held_[kMaxInputs] = {};
  int payload_index() const { return residual_dims_ + history_dims_; }
  InputEncoding encoding_ = InputEncoding::bend_vector;
  std::array<S, kMaxInputs> input_mean_{};
  std::array<S, kMaxInputs> input_gain_{};
  std::array<S, kImageOutputs> output_mean_{};
  std::array<S, kImageOutputs> output_gain_{};
};

}  // namespace cdcr::model
