#pragma once
// The robot model the runtime runs and the forward path on it: the types in
// the runtime's precision, the model an image binds (or the nominal one),
// a pose from cable lengths, and its variance over a few cycles' slices.

#include <cstdint>

#include "cdcr/firmware/capacity.hpp"
#include "cdcr/model/compensated_kinematics.hpp"
#include "cdcr/model/flash_image.hpp"
#include "cdcr/model/gp_correction.hpp"
#include "cdcr/model/gp_uncertainty.hpp"
#include "cdcr/model/inverse_kinematics.hpp"
#include "cdcr/model/payload_compliance.hpp"

namespace cdcr::firmware {

// float kinematics; the GP sums in double where the FPU has it (host,
// Cortex-M7), in compensated float where it is single precision only
// (Cortex-M4F), where double arithmetic would be software (see
// gp_correction.hpp; `cdcr train` reports the fidelity of both).
using Scalar = float;
#if defined(__ARM_FP) && !(__ARM_FP & 0x8)
using Accumulator = model::CompensatedFloat;
#else
using Accumulator = double;
#endif
using Geometry = model::RobotGeometry<Scalar, kMaxSegments>;
using Cables = model::CableVector<Scalar, kMaxSegments>;
using Joints = model::JointVector<Scalar, kMaxSegments>;
using Correction = model::GpCorrection<Scalar, Accumulator, kMaxSegments>;
using Uncertainty = model::GpUncertainty<Scalar, Correction::kMaxInputs>;
using Pose = model::Pose<Scalar>;
using Compliance = model::PayloadCompliance<Scalar, kMaxSegments>;

// The correction as the IK solver sees it: the GP's evaluation in slices.
// Its functions are defined in kinematics.cpp, beside the forward path, so
// the GP loops are compiled as the forward path's are wherever the solver is
// compiled (firmware/CMakeLists.txt).
//
// With a compliance model (an image's compliance block) the solver works in
// sagged-bend space: its nominal model is the plain kinematics of the
// sagged bends b', and the correction, trained at the commanded bends b, is
// evaluated at b = commanded_bends(b') (payload_compliance.hpp, explicit:
// no fixed point). Its gradient is taken as d(eps)/db for d(eps)/db': db/db'
// differs from the identity by the sag's change with the shape (a tenth at
// most), and the gradient only steers the iteration.
class SolverCorrection {
 public:
  using Evaluation = Correction::Evaluation;
  explicit SolverCorrection(const Correction& correction, const Compliance* compliance = nullptr,
                            const Geometry* geometry = nullptr)
      : correction_(&correction), compliance_(compliance), geometry_(geometry) {}
  model::Status begin_evaluation(const Joints& bend, Evaluation& evaluation, bool with_gradient) const;
  std::uint32_t continue_evaluation(Evaluation& evaluation, std::uint32_t max_units) const;
  bool evaluation_finished(const Evaluation& evaluation) const;
  bool evaluation_has_gradient(const Evaluation& evaluation) const;
  void evaluation_result(const Evaluation& evaluation, model::Twist<Scalar>& eps,
                         model::Jacobian<Scalar, kMaxSegments>& d_eps_d_bend) const;

 private:
  const Correction* correction_;
  const Compliance* compliance_;
  const Geometry* geometry_;
};
using Solver = model::IkSolver<Scalar, kMaxSegments, SolverCorrection>;

// What the runtime computes with: the image's geometry, correction and
// variance block (compensated, in RUN), or the fallback geometry alone
// (nominal, in DEGRADED and before init).
struct RobotModel {
  Geometry geometry;
  model::ImageView image{};
  Correction correction;
  Uncertainty uncertainty;
  // The image's compliance block (empty without one): the nominal pose sags
  // under the correction's payload.
  Compliance compliance;
  bool compensated = false;
};

// The payload's sag on the board (payload_sag.cpp, out of line): the sagged
// bends of commanded ones, and the commanded bends that sag into given
// ones, at the payload given.
Joints sagged_bends_of(const Compliance& compliance, const Geometry& geometry, Scalar payload_kg, const Joints& bend);
Joints commanded_bends_of(const Compliance& compliance, const Geometry& geometry, Scalar payload_kg,
                          const Joints& sagged);

// The joints whose cables the drives are sent for the solver's joints: with
// a compliance model (compensated only) those of the commanded bends that
// sag into the solver's, otherwise the solver's own.
Joints commanded_joints(const RobotModel& model, const Joints& solver_joints);

struct PoseEstimate {
  Pose pose;
  Joints joints;
  // What the cables say beyond the bend, for a model that takes it
  // (cable_fit.hpp); empty otherwise.
  model::CableResiduals<Scalar, kMaxSegments> cable_residuals;
  bool compensated = false;
  // Outside the input range the model was fitted on (never in DEGRADED).
  bool outside_range = false;
  // The query in the GP's kernel coordinates (compensated only), for the
  // variance of this pose.
  Scalar kernel_coordinates[Correction::kMaxInputs] = {};
};

// The forward path on the latest cable set: nominal or compensated as the
// model is. Writes `estimate` only on success.
model::Status estimate_pose(const RobotModel& model, const Cables& cables_mm, PoseEstimate& estimate);
// The radii and extrapolation flag of an estimate in one go; zero radii
// without a variance block or for a nominal estimate.
model::PoseUncertainty<Scalar> estimate_uncertainty(const RobotModel& model, const PoseEstimate& estimate);

// The variance of a recent pose, computed over a few cycles' slices of
// kUncertaintyUnitsPerCycle; the radii of the last one that ended stay.
class PoseVariance {
 public:
  bool running() const { return running_; }
  // Starts on `estimate` (a compensated one, with a variance block), named
  // by the cycle's sequence number.
  void begin(const Uncertainty& uncertainty, const PoseEstimate& estimate, std::uint8_t sequence);
  // A slice of the work; true when the evaluation ended in it.
  bool continue_slice(const Uncertainty& uncertainty);
  // Drops the evaluation in progress (its pose belongs to an old model).
  void abandon() { running_ = false; }

  bool has_result() const { return has_result_; }
  const model::PoseUncertainty<Scalar>& result() const { return result_; }
  // The same, for the caller that widens the radii (hysteresis_tracker.hpp).
  model::PoseUncertainty<Scalar>& result() { return result_; }
  std::uint8_t result_sequence() const { return result_sequence_; }

 private:
  Uncertainty::Evaluation evaluation_;
  bool running_ = false;
  std::uint8_t running_sequence_ = 0;
  model::PoseUncertainty<Scalar> result_;
  bool has_result_ = false;
  std::uint8_t result_sequence_ = 0;
};

}  // namespace cdcr::firmware
