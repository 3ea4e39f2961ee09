// The payload model with the segments' compliance identified (issue 25, "the
// payload's load"; train/compliance_identification.hpp), measured against
// today's payload model on the same rows with the same GP search as `cdcr
// train` with its defaults (50 of the training rows held out, the search on
// the rest, the model refitted on every row).
//
// The compliance is identified and chosen on the search's rows; every
// candidate structure is then trained (the GP on what the sagged nominal
// model leaves, the payload still an input) and evaluated on the test rows,
// so the criterion's choice can be checked against the test error. Prints
// the baseline and the chosen model last, against the test rows' floor:
//
//   cdcr-bench-compliance --train session0.csv --test session1.csv
//       [--segments 4 --length 110 --radius 60] [--floor-mm F --floor-deg G]

#include <cmath>
#include <cstdio>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <Eigen/Core>

#include "cdcr/model/geometry.hpp"
#include "dataset/csv_dataset.hpp"
#include "train/compliance_identification.hpp"
#include "train/evaluation.hpp"
#include "train/model_selection.hpp"
#include "train/trainer.hpp"
#include "train/training_set.hpp"

namespace {

using cdcr::model::RobotGeometry;
using cdcr::training::TrainingSet;

struct Outcome {
  cdcr::training::MeanErrors test;
  double log_marginal_likelihood = 0.0;
  cdcr::training::MeanErrors validation;  // the 50 held-out rows, by the searched model
};

Outcome train_and_test(const TrainingSet& all, const TrainingSet& test, const RobotGeometry<double>& g) {
  using namespace cdcr::training;
  TrainingOptions options;
  options.search.restarts = 2;
  options.search.seed = 1;
  const Split split = random_split(all.size(), 50, options.search.seed);
  const TrainingSet train_set = all.subset(split.train);
  const ModelSelection shipped = select_model(all.size(), static_cast<int>(all.inputs.cols()), g.segment_count,
                                              options.model, options.inducing_points, options.board);
  TrainingOptions search_options = options;
  search_options.model = shipped.kind == ModelKind::exact ? ModelChoice::exact : ModelChoice::sparse;
  search_options.inducing_points = shipped.kind == ModelKind::exact ? 0 : std::min(shipped.points, train_set.size());
  TrainingReport report;
  const TrainedModel searched = train(train_set, g, search_options, &report);
  const TrainingSet validation = all.subset(split.test);
  Outcome o;
  o.validation = evaluate(validation, predict_error_twists(searched, validation)).compensated;
  o.log_marginal_likelihood = report.log_marginal_likelihood;
  const TrainedModel model = refit(searched, shipped.kind, all);
  o.test = evaluate(test, predict_error_twists(model, test)).compensated;
  return o;
}

void print_row(const char* name, const Outcome& o, double floor_mm, double floor_deg) {
  const cdcr::training::MeanErrors& e = o.test;
  std::printf("  %-26s %7.3f mm %7.4f deg  (LML %9.1f, validation %.3f mm %.4f deg)", name, e.position_mm,
              e.orientation_deg, o.log_marginal_likelihood, o.validation.position_mm, o.validation.orientation_deg);
  if (floor_mm > 0.0 && floor_deg > 0.0) {
    std::printf("   %.2fx %.2fx the floor", e.position_mm / floor_mm, e.orientation_deg / floor_deg);
  }
  std::printf("\n");
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"The payload model with identified segment compliance against today's"};
  std::string train_path, test_path;
  std::optional<int> segments;
  double length_mm = cdcr::model::kPrototypeBackboneLengthMm, radius_mm = cdcr::model::kPrototypeAnchorRadiusMm;
  double floor_mm = 0.0, floor_deg = 0.0;
  app.add_option("--train", train_path, "Training dataset CSV with a payload_kg column")->required();
  app.add_option("--test", test_path, "Test dataset CSV with a payload_kg column")->required();
  app.add_option("--segments", segments, "Segment count (default: the data's)");
  app.add_option("--length", length_mm, "Nominal backbone length (mm)");
  app.add_option("--radius", radius_mm, "Nominal anchor radius (mm)");
  app.add_option("--floor-mm", floor_mm, "The test rows' noise floor, position (mm)");
  app.add_option("--floor-deg", floor_deg, "The test rows' noise floor, orientation (deg)");
  CLI11_PARSE(app, argc, argv);
  try {
    using namespace cdcr;
    const dataset::Dataset train_data = dataset::read_dataset_csv(train_path, dataset::PoseColumns::required);
    const dataset::Dataset test_data = dataset::read_dataset_csv(test_path, dataset::PoseColumns::required);
    if (!train_data.has_payload || !test_data.has_payload) throw std::invalid_argument("both datasets need a payload_kg column");
    const auto g = model::RobotGeometry<double>::uniform(segments.value_or(train_data.segment_count), length_mm, radius_mm);
    const training::TrainingSet all = training::make_training_set(train_data, g, model::InputEncoding::bend_vector);
    const training::TrainingSet test = training::make_training_set(test_data, g, model::InputEncoding::bend_vector);
    std::printf("  %-26s %7.3f mm %7.4f deg\n", "nominal", training::mean_errors(test.measured, test.nominal).position_mm,
                training::mean_errors(test.measured, test.nominal).orientation_deg);
    const Outcome baseline = train_and_test(all, test, g);
    print_row("baseline (payload input)", baseline, floor_mm, floor_deg);
    // Identified and chosen on the search's 650 training rows, as the
    // trainer would.
    const training::Split split = training::random_split(all.size(), 50, 1);
    training::TrainingOptions options;
    options.search.restarts = 2;
    options.search.seed = 1;
    const training::ComplianceChoice choice = training::choose_compliance(all.subset(split.train), g, options);
    Outcome chosen = baseline;
    for (const training::ComplianceCandidate& c : choice.candidates) {
      const std::string name = c.none ? std::string("none") : c.structure.name();
      if (c.none) {
        std::printf("  %-34s criterion %9.1f\n", "none (the baseline)", c.criterion);
        continue;
      }
      const Eigen::Vector3d direction = c.model.gravity_direction();
      std::printf("  %-34s criterion %9.1f%s; c_0 %.3e rad/(N mm), ratios", name.c_str(), c.criterion,
                  c.plausible ? "" : " (implausible)", c.model.compliance_rad_per_n_mm(0));
      for (const double r : c.model.ratio) std::printf(" %.3f", r);
      std::printf(", softening %.3f /rad, m_0 %.3f kg, g along (%.3f %.3f %.3f)\n", c.model.softening_per_rad,
                  c.model.unloaded_mass_kg, direction.x(), direction.y(), direction.z());
      const Outcome o = train_and_test(training::with_compliance(all, g, c.model),
                                       training::with_compliance(test, g, c.model), g);
      print_row("    + GP", o, floor_mm, floor_deg);
      if (!choice.model.empty() && c.structure.name() == choice.structure.name()) chosen = o;
    }
    std::printf("  chosen by the criterion: %s\n", choice.model.empty() ? "none" : choice.structure.name().c_str());
    print_row("baseline (payload input)", baseline, floor_mm, floor_deg);
    print_row("compliance (chosen) + GP", chosen, floor_mm, floor_deg);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "cdcr-bench-compliance: %s\n", e.what());
    return 1;
  }
  return 0;
}
