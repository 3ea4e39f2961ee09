#include "learning_curve_command.hpp"

#include <fstream>
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
#include "training_options.hpp"

namespace cdcr::cli {
namespace {

struct LearningCurveOptions {
  std::string data_path;
  std::string sizes = "100,200,300,400,500,600,700";
  int test_size = 50;
  std::string encodings = "bend-vector,joint-angles";
  std::string sharing = "shared";
  std::string plot_prefix = "learning-curve";
  std::string noise_floor;  // "POSITION_MM,ORIENTATION_DEG", drawn as a reference line
  GeometryOptions geometry;
  TrainingFlags training;
  bool json = false;
};

struct EncodingCurve {
  std::string encoding;
  training::LearningCurve curve;
};

const char* kColours[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd"};

void write_text(const std::string& path, const std::string& text) {
  std::ofstream file(path, std::ios::trunc);
  if (!file) throw InputError(fmt::format("{}: cannot open for writing", path));
  file << text;
}

Chart make_chart(const std::vector<EncodingCurve>& curves, bool position, const std::vector<double>& noise_floor) {
  Chart chart;
  // The nominal model's error is far above the curves; it goes in the title
  // rather than on the axis, where it would flatten them.
  const training::MeanErrors& initial = curves.front().curve.initial;
  chart.title = position ? fmt::format("Residual position error (nominal model: {:.1f} mm)", initial.position_mm)
                         : fmt::format("Residual orientation error (nominal model: {:.2f} deg)", initial.orientation_deg);
  chart.x_label = "Number of training samples";
  chart.y_label = position ? "Mean position error (mm)" : "Mean orientation error (deg)";
  std::vector<double> x;
  for (const auto& p : curves.front().curve.points) x.push_back(p.training_samples);
  for (std::size_t i = 0; i < curves.size(); ++i) {
    ChartSeries s;
    s.label = curves[i].encoding;
    s.colour = kColours[i % 4];
    s.x = x;
    for (const auto& p : curves[i].curve.points) {
      s.y.push_back(position ? p.compensated.position_mm : p.compensated.orientation_deg);
    }
    chart.series.push_back(s);
  }
  if (noise_floor.size() == 2) {
    const double v = position ? noise_floor[0] : noise_floor[1];
    chart.series.push_back(ChartSeries{"noise floor", {x.front(), x.back()}, {v, v}, "#ff7f0e", true, false});
  }
  return chart;
}

CommandOutput run_learning_curve(const LearningCurveOptions& o) {
  training::TrainingOptions options = make_training_options(o.training);
  if (o.sharing == "per-output") options.sharing = training::HyperparameterSharing::per_output;
  std::vector<int> sizes;
  for (double v : parse_number_list(o.sizes, "--sizes")) sizes.push_back(static_cast<int>(v));
  std::vector<double> noise_floor;
  if (!o.noise_floor.empty()) {
    noise_floor = parse_number_list(o.noise_floor, "--noise-floor");
    if (noise_floor.size() != 2) throw InputError("--noise-floor takes POSITION_MM,ORIENTATION_DEG");
  }
  std::vector<std::string> encodings;
  {
    std::stringstream list(o.encodings);
    for (std::string name; std::getline(list, name, ',');) {
      if (name != "bend-vector" && name != "joint-angles") {
        throw UsageError(fmt::format("--encodings: unknown encoding '{}'", name));
      }
      encodings.push_back(name);
    }
  }
  if (encodings.empty()) throw UsageError("--encodings: give at least one encoding");

  const dataset::Dataset data = load_dataset(o.data_path, true);
  const model::RobotGeometry<double> geometry = geometry_for(data, o.geometry);
  std::vector<EncodingCurve> curves;
  try {
    for (const std::string& name : encodings) {
      options.encoding = parse_encoding(name);
      const training::TrainingSet all = training::make_training_set(data, geometry, options.encoding);
      curves.push_back({name, training::learning_curve(all, sizes, o.test_size, o.training.seed, options, geometry)});
    }
  } catch (const std::invalid_argument& e) {
    throw InputError(fmt::format("{}: {}", o.data_path, e.what()));
  }

  const std::string position_plot = o.plot_prefix + "-position.svg";
  const std::string orientation_plot = o.plot_prefix + "-orientation.svg";
  write_text(position_plot, render_svg(make_chart(curves, true, noise_floor)));
  write_text(orientation_plot, render_svg(make_chart(curves, false, noise_floor)));

  CommandOutput output;
  const training::MeanErrors& initial = curves.front().curve.initial;
  if (o.json) {
    Json j;
    j["test_samples"] = curves.front().curve.test_samples;
    j["initial"] = {{"position_mm", initial.position_mm}, {"orientation_deg", initial.orientation_deg}};
    for (const EncodingCurve& c : curves) {
      Json rows = Json::array();
      for (const auto& p : c.curve.points) {
        rows.push_back({{"training_samples", p.training_samples},
                        {"position_mm", p.compensated.position_mm},
                        {"orientation_deg", p.compensated.orientation_deg},
                        {"seconds", p.seconds}});
      }
      j["curves"][c.encoding] = rows;
    }
    j["plots"] = {position_plot, orientation_plot};
    output.text = j.dump() + "\n";
    return output;
  }
  std::string t = fmt::format("test set: {} held-out samples; initial mean error {:.4f} mm, {:.4f} deg\n",
                              curves.front().curve.test_samples, initial.position_mm, initial.orientation_deg);
  t += fmt::format("{:>10}", "training");
  for (const EncodingCurve& c : curves) t += fmt::format(" | {:^29}", c.encoding);
  t += fmt::format("\n{:>10}", "samples");
  for (std::size_t i = 0; i < curves.size(); ++i) t += fmt::format(" | {:>13} {:>15}", "position (mm)", "orient. (deg)");
  t += "\n";
  for (std::size_t row = 0; row < sizes.size(); ++row) {
    t += fmt::format("{:>10}", sizes[row]);
    for (const EncodingCurve& c : curves) {
      t += fmt::format(" | {:13.4f} {:15.4f}", c.curve.points[row].compensated.position_mm,
                       c.curve.points[row].compensated.orientation_deg);
    }
    t += "\n";
  }
  t += fmt::format("plots: {}, {}\n", position_plot, orientation_plot);
  output.text = t;
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
