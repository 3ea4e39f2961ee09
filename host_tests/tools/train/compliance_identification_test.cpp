// Compliance identification against the simulator with only its gravity sag
// on (no geometric errors, no noise, no distributed segment weight): the
// sag of a tip load on a segment of stiffness K = EI / L + 2 k r^2 is the
// sagged nominal model's, so the identification must find 1 / K, the end
// platform's mass and gravity's direction. Data without payload must keep
// the training set it always had. Then the pipeline that exports it.
#include <cmath>
#include <cstdio>
#include <random>

#include <gtest/gtest.h>

#include "cdcr/model/chain.hpp"
#include "cdcr/model/image_compliance.hpp"
#include "pipeline/train_and_export.hpp"
#include "sim/simulated_robot.hpp"
#include "train/compliance_identification.hpp"

#include "../../support/random_joints.hpp"

namespace cdcr::training {
namespace {

sim::SimulatorConfig gravity_only() {
  sim::SimulatorConfig config = sim::SimulatorConfig::nominal_only();
  config.gravity.enabled = true;
  config.gravity.segment_mass_kg = 0.0;  // the tip load alone: what the sagged nominal model describes
  return config;
}

// Commanded cables from random joints through the design geometry; each row
// carries a payload uniform in 0-1 kg (none when with_payload is false) and
// the pose where `robot` takes it (as motion capture measures it when
// measured is true).
dataset::Dataset recorded(sim::SimulatedRobot& robot, int samples, bool with_payload, bool measured = false) {
  const model::RobotGeometry<double>& design = robot.nominal_geometry();
  dataset::Dataset data;
  data.segment_count = design.segment_count;
  data.has_poses = true;
  data.has_payload = with_payload;
  data.cables_mm.resize(samples, 4 * design.segment_count);
  if (with_payload) data.payload_kg.resize(samples);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> alpha(-3.1, 3.1);
  std::uniform_real_distribution<double> theta(0.0, 0.2);
  std::uniform_real_distribution<double> payload(0.0, 1.0);
  for (int k = 0; k < samples; ++k) {
    const model::JointVector<double> joints = test_support::random_joints(design.segment_count, rng, alpha, theta);
    model::CableVector<double> cables;
    EXPECT_EQ(model::cables_from_joints(joints, design, cables), model::Status::ok);
    data.cables_mm.row(k) = cables.transpose();
    const double kg = with_payload ? payload(rng) : 0.0;
    if (with_payload) data.payload_kg[k] = kg;
    data.poses.push_back(measured ? robot.measure(cables, kg).measured_pose : robot.true_pose(cables, kg));
  }
  return data;
}

// The simulator's bending stiffness of a segment of the (uniform) prototype,
// N mm/rad: the backbone's EI/L and the two cables' k r² of each plane.
double simulator_segment_stiffness(const model::RobotGeometry<double>& design, const sim::SimulatorConfig& config) {
  const double length = design.segments[0].backbone_length_mm, radius = design.segments[0].anchor_radius_mm;
  return config.structure.backbone_bending_stiffness_n_mm2 / length +
         2.0 * config.structure.cable_stiffness_n_per_mm * radius * radius;
}

TEST(ComplianceIdentification, FindsTheSimulatorsStiffnessPlatformMassAndGravity) {
  const auto design = model::RobotGeometry<double>::prototype();
  const sim::SimulatorConfig config = gravity_only();
  sim::SimulatedRobot robot(design, config);
  // 240 rows: enough for the background's 45 columns to be projected out,
  // as on real data.
  const TrainingSet set = make_training_set(recorded(robot, 240, true), design, model::InputEncoding::bend_vector);
  ComplianceStructure structure;
  structure.unloaded_mass = true;
  const ComplianceModel c = identify_compliance(set, design, structure);

  const double stiffness = simulator_segment_stiffness(design, config);
  // Tolerances: 0.1 % on the compliance, 1 g on the platform, 0.05 deg on
  // the direction (the sag is the same formula; the model library's Newton steps
  // against the simulator's converged equilibrium).
  for (int s = 0; s < design.segment_count; ++s) {
    EXPECT_NEAR(c.compliance_rad_per_n_mm(s) * stiffness, 1.0, 1e-3) << s;
  }
  EXPECT_NEAR(c.unloaded_mass_kg, config.gravity.platform_mass_kg, 1e-3);
  const double off_deg = std::acos(std::min(1.0, c.gravity_direction().dot(config.gravity.direction.normalized()))) *
                         180.0 / 3.141592653589793;
  EXPECT_LT(off_deg, 0.05);
  // And the sagged nominal model leaves (almost) nothing.
  const TrainingSet sagged = with_compliance(set, design, c);
  EXPECT_GT(set.error_twists.leftCols<3>().rowwise().norm().mean(), 20.0);
  EXPECT_LT(sagged.error_twists.leftCols<3>().rowwise().norm().mean(), 0.05);
}

// An error of the bends alone (here a tip offset linear in them, millimetres
// over the workspace, whatever the payload) is projected out of the
// residuals: the stiffness, platform and direction stay where they were.
TEST(ComplianceIdentification, AnErrorOfTheBendsAloneDoesNotMoveTheStiffness) {
  const auto design = model::RobotGeometry<double>::prototype();
  const sim::SimulatorConfig config = gravity_only();
  sim::SimulatedRobot robot(design, config);
  dataset::Dataset data = recorded(robot, 240, true);
  const TrainingSet clean = make_training_set(data, design, model::InputEncoding::bend_vector);
  std::mt19937_64 rng(5);
  std::normal_distribution<double> gain(0.0, 20.0);  // mm per rad of bend
  Eigen::Matrix<double, 3, 8> offset_per_bend;
  for (double& v : offset_per_bend.reshaped()) v = gain(rng);
  for (int i = 0; i < clean.size(); ++i) {
    data.poses[static_cast<std::size_t>(i)].position_mm +=
        Eigen::Vector3d(1.0, -2.0, 0.5) + offset_per_bend * clean.bends.row(i).transpose();
  }
  const TrainingSet set = make_training_set(data, design, model::InputEncoding::bend_vector);
  ComplianceStructure structure;
  structure.unloaded_mass = true;
  const ComplianceModel c = identify_compliance(set, design, structure);
  const double stiffness = simulator_segment_stiffness(design, config);
  const double off_deg = std::acos(std::min(1.0, c.gravity_direction().dot(config.gravity.direction.normalized()))) *
                         180.0 / 3.141592653589793;
  // Tolerances as without the offset, but for the platform's mass, whose
  // sag is mostly a function of the bends alone (what is left of it is the
  // change of the lever arms with the payload's own sag): 10 g.
  EXPECT_NEAR(c.compliance_rad_per_n_mm(0) * stiffness, 1.0, 1e-3);
  EXPECT_LT(off_deg, 0.05);
  EXPECT_NEAR(c.unloaded_mass_kg, config.gravity.platform_mass_kg, 0.01);
}

// The choice between no sag and a sag with an unloaded mass, on the
// prototype, with a single start of the search.
struct ChoiceSetup {
  model::RobotGeometry<double> design = model::RobotGeometry<double>::prototype();
  TrainingOptions options = [] {
    TrainingOptions o;
    o.search.restarts = 0;
    return o;
  }();
  std::vector<ComplianceStructure> structures = {ComplianceStructure{}, [] {
                                                   ComplianceStructure with_mass;
                                                   with_mass.unloaded_mass = true;
                                                   return with_mass;
                                                 }()};

