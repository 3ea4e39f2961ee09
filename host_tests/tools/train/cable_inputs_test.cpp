// The cables' residuals as GP inputs (model/cable_fit.hpp,
// train/cable_inputs.hpp): a robot whose tip moves with what the pairs' sums
// say, which the bend alone cannot tell; the evidence keeps the residuals
// there and nowhere else; the image carries them and the board's float32
// path reads them from the cables as the trainer does.

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "cdcr/model/cable_fit.hpp"
#include "cdcr/model/chain.hpp"
#include "cdcr/model/flash_image.hpp"
#include "cdcr/model/gp_correction.hpp"
#include "export/image_writer.hpp"
#include "pipeline/train_and_export.hpp"
#include "train/cable_inputs.hpp"

#include "../../model/image_edits.hpp"

namespace cdcr::training {
namespace {

model::RobotGeometry<double> lab_segment() {
  model::RobotGeometry<double> g;
  g.segment_count = 1;
  g.segments[0] = model::SegmentGeometry<double>{64.0, 8.0, 1.5707963267948966};
  return g;
}

// A segment whose cables are driven apart: a pair pulled against the other
// (imbalance p) bends the backbone further along the pulled pair's plane,
// and slack in common (c) leaves it shorter. The constant-curvature map sees
// only the differences.
dataset::Dataset pulled_against_each_other(const model::RobotGeometry<double>& g, int rows, double residual_mm,
                                           std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> alpha(-3.1, 3.1), theta(0.05, 1.2), residual(-residual_mm, residual_mm);
  std::normal_distribution<double> noise(0.0, 0.1);  // a tracker's, in mm
  dataset::Dataset data;
  data.segment_count = 1;
  data.has_poses = true;
  data.cables_mm.resize(rows, 4);
  for (int k = 0; k < rows; ++k) {
    model::SegmentCableFit<double> fit;
    fit.joints = model::SegmentJoints<double>{alpha(rng), theta(rng)};
    fit.common_mode_mm = -std::abs(residual(rng));
    fit.pair_imbalance_mm = residual(rng);
    data.cables_mm.row(k) = model::cables_from_fit(fit, g.segments[0]).transpose();
    const Eigen::Vector2d b = model::bend_from_joints(fit.joints);
    const Eigen::Vector2d true_bend = b + 0.03 * fit.pair_imbalance_mm * Eigen::Vector2d(1.0, 0.5);
    model::Pose<double> pose =
        model::segment_pose(true_bend, g.segments[0].backbone_length_mm + 1.5 * fit.common_mode_mm);
    pose.position_mm += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    data.poses.push_back(pose);
  }
  return data;
}

TrainingOptions quick_options() {
  TrainingOptions options;
  options.variance_rank = 16;
  options.search.restarts = 1;
  return options;
}

ExportResult trained(const TrainingSet& all, const model::RobotGeometry<double>& g, const TrainingOptions& options) {
  const Split split = random_split(all.size(), all.size() / 4, 3);
  return train_and_export(all.subset(split.train), all.subset(split.test), all, g, options, 0, 0);
}

TEST(CableInputs, TheFitsResidualsAreTheRowsInputsAndCounted) {
  const model::RobotGeometry<double> g = lab_segment();
  const dataset::Dataset data = pulled_against_each_other(g, 200, 3.0, 5);
  const TrainingSet set = make_training_set(data, g, model::InputEncoding::bend_vector_cable_fit);
  ASSERT_EQ(set.inputs.cols(), 4);
  int far = 0;
  for (int k = 0; k < set.size(); ++k) {
    model::SegmentCableFit<double> fit;
    ASSERT_EQ(model::fit_cables(model::Vec4<double>(data.cables_mm.row(k).transpose()), g.segments[0], fit),
              model::Status::ok);
    EXPECT_NEAR(set.inputs(k, 2), fit.common_mode_mm, 1e-12);
    EXPECT_NEAR(set.inputs(k, 3), fit.pair_imbalance_mm, 1e-12);
    far += model::far_from_consistent(fit) ? 1 : 0;
  }
  EXPECT_EQ(set.far_from_consistent_rows, far);
  EXPECT_GT(far, 150);
  EXPECT_EQ(set.beyond_limit_rows, 0);
  EXPECT_EQ(make_training_set(data, g, model::InputEncoding::bend_vector).inputs.cols(), 2);
}

TEST(CableInputs, EvidenceKeepsTheResidualsWhereTheTipMovesWithThem) {
  const model::RobotGeometry<double> g = lab_segment();
  const TrainingSet all =
      make_training_set(pulled_against_each_other(g, 240, 3.0, 1), g, model::InputEncoding::bend_vector);
  const TrainingOptions options = quick_options();
  const CableInputChoice choice = choose_cable_inputs(all, options);
  EXPECT_TRUE(choice.searched);
  EXPECT_EQ(choice.encoding, model::InputEncoding::bend_vector_cable_fit);
  EXPECT_GT(choice.with_residuals_log_likelihood - choice.bend_only_log_likelihood, 50.0);

  const ExportResult bend_only = trained(all, g, options);
  TrainingOptions cable_fit = options;
  cable_fit.encoding = model::InputEncoding::bend_vector_cable_fit;
  const ExportResult with_residuals =
      trained(with_encoding(all, model::InputEncoding::bend_vector_cable_fit), g, cable_fit);
  const double bend_only_mm = bend_only.validation.compensated.position_mm;
  const double residuals_mm = with_residuals.validation.compensated.position_mm;
  EXPECT_LT(residuals_mm, 0.3 * bend_only_mm) << residuals_mm << " vs " << bend_only_mm;
  // The float32 image reads the residuals from the cables itself.
  EXPECT_NEAR(with_residuals.firmware.compensated.position_mm, residuals_mm, 0.01);
  EXPECT_TRUE(with_residuals.fidelity_met())
      << with_residuals.fidelity.max_position_mm << " mm, " << with_residuals.fidelity.max_orientation_deg << " deg; "
      << bend_only.fidelity.max_position_mm << " mm, " << bend_only.fidelity.max_orientation_deg << " deg";

  model::ImageView view{};
  ASSERT_EQ(model::parse_image(with_residuals.image.data(), with_residuals.image.size(), view), model::ImageStatus::ok);
  EXPECT_EQ(view.encoding, model::InputEncoding::bend_vector_cable_fit);
  // 2.4 for the encoding, 2.6 for the variance block's flag.
  EXPECT_EQ(view.version_minor, model::kImageVersionMinorHeldOutThreshold);
  EXPECT_GT(view.variance_rank, 0u);
  EXPECT_EQ(view.input_dims, 4);
  EXPECT_EQ(view.extra_inputs, 0);

  // The board's correction against the trainer's prediction, row by row:
  // with the residuals passed, and with them held (as IK evaluates).
  model::GpCorrection<double> correction;
  ASSERT_EQ(correction.bind(view), model::Status::ok);
  ASSERT_TRUE(correction.takes_cable_residuals());
  const TrainingSet rows = with_encoding(all, model::InputEncoding::bend_vector_cable_fit);
  const Eigen::MatrixXd expected = predict_error_twists(with_residuals.model, rows);
  for (int k = 0; k < rows.size(); k += 7) {
    const model::JointVector<double> bend = rows.bends.row(k).transpose();
    const model::CableResiduals<double> residuals = rows.cable_residuals.row(k).transpose();
    const model::Twist<double> passed = correction.predict(bend, residuals);
    // The image holds float32 points and weights: within the fidelity target.
    EXPECT_LT((passed - expected.row(k).transpose()).head<3>().norm(), kFidelityTargetPositionMm) << k;
    correction.set_cable_residuals(residuals);
    EXPECT_EQ(correction.predict(bend), passed) << k;
  }
}

TEST(CableInputs, ConsistentCablesTrainAsToday) {
  const model::RobotGeometry<double> g = lab_segment();
  const TrainingSet all =
      make_training_set(pulled_against_each_other(g, 120, 0.0, 2), g, model::InputEncoding::bend_vector);
  EXPECT_EQ(all.far_from_consistent_rows, 0);
  const CableInputChoice choice = choose_cable_inputs(all, quick_options());
  EXPECT_FALSE(choice.searched);
  EXPECT_EQ(choice.encoding, model::InputEncoding::bend_vector);
}

TEST(CableInputs, RowsBeyondTheLimitLeaveOnlyTheCableFit) {
  model::RobotGeometry<double> g = lab_segment();
  const dataset::Dataset data = pulled_against_each_other(g, 120, 1.0, 4);
  g.segments[0].theta_max_rad = 0.9;  // theta reaches 1.2 in the data
  const TrainingSet all = make_training_set(data, g, model::InputEncoding::bend_vector);
  EXPECT_GT(all.beyond_limit_rows, 10);
  const CableInputChoice choice = choose_cable_inputs(all, quick_options());
  EXPECT_FALSE(choice.searched);
  EXPECT_EQ(choice.encoding, model::InputEncoding::bend_vector_cable_fit);
  // ... and the board's path reads them: the image validates on them.
  TrainingOptions cable_fit = quick_options();
  cable_fit.encoding = model::InputEncoding::bend_vector_cable_fit;
  const ExportResult r = trained(with_encoding(all, cable_fit.encoding), g, cable_fit);
  EXPECT_TRUE(r.fidelity_met());
  EXPECT_LT(r.firmware.compensated.position_mm, 0.5 * r.firmware.initial.position_mm);
}

// Consistent cables written as a CSV writes them (to 1 um) leave residuals
// of rounding only; with rows beyond the limit the cable fit is the only
// choice all the same, and the board's float32 residuals (and its 0.01 mm
// steps) must not move the model: the residuals are normalised by at least
// the protocol's step.
TEST(CableInputs, RoundingResidualsDoNotMoveTheBoardsModel) {
  model::RobotGeometry<double> g = lab_segment();
  dataset::Dataset data = pulled_against_each_other(g, 160, 0.0, 8);
  data.cables_mm = (data.cables_mm * 1e6).array().round() / 1e6;
  g.segments[0].theta_max_rad = 0.9;
  TrainingOptions cable_fit = quick_options();
  cable_fit.encoding = model::InputEncoding::bend_vector_cable_fit;
  const TrainingSet all = make_training_set(data, g, cable_fit.encoding);
  ASSERT_GT(all.beyond_limit_rows, 10);
  ASSERT_GT(all.cable_residuals.cwiseAbs().maxCoeff(), 0.0);
  const ExportResult r = trained(all, g, cable_fit);
  EXPECT_TRUE(r.fidelity_met()) << r.fidelity.max_position_mm << " mm, " << r.fidelity.max_orientation_deg << " deg";
  EXPECT_NEAR(r.firmware.compensated.position_mm, r.validation.compensated.position_mm, 0.01);
}

TEST(CableInputs, TheParserRefusesTheEncodingInAnOlderImageAndAWrongInputCount) {
  const model::RobotGeometry<double> g = lab_segment();
  TrainingOptions cable_fit = quick_options();
  cable_fit.encoding = model::InputEncoding::bend_vector_cable_fit;
  const TrainingSet all = make_training_set(pulled_against_each_other(g, 60, 2.0, 6), g, cable_fit.encoding);
  const std::vector<std::uint8_t> image = trained(all, g, cable_fit).image;
  model::ImageView view{};
  ASSERT_EQ(model::parse_image(image.data(), image.size(), view), model::ImageStatus::ok);

  test_support::Bytes older = image;
  test_support::put<std::uint16_t>(older, model::image_field::version_minor.offset,
                                   model::kImageVersionMinorCompliance);
  test_support::reseal(older);
  EXPECT_EQ(model::parse_image(older.data(), older.size(), view), model::ImageStatus::unsupported_kind);

  test_support::Bytes bend_only = image;
  test_support::put<std::uint8_t>(bend_only, model::image_field::input_encoding.offset,
                                  static_cast<std::uint8_t>(model::InputEncoding::bend_vector));
  test_support::reseal(bend_only);
  EXPECT_EQ(model::parse_image(bend_only.data(), bend_only.size(), view), model::ImageStatus::bad_header);
}

}  // namespace
}  // namespace cdcr::training
