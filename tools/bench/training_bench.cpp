// Hyperparameter search of the trainer on a dataset, timed, and the same
// normalised training data written out so scikit-learn can fit it in the same
// run (tools/bench/run_training_bench.sh drives both).
//
//   cdcr-bench-training --data data.csv --samples 700 --restarts 2 --repetitions 3 --export xy.json
//
// Prints one JSON object: median seconds, the log marginal likelihood reached,
// the likelihood evaluations it took, the hyperparameters, and the floor: the
// flops of one evaluation (Cholesky factor, inverse and the gradient's
// products) at the rate this machine reaches on a BLAS dense product of the
// same size, times the evaluations.

#include <algorithm>
#include <chrono>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "cdcr/model/geometry.hpp"
#include "dataset/csv_dataset.hpp"
#include "train/hyperparameter_search.hpp"
#include "train/json_rows.hpp"
#include "train/lapack.hpp"
#include "train/trainer.hpp"
#include "train/training_set.hpp"

int main(int argc, char** argv) {
  using namespace cdcr;
  std::string data_path;
  std::string export_path;
  int samples = 700;
  int restarts = 0;
  int repetitions = 3;
  CLI::App app{"Times the GP hyperparameter search on a dataset"};
  app.add_option("--data", data_path, "Dataset CSV with poses")->required();
  app.add_option("--samples", samples, "Training samples (the first N rows)");
  app.add_option("--restarts", restarts, "Random restarts after the first start")->capture_default_str();
  app.add_option("--repetitions", repetitions, "Timed repetitions; the median is reported");
  app.add_option("--export", export_path, "Write the normalised X, Y and the search bounds as JSON");
  CLI11_PARSE(app, argc, argv);

  try {
    const dataset::Dataset data = dataset::read_dataset_csv(data_path, dataset::PoseColumns::required);
    const auto geometry = model::RobotGeometry<double>::uniform(
        data.segment_count, model::kPrototypeBackboneLengthMm, model::kPrototypeAnchorRadiusMm);
    const training::TrainingSet all =
        training::make_training_set(data, geometry, model::InputEncoding::bend_vector);
    std::vector<int> first(static_cast<std::size_t>(std::min(samples, all.size())));
    for (std::size_t i = 0; i < first.size(); ++i) first[i] = static_cast<int>(i);
    const training::TrainingSet set = all.subset(first);
    const training::Normalisation n = training::normalisation_of(set);
    const Eigen::MatrixXd x = training::normalise(set.inputs, n.input_mean, n.input_scale);
    const Eigen::MatrixXd y = training::normalise(set.error_twists, n.output_mean, n.output_scale);

    training::SearchOptions options;
    options.restarts = restarts;
    if (!export_path.empty()) {
      const training::SearchBounds& b = options.bounds;
      nlohmann::json j;
      j["x"] = training::json_rows(x);
      j["y"] = training::json_rows(y);
      j["bounds"] = {{"length_scale", {b.length_scale_min, b.length_scale_max}},
                     {"signal_variance", {b.signal_variance_min, b.signal_variance_max}},
                     {"noise_variance", {b.noise_variance_min, b.noise_variance_max}}};
      std::ofstream(export_path) << j.dump();
    }

    std::vector<double> seconds;
    training::SearchResult result;
    for (int r = 0; r < repetitions; ++r) {
      const auto start = std::chrono::steady_clock::now();
      result = training::maximise_likelihood(x, y, training::default_initial_hyperparameters(static_cast<int>(x.cols())),
                                             options);
      seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
    std::sort(seconds.begin(), seconds.end());
    // What this machine reaches on an N x N dense product (2 N^3 flops)
    // through the BLAS the trainer uses, on the threads its calls get
    // (OPENBLAS_NUM_THREADS; one under run_training_bench.sh), the best of
    // five.
    const Eigen::Index nn = x.rows();
    const Eigen::MatrixXd a = Eigen::MatrixXd::Random(nn, nn), b = Eigen::MatrixXd::Random(nn, nn);
    Eigen::MatrixXd c(nn, nn);
    double best_product_s = 1e9;
    for (int k = 0; k < 5; ++k) {
      const auto start = std::chrono::steady_clock::now();
      training::lapack::multiply(a, b, c);
      best_product_s = std::min(best_product_s,
                                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
    const double flops_per_second = 2.0 * double(nn) * double(nn) * double(nn) / best_product_s;
    // One evaluation: the Cholesky factor (N^3 / 3), the triangular inverse
    // and the lower triangle of L^-T L^-1 (N^3 / 3 each), alpha (2 N^2 m),
    // and the gradient's products (W .* K and M a, about 4 N^2 D).
    const double dims = double(x.cols()), outputs = double(y.cols()), n3 = double(nn) * double(nn) * double(nn);
    const double flops_per_evaluation = n3 + double(nn) * double(nn) * (2.0 * outputs + 4.0 * dims);
    nlohmann::json out;
    out["samples"] = set.size();
    out["inputs"] = x.cols();
    out["outputs"] = y.cols();
    out["starts"] = restarts + 1;
    out["median_seconds"] = seconds[seconds.size() / 2];
    out["seconds"] = seconds;
    out["log_marginal_likelihood"] = result.log_marginal_likelihood;
    out["likelihood_evaluations"] = result.likelihood_evaluations;
    out["flops_per_evaluation"] = flops_per_evaluation;
    out["achieved_gflops"] = flops_per_second * 1e-9;
    out["floor_seconds"] = double(result.likelihood_evaluations) * flops_per_evaluation / flops_per_second;
    const auto& h = result.hyperparameters;
    out["length_scales"] = std::vector<double>(h.length_scales.data(), h.length_scales.data() + h.length_scales.size());
    out["signal_variance"] = h.signal_variance;
    out["noise_variance"] = h.noise_variance;
    std::cout << out.dump() << '\n';
  } catch (const std::exception& e) {
    std::cerr << "cdcr-bench-training: " << e.what() << '\n';
    return 1;
  }
  return 0;
}