  ComplianceChoice choose(const dataset::Dataset& recording) const {
    return choose_compliance(make_training_set(recording, design, model::InputEncoding::bend_vector), design, options,
                             structures);
  }
};

TEST(ComplianceIdentification, TheChoiceTakesTheSagWhereThereIsOneAndNoneWhereThereIsNot) {
  const ChoiceSetup setup;
  sim::SimulatedRobot sagging(setup.design, gravity_only());
  const ComplianceChoice with_sag = setup.choose(recorded(sagging, 80, true));
  ASSERT_TRUE(with_sag.attempted);
  EXPECT_FALSE(with_sag.model.empty());
  EXPECT_TRUE(with_sag.structure.unloaded_mass);

  // The same rows where nothing sags (gravity off), measured by motion
  // capture: the payload column is there but moves nothing, a fitted sag
  // only follows the noise, and a model without sag is the better one.
  sim::SimulatorConfig still = gravity_only();
  still.gravity.enabled = false;
  still.mocap_noise.enabled = true;
  sim::SimulatedRobot rigid(setup.design, still);
  const ComplianceChoice without_sag = setup.choose(recorded(rigid, 80, true, true));
  ASSERT_TRUE(without_sag.attempted);
  EXPECT_TRUE(without_sag.model.empty());
}

// A payload column that reads 0.5 kg over what the robot carries (a tare
// left out): the sag fits best with a platform of -0.3 kg, which no robot
// has. That candidate is reported, but the choice falls on a plausible one.
TEST(ComplianceIdentification, AnImplausibleCandidateIsNeverChosenHoweverWellItFits) {
  const ChoiceSetup setup;
  sim::SimulatedRobot sagging(setup.design, gravity_only());
  dataset::Dataset data = recorded(sagging, 80, true);
  data.payload_kg.array() += 0.5;
  const ComplianceChoice choice = setup.choose(data);
  ASSERT_TRUE(choice.attempted);
  ASSERT_EQ(choice.candidates.size(), 3u);
  const ComplianceCandidate& negative_mass = choice.candidates[2];
  EXPECT_LT(negative_mass.model.unloaded_mass_kg, -0.2);
  EXPECT_FALSE(negative_mass.plausible);
  EXPECT_GT(negative_mass.criterion, choice.candidates[1].criterion) << "it would win if it were allowed to";
  EXPECT_FALSE(choice.structure.unloaded_mass);
  EXPECT_GE(choice.model.unloaded_mass_kg, 0.0);
}

TEST(ComplianceIdentification, DataWithoutPayloadTrainsAsItAlwaysDid) {
  const auto design = model::RobotGeometry<double>::prototype();
  sim::SimulatedRobot robot(design, gravity_only());
  const TrainingSet set = make_training_set(recorded(robot, 40, false), design, model::InputEncoding::bend_vector);
  const ComplianceChoice choice = choose_compliance(set, design, TrainingOptions{});
  EXPECT_FALSE(choice.attempted);
  EXPECT_EQ(choice.skipped_reason, "the data have no payload_kg column");
  EXPECT_TRUE(choice.model.empty());
  // The empty model leaves the set bit for bit.
  const TrainingSet same = with_compliance(set, design, choice.model);
  EXPECT_EQ(same.inputs, set.inputs);
  EXPECT_EQ(same.error_twists, set.error_twists);
  for (int i = 0; i < set.size(); ++i) {
    EXPECT_EQ(same.nominal[i].matrix(), set.nominal[i].matrix()) << i;
  }
  EXPECT_THROW(identify_compliance(set, design, ComplianceStructure{}), std::invalid_argument);
}

TEST(ComplianceIdentification, TooFewRowsAreRefused) {
  const auto design = model::RobotGeometry<double>::prototype();
  sim::SimulatedRobot robot(design, gravity_only());
  ComplianceStructure structure;
  structure.unloaded_mass = true;  // 4 parameters: 8 rows at least
  const TrainingSet set = make_training_set(recorded(robot, 7, true), design, model::InputEncoding::bend_vector);
  EXPECT_THROW(identify_compliance(set, design, structure), std::invalid_argument);
  const TrainingSet enough = make_training_set(recorded(robot, 8, true), design, model::InputEncoding::bend_vector);
  EXPECT_NO_THROW(identify_compliance(enough, design, structure));
}

// cdcr train's job on payload data, below the command line: the chosen sag
// goes into the image's compliance block, the GP is fitted on the sagged
// residuals, the float32 image path (which sags the nominal pose itself)
// stays within the fidelity target of the double trainer on the payload
// rows, and the held-out error is below the payload-as-an-input model's.
TEST(PayloadTraining, TheChosenSagIsExportedAndTheImagePathFollowsTheTrainer) {
  const auto design = model::RobotGeometry<double>::prototype();
  sim::SimulatorConfig config = gravity_only();
  config.mocap_noise.enabled = true;
  sim::SimulatedRobot robot(design, config);
  const TrainingSet all = make_training_set(recorded(robot, 300, true, true), design, model::InputEncoding::bend_vector);
  const Split split = random_split(all.size(), 60, 3);
  const TrainingSet train_set = all.subset(split.train);
  const TrainingSet validation_set = all.subset(split.test);
  TrainingOptions options;
  options.search.restarts = 0;
  options.variance_rank = 16;

  const PayloadExport out = train_and_export_payload(train_set, validation_set, all, design, options, 0, 0);
  ASSERT_TRUE(out.choice.attempted);
  ASSERT_TRUE(out.uses_compliance());
  const model::PayloadCompliance<double> chosen = out.choice.model.for_model(design.segment_count);
  EXPECT_EQ(out.result.model.compliance.weighted_gravity, chosen.weighted_gravity);
  EXPECT_EQ(out.result.model.compliance.unloaded_mass_kg, chosen.unloaded_mass_kg);

  model::ImageView view{};
  ASSERT_EQ(model::parse_image(out.result.image.data(), out.result.image.size(), view), model::ImageStatus::ok);
  model::PayloadCompliance<float> from_image;
  ASSERT_TRUE(model::compliance_from_image(view, from_image));
  EXPECT_EQ(from_image.weighted_gravity, chosen.weighted_gravity.cast<float>());

  // Float32 fidelity on the held-out payload rows, both accumulators the
  // firmware builds use.
  ASSERT_EQ(out.result.fidelity_by_accumulator.size(), 3u);
  for (const auto& [accumulator, f] : out.result.fidelity_by_accumulator) {
    std::printf("  %s: max %.2e mm, %.2e deg\n", to_string(accumulator), f.max_position_mm, f.max_orientation_deg);
    if (accumulator == FirmwareAccumulator::float32) continue;
    EXPECT_LE(f.max_position_mm, 0.01) << to_string(accumulator);
    EXPECT_LE(f.max_orientation_deg, 0.001) << to_string(accumulator);
  }
  // The same measure, independently: the image path at the rows' cables
  // and payloads against the double trainer's sagged nominal pose and GP.
  const std::vector<model::Pose<double>> double_poses = compensated_poses(
      with_compliance(validation_set, design, out.choice.model),
      predict_error_twists(out.result.model, validation_set));
  const Fidelity f = compare_poses(
      double_poses, firmware_poses(view, validation_set.cables_mm, FirmwareAccumulator::compensated_float32,
                                   validation_set.payload_kg));
  EXPECT_LE(f.max_position_mm, 0.01);
  EXPECT_LE(f.max_orientation_deg, 0.001);

  // The payload-as-an-input model of the same rows, without the sag.
  const ExportResult plain = train_and_export(train_set, validation_set, all, design, options, 0, 0);
  EXPECT_TRUE(plain.model.compliance.empty());
  std::printf("  held out: %.3f mm with the sag, %.3f mm payload as an input\n",
              out.result.validation.compensated.position_mm, plain.validation.compensated.position_mm);
  EXPECT_LT(out.result.validation.compensated.position_mm, plain.validation.compensated.position_mm);
  // The nominal model without the sag, for the report.
  EXPECT_EQ(out.unsagged_validation.initial.position_mm, mean_errors(validation_set.measured, validation_set.nominal).position_mm);
}

TEST(PayloadTraining, RowsWithoutAPayloadAreRefused) {
  const auto design = model::RobotGeometry<double>::prototype();
  sim::SimulatedRobot robot(design, gravity_only());
  const TrainingSet set = make_training_set(recorded(robot, 40, false), design, model::InputEncoding::bend_vector);
  EXPECT_THROW(train_and_export_payload(set, TrainingSet{}, set, design, TrainingOptions{}, 0, 0),
               std::invalid_argument);
}

}  // namespace
}  // namespace cdcr::training
