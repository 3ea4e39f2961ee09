#pragma once
// Accuracy before and after compensation (Section V): position error
// |p_measured - p| in mm, orientation error the rotation angle of
// R_measured R^T in degrees, averaged over samples.

#include <vector>

#include <Eigen/Core>

#include "cdcr/model/flash_image.hpp"
#include "cdcr/model/gp_uncertainty.hpp"
#include "cdcr/model/pose_error_summary.hpp"
#include "cdcr/model/se3.hpp"
#include "training_set.hpp"

namespace cdcr::training {

struct MeanErrors {
  double position_mm = 0.0;
  double orientation_deg = 0.0;
};

struct Evaluation {
  int samples = 0;
  MeanErrors initial;      // nominal model
  MeanErrors compensated;  // nominal model plus GP correction
};

MeanErrors mean_errors(const std::vector<model::Pose<double>>& reference, const std::vector<model::Pose<double>>& poses);

// Compensated poses exp(eps_i) T_nominal,i for predicted error twists (rows).
std::vector<model::Pose<double>> compensated_poses(const TrainingSet& set, const Eigen::MatrixXd& error_twists);

Evaluation evaluate(const TrainingSet& set, const Eigen::MatrixXd& predicted_error_twists);

// How the firmware's GP sums its N terms (model::GpCorrection's Accumulator).
enum class FirmwareAccumulator {
  float64,             // FPUs with double support: host, Cortex-M7
  compensated_float32, // single-precision FPUs: Cortex-M4F
  float32,             // naive single precision, for comparison only
};

const char* to_string(FirmwareAccumulator accumulator);

// The board's forward path in float32 (firmware::estimate_compensated_pose
// on the parsed image) over the samples' commanded cables. An image with the
// payload input takes each sample's payload_kg, set on the correction before
// the sample as the runtime sets a received one (throws
// std::invalid_argument when there are none); other images ignore them. An
// image with a compliance block sags the nominal pose under that payload.
// An image with a history encoding takes each sample's history_inputs row
// (where each cable last moved) the same way.
std::vector<model::Pose<double>> firmware_poses(const model::ImageView& image, const Eigen::MatrixXd& cables_mm,
                                                FirmwareAccumulator accumulator = FirmwareAccumulator::float64,
                                                const Eigen::VectorXd& payload_kg = {},
                                                const Eigen::MatrixXd& history_inputs = {});

// How far one path's poses lie from another's: the mean and largest position
// and orientation differences.
using Fidelity = model::PoseErrorSummary;

// The firmware's uncertainty path (model::GpUncertainty on the parsed
// image, float32) for each sample, beside its compensated pose.
struct FirmwareEstimate {
  model::Pose<double> pose;
  model::PoseUncertainty<double> uncertainty;
};
// The board's float32 pose and radii, widened to double.
FirmwareEstimate firmware_estimate(const model::Pose<float>& pose, const model::PoseUncertainty<float>& radii);
std::vector<FirmwareEstimate> firmware_estimates(const model::ImageView& image, const Eigen::MatrixXd& cables_mm,
                                                const Eigen::VectorXd& payload_kg = {},
                                                const Eigen::MatrixXd& history_inputs = {});

// How well the radii describe measured poses: the share of samples whose
// measured position lies within r95_mm of the compensated one (and the
// orientation within r95_deg), and how many are flagged as extrapolating.
struct CoverageCheck {
  int samples = 0;
  double position_coverage = 0.0;
  double orientation_coverage = 0.0;
  double median_r95_mm = 0.0;
  double median_r95_deg = 0.0;
  double median_latent_share = 0.0;
  int extrapolating = 0;
  int outside_range = 0;
};
CoverageCheck check_coverage(const std::vector<model::Pose<double>>& measured,
                             const std::vector<FirmwareEstimate>& estimates);

Fidelity compare_poses(const std::vector<model::Pose<double>>& reference, const std::vector<model::Pose<double>>& poses);

}  // namespace cdcr::training
