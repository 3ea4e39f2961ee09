#include "training_commands.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <optional>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "cli_errors.hpp"
#include "dataset_input.hpp"
#include "json_output.hpp"
#include "number_list.hpp"
#include "svg_chart.hpp"
#include "train/learning_curve.hpp"
#include "pipeline/train_and_export.hpp"
#include "training_options.hpp"

namespace cdcr::cli {
namespace {

struct LearningCurveOptions {
  std::string data_path;
  std::string test_data_path;
  std::string sizes = "100,200,300,400,500,600,700";
  int test_size = 50;
  std::string encodings = "bend-vector,joint-angles";
  std::string models = "exact";
  int inducing = 256;
  std::string inducing_sizes;
  std::string sharing = "shared";
  std::string plot_prefix = "learning-curve";
  std::string noise_floor;  // "POSITION_MM,ORIENTATION_DEG", drawn as a reference line
  GeometryOptions geometry;
  TrainingFlags training;
  bool json = false;
};

struct Series {
  std::string label;
  training::LearningCurve curve;
};

const char* kColours[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd"};

void write_text(const std::string& path, const std::string& text) {
  std::ofstream file(path, std::ios::trunc);
  if (!file) throw InputError(fmt::format("{}: cannot open for writing", path));
  file << text;
}

enum class Quantity { position, orientation, seconds };

double value_of(const training::LearningCurvePoint& p, Quantity q) {
  switch (q) {
    case Quantity::position: return p.compensated.position_mm;
    case Quantity::orientation: return p.compensated.orientation_deg;
    case Quantity::seconds: return p.seconds;
  }
  return 0.0;
}

// x: the training samples, or the model's points for the curve against M.
Chart make_chart(const std::vector<Series>& series, Quantity q, bool against_points,
                 const std::vector<double>& noise_floor) {
  Chart chart;
  // The nominal model's error is far above the curves; it goes in the title
  // rather than on the axis, where it would flatten them.
  const training::MeanErrors& initial = series.front().curve.initial;
  const std::string fixed_n =
      against_points ? fmt::format(", N = {}", series.front().curve.points.front().training_samples) : "";
  switch (q) {
    case Quantity::position:
      chart.title = fmt::format("Residual position error{} (nominal model: {:.1f} mm)", fixed_n, initial.position_mm);
      chart.y_label = "Mean position error (mm)";
      break;
    case Quantity::orientation:
      chart.title =
          fmt::format("Residual orientation error{} (nominal model: {:.2f} deg)", fixed_n, initial.orientation_deg);
      chart.y_label = "Mean orientation error (deg)";
      break;
    case Quantity::seconds:
      chart.title = "Training time";
      chart.y_label = "Seconds";
      break;
  }
  chart.x_label = against_points ? "Inducing points M" : "Number of training samples";
  double x_min = 0.0, x_max = 0.0;
  for (std::size_t i = 0; i < series.size(); ++i) {
    ChartSeries s;
    s.label = series[i].label;
    s.colour = kColours[i % 4];
    for (const auto& p : series[i].curve.points) {
      s.x.push_back(against_points ? p.model_points : p.training_samples);
      s.y.push_back(value_of(p, q));
    }
    x_min = i == 0 ? s.x.front() : std::min(x_min, s.x.front());
    x_max = i == 0 ? s.x.back() : std::max(x_max, s.x.back());
    chart.series.push_back(s);
  }
  if (noise_floor.size() == 2 && q != Quantity::seconds) {
    const double v = q == Quantity::position ? noise_floor[0] : noise_floor[1];
    chart.series.push_back(ChartSeries{"noise floor", {x_min, x_max}, {v, v}, "#ff7f0e", true, false});
  }
  return chart;
}

std::vector<std::string> parse_names(const std::string& list, const char* option,
                                     std::initializer_list<const char*> known) {
  std::vector<std::string> names;
  std::stringstream stream(list);
  for (std::string name; std::getline(stream, name, ',');) {
    if (std::none_of(known.begin(), known.end(), [&name](const char* k) { return name == k; })) {
      throw UsageError(fmt::format("{}: unknown name '{}'", option, name));
    }
    names.push_back(name);
  }
  if (names.empty()) throw UsageError(fmt::format("{}: give at least one", option));
  return names;
}

std::vector<int> parse_sizes(const std::string& list, const char* option) {
  std::vector<int> sizes;
  for (double v : parse_number_list(list, option)) {
    if (!(v >= 1.0 && v <= 1e6) || v != std::floor(v)) {
      throw InputError(fmt::format("{}: {} is not a whole number of samples", option, v));
    }
    sizes.push_back(static_cast<int>(v));
  }
  return sizes;
}

Json curve_json(const training::LearningCurve& curve) {
  Json rows = Json::array();
  for (const auto& p : curve.points) {
    rows.push_back({{"training_samples", p.training_samples},
                    {"model_points", p.model_points},
                    {"position_mm", p.compensated.position_mm},
                    {"orientation_deg", p.compensated.orientation_deg},
                    {"seconds", p.seconds}});
  }
  return rows;
}

std::string curve_table(const std::vector<Series>& series, bool against_points) {
  std::string t = fmt::format("{:>10}", against_points ? "inducing" : "training");
  for (const Series& c : series) t += fmt::format(" | {:^38}", c.label);
  t += fmt::format("\n{:>10}", against_points ? "points" : "samples");
  for (std::size_t i = 0; i < series.size(); ++i) {
    t += fmt::format(" | {:>13} {:>15} {:>8}", "position (mm)", "orient. (deg)", "seconds");
  }
  t += "\n";
  for (std::size_t row = 0; row < series.front().curve.points.size(); ++row) {
    const auto& first = series.front().curve.points[row];
    t += fmt::format("{:>10}", against_points ? first.model_points : first.training_samples);
    for (const Series& c : series) {
      const auto& p = c.curve.points[row];
      t += fmt::format(" | {:13.4f} {:15.4f} {:8.2f}", p.compensated.position_mm, p.compensated.orientation_deg,
                       p.seconds);
    }
    t += "\n";
  }
  return t;
}

CommandOutput run_learning_curve(const LearningCurveOptions& o) {
  training::TrainingOptions options = make_training_options(o.training);
  if (o.sharing == "per-output") options.sharing = training::HyperparameterSharing::per_output;
  const std::vector<int> sizes = parse_sizes(o.sizes, "--sizes");
  const std::vector<int> inducing_sizes =
      o.inducing_sizes.empty() ? std::vector<int>{} : parse_sizes(o.inducing_sizes, "--inducing-sizes");
  if (o.inducing < 1) throw InputError(fmt::format("--inducing must be positive (got {})", o.inducing));
  std::vector<double> noise_floor;
  if (!o.noise_floor.empty()) {
    noise_floor = parse_number_list(o.noise_floor, "--noise-floor");
    if (noise_floor.size() != 2) throw InputError("--noise-floor takes POSITION_MM,ORIENTATION_DEG");
  }
  const std::vector<std::string> encodings =
      parse_names(o.encodings, "--encodings", {"bend-vector", "joint-angles"});
  const std::vector<std::string> models = parse_names(o.models, "--models", {"exact", "sparse"});
  if (options.sharing != training::HyperparameterSharing::shared &&
      (models != std::vector<std::string>{"exact"} || !inducing_sizes.empty())) {
    throw InputError("--sharing per-output is measured with exact GPs only");
  }

  const dataset::Dataset data = load_dataset(o.data_path, true);
  const model::RobotGeometry<double> geometry = geometry_for(data, o.geometry);
  std::optional<dataset::Dataset> test_data;
  if (!o.test_data_path.empty()) test_data = load_dataset(o.test_data_path, true);
  // A learning curve measures models of any size, not only those a board runs.
  options.board.capacity_points = static_cast<std::uint32_t>(data.sample_count());
  options.board.flash_budget_bytes = std::numeric_limits<std::uint32_t>::max();
  options.board.forward_cycle_instructions = std::numeric_limits<std::uint32_t>::max();

  std::vector<Series> curves;
  std::vector<Series> inducing_curves;
  try {
    for (const std::string& encoding : encodings) {
      options.encoding = parse_encoding(encoding);
      const training::TrainingSet all = training::make_training_set(data, geometry, options.encoding);
      training::TrainingSet pool = all;
      training::TrainingSet test;
      if (test_data) {
        test = training::make_training_set(*test_data, geometry, options.encoding);
      } else {
        const training::Split split = training::random_split(all.size(), o.test_size, o.training.seed);
        pool = all.subset(split.train);
        test = all.subset(split.test);
      }
      for (const std::string& model : models) {
        options.model = model == "sparse" ? training::ModelChoice::sparse : training::ModelChoice::exact;
        options.inducing_points = model == "sparse" ? o.inducing : 0;
        std::string label = encoding;
        if (models.size() > 1 || model == "sparse") {
          const std::string model_label = model == "sparse" ? fmt::format("sparse, M = {}", o.inducing) : "exact";
          label = encodings.size() > 1 ? fmt::format("{}, {}", encoding, model_label) : model_label;
        }
        curves.push_back({label, training::learning_curve(pool, test, sizes, o.training.seed, options, geometry)});
      }
      if (!inducing_sizes.empty() && encoding == encodings.front()) {
        inducing_curves.push_back(
            {fmt::format("sparse, N = {}", sizes.back()),
             training::inducing_curve(pool, test, sizes.back(), inducing_sizes, o.training.seed, options, geometry)});
      }
    }
  } catch (const std::invalid_argument& e) {
    throw InputError(fmt::format("{}: {}", o.data_path, e.what()));
  }

  std::vector<std::string> plots = {o.plot_prefix + "-position.svg", o.plot_prefix + "-orientation.svg"};
  write_text(plots[0], render_svg(make_chart(curves, Quantity::position, false, noise_floor)));
  write_text(plots[1], render_svg(make_chart(curves, Quantity::orientation, false, noise_floor)));
  if (models.size() > 1 || !inducing_sizes.empty()) {
    plots.push_back(o.plot_prefix + "-time.svg");
    write_text(plots.back(), render_svg(make_chart(curves, Quantity::seconds, false, {})));
  }
  if (!inducing_curves.empty()) {
    plots.push_back(o.plot_prefix + "-inducing-position.svg");
    write_text(plots.back(), render_svg(make_chart(inducing_curves, Quantity::position, true, noise_floor)));
    plots.push_back(o.plot_prefix + "-inducing-orientation.svg");
    write_text(plots.back(), render_svg(make_chart(inducing_curves, Quantity::orientation, true, noise_floor)));
  }

  CommandOutput output;
  const training::MeanErrors& initial = curves.front().curve.initial;
  if (o.json) {
    Json j;
    j["test_samples"] = curves.front().curve.test_samples;
    j["initial"] = {{"position_mm", initial.position_mm}, {"orientation_deg", initial.orientation_deg}};
    for (const Series& c : curves) j["curves"][c.label] = curve_json(c.curve);
    for (const Series& c : inducing_curves) j["inducing_curves"][c.label] = curve_json(c.curve);
    j["plots"] = plots;
    output.text = j.dump() + "\n";
    return output;
  }
  std::string t = fmt::format("test set: {} {}samples; initial mean error {:.4f} mm, {:.4f} deg\n",
                              curves.front().curve.test_samples, test_data ? "" : "held-out ",
                              initial.position_mm, initial.orientation_deg);
  t += curve_table(curves, false);
  if (!inducing_curves.empty()) t += curve_table(inducing_curves, true);
  t += "plots:";
  for (const std::string& plot : plots) t += " " + plot;
  output.text = t + "\n";
  return output;
}

}  // namespace

void register_learning_curve_command(CLI::App& app, CommandOutput& output) {
  auto o = std::make_shared<LearningCurveOptions>();
  CLI::App* command =
      app.add_subcommand("learning-curve", "Residual error vs number of training samples (the paper's protocol)");
  command->add_option("--data", o->data_path, "Dataset CSV with measured poses")->required();
  command->add_option("--sizes", o->sizes, "Training set sizes")->capture_default_str();
  command->add_option("--test-size", o->test_size, "Samples held out for testing")->capture_default_str();
  command->add_option("--test-data", o->test_data_path,
                      "Test set collected apart (e.g. cdcr simulate --session 1); every row of --data may train");
  command->add_option("--models", o->models, "GPs to compare: exact, sparse")->capture_default_str();
  command->add_option("--inducing", o->inducing, "Inducing points M of the sparse model (at most N)")
      ->capture_default_str();
  command->add_option("--inducing-sizes", o->inducing_sizes,
                      "Also the sparse model's error against M at the largest of --sizes, for these M");
  command->add_option("--encodings", o->encodings, "Input encodings to compare")->capture_default_str();
  command->add_option("--sharing", o->sharing, "Hyperparameters shared by the six outputs, or one set per output")
      ->check(CLI::IsMember({"shared", "per-output"}))
      ->capture_default_str();
  command->add_option("--plot-prefix", o->plot_prefix, "Plots go to PREFIX-position.svg and PREFIX-orientation.svg")
      ->capture_default_str();
  command->add_option("--noise-floor", o->noise_floor, "Reference line on the plots: POSITION_MM,ORIENTATION_DEG");
  add_geometry_options(*command, o->geometry, "Number of segments (default: from the dataset's cable columns)");
  add_training_flags(*command, o->training, false);
  command->add_flag("--json", o->json, "Print one JSON object");
  command->callback([o, &output] { output = run_learning_curve(*o); });
}

}  // namespace cdcr::cli
