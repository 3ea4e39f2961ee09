#include "hysteresis_identification.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numeric>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>

#include "cdcr/model/hysteresis_sequence.hpp"
#include "cdcr/model/limits.hpp"
#include "gaussian_process.hpp"
#include "hyperparameter_search.hpp"

namespace cdcr::training {

Eigen::MatrixXd effective_cables(const Eigen::MatrixXd& commanded_mm, const std::vector<int>& session_starts,
                                 const model::HysteresisModel<double>& hysteresis,
                                 const model::RobotGeometry<double>& geometry, model::SessionStart start,
                                 Eigen::MatrixXd* history) {
  if (hysteresis.empty()) return commanded_mm;
  const auto rows = static_cast<int>(commanded_mm.rows());
  if (hysteresis.cables != commanded_mm.cols()) {
    throw std::invalid_argument("the hysteresis model has " + std::to_string(hysteresis.cables) +
                                " cables, the rows have " + std::to_string(commanded_mm.cols()));
  }
  if (rows > 0 && (session_starts.empty() || session_starts.front() != 0)) {
    throw std::invalid_argument("a sequence's first session must start at row 0");
  }
  for (std::size_t i = 1; i < session_starts.size(); ++i) {
    if (session_starts[i] <= session_starts[i - 1] || session_starts[i] >= rows) {
      throw std::invalid_argument("session starts must increase within the rows (session " + std::to_string(i + 1) +
                                  " starts at row " + std::to_string(session_starts[i] + 1) + ")");
    }
  }
  // The same sequence code the replay and the evaluation run in float32.
  Eigen::MatrixXd effective(commanded_mm.rows(), commanded_mm.cols());
  if (history != nullptr) history->resize(commanded_mm.rows(), commanded_mm.cols());
  const model::Status status = model::effective_lengths_over_sequence(
      hysteresis, geometry, commanded_mm, session_starts.data(), static_cast<int>(session_starts.size()), effective,
      start, history);
  if (status != model::Status::ok) throw std::invalid_argument(std::string("homing move: ") + model::to_string(status));
  return effective;
}

TrainingSet make_sequence_training_set(const dataset::Dataset& data, const model::HysteresisModel<double>& hysteresis,
                                       const model::RobotGeometry<double>& geometry, model::InputEncoding encoding,
                                       bool with_payload) {
  if (!data.has_time) throw std::invalid_argument("a hysteresis model needs a motion sequence (a t_s column)");
  const bool with_history = model::takes_history(encoding);
  if (with_history && hysteresis.empty()) {
    throw std::invalid_argument("the history inputs need a hysteresis model to keep them");
  }
  dataset::Dataset effective = data;
  Eigen::MatrixXd history;
  effective.cables_mm = effective_cables(data.cables_mm, data.session_starts, hysteresis, geometry,
                                         session_start(data), with_history ? &history : nullptr);
  TrainingSet set = make_training_set(effective, geometry, model::with_history(encoding, false), with_payload);
  set.commanded_mm = data.cables_mm;
  if (!with_history) return set;
  set.history_inputs = std::move(history);
  return with_encoding(set, encoding);
}

const char* to_string(HysteresisSharing sharing) {
  switch (sharing) {
    case HysteresisSharing::none: return "none";
    case HysteresisSharing::all_cables: return "one width for all cables";
    case HysteresisSharing::per_segment: return "one width per segment";
    case HysteresisSharing::per_cable: return "one width per cable";
  }
  return "?";
}

namespace {

// The segment cable `cable` of the robot's (segment by segment) belongs to.
int segment_of(const model::RobotGeometry<double>& geometry, int cable) {
  int segment = 0;
  while (segment + 1 < geometry.segment_count && geometry.first_cable(segment + 1) <= cable) ++segment;
  return segment;
}

// A candidate structure and its parameters: the widths of its groups (the
// largest operator's, mm), then the K weights shared by every cable.
struct Shape {
  HysteresisSharing sharing = HysteresisSharing::none;
  int operators = 0;
  const model::RobotGeometry<double>* geometry = nullptr;  // whose cables (not for none)

  int groups() const {
    switch (sharing) {
      case HysteresisSharing::none: return 0;
      case HysteresisSharing::all_cables: return 1;
      case HysteresisSharing::per_segment: return geometry->segment_count;
      case HysteresisSharing::per_cable: return geometry->cable_count();
    }
    return 0;
  }
  int group_of(int cable) const {
    switch (sharing) {
      case HysteresisSharing::per_segment: return segment_of(*geometry, cable);
      case HysteresisSharing::per_cable: return cable;
      default: return 0;
    }
  }
  int parameters() const { return sharing == HysteresisSharing::none ? 0 : groups() + operators; }
};

model::HysteresisModel<double> model_for(const Shape& shape, const Eigen::VectorXd& parameters,
                                         const model::RobotGeometry<double>& geometry) {
  model::HysteresisModel<double> m;
  if (shape.sharing == HysteresisSharing::none) return m;
  m.cables = geometry.cable_count();
  m.operators = shape.operators;
  const int groups = shape.groups();
  for (int c = 0; c < m.cables; ++c) {
    const double width = parameters[shape.group_of(c)];
    for (int k = 0; k < m.operators; ++k) {
      // The fixed ratio of the shape: the operators' widths r/K, 2r/K, ..., r.
      m.widths_mm[c][k] = width * double(k + 1) / double(m.operators);
      m.weights[c][k] = parameters[groups + k];
    }
  }
  model::CableVector<double> approach_mm, home_mm;
  if (const model::Status s = model::homing_waypoints(geometry, approach_mm, home_mm); s != model::Status::ok) {
    throw std::invalid_argument(std::string("homing move: ") + model::to_string(s));
  }
  model::compute_homing_lags(m, approach_mm, home_mm);
  return m;
}

// The rows the likelihood sees: every training row, or at most `count` of
// them drawn at random (sorted).
std::vector<int> likelihood_rows(const std::vector<int>& train_rows, int count, std::uint64_t seed) {
  if (static_cast<int>(train_rows.size()) <= count) return train_rows;
  std::vector<int> rows = train_rows;
  std::mt19937_64 rng(seed);
  std::shuffle(rows.begin(), rows.end(), rng);
  rows.resize(static_cast<std::size_t>(count));
  std::sort(rows.begin(), rows.end());
  return rows;
}

// The GP's likelihood on the identification rows for one hysteresis model.
// Inputs and outputs are normalised once, by the commanded rows, for every
// candidate: the likelihood of outputs scaled differently would not compare.
class Likelihood {
 public:
  Likelihood(const dataset::Dataset& data, const std::vector<int>& rows, const model::RobotGeometry<double>& geometry,
             model::InputEncoding encoding, bool with_payload)
      : data_(data), rows_(rows), geometry_(geometry), encoding_(encoding), with_payload_(with_payload) {
    rows_data_.segment_count = data.segment_count;
    rows_data_.segment_cables = data.segment_cables;
    rows_data_.has_poses = true;
    rows_data_.has_payload = data.has_payload;
    if (data.has_payload) rows_data_.payload_kg = data.payload_kg(rows);
    for (const int row : rows) rows_data_.poses.push_back(data.poses[static_cast<std::size_t>(row)]);
    const TrainingSet commanded = set_for({});
    normalisation_ = normalisation_of(commanded);
  }

  // Normalised inputs and outputs; throws std::invalid_argument when the
  // nominal model rejects an effective row.
  std::pair<Eigen::MatrixXd, Eigen::MatrixXd> normalised_rows(const model::HysteresisModel<double>& m) const {
    const TrainingSet set = set_for(m);
    return {normalise(set.inputs, normalisation_.input_mean, normalisation_.input_scale),
            normalise(set.error_twists, normalisation_.output_mean, normalisation_.output_scale)};
  }

  // With the hyperparameters held; -infinity for a model the nominal
  // kinematics or the factorisation rejects.
  double operator()(const model::HysteresisModel<double>& m, const KernelHyperparameters& h) {
    ++evaluations_;
    try {
      const auto [x, y] = normalised_rows(m);
      return log_marginal_likelihood(x, y, h, false, workspace_).log_marginal_likelihood;
    } catch (const std::invalid_argument&) {
    } catch (const std::runtime_error&) {
    }
    return -std::numeric_limits<double>::infinity();
  }

  int evaluations() const { return evaluations_; }
  int rows() const { return static_cast<int>(rows_.size()); }

 private:
  TrainingSet set_for(const model::HysteresisModel<double>& m) const {
    dataset::Dataset d = rows_data_;
    d.cables_mm = effective_cables(data_.cables_mm, data_.session_starts, m, geometry_, session_start(data_))(
        rows_, Eigen::all);
    return make_training_set(d, geometry_, encoding_, with_payload_);
  }

  const dataset::Dataset& data_;
  std::vector<int> rows_;
  const model::RobotGeometry<double>& geometry_;
  model::InputEncoding encoding_;
  bool with_payload_;
  dataset::Dataset rows_data_;
  Normalisation normalisation_;
  LikelihoodWorkspace workspace_;
  int evaluations_ = 0;
};

// The largest of f on [low, high] by golden section, `steps` evaluations,
// starting from the best known point (x0, f0), which it returns if nothing
// beats it.
std::pair<double, double> golden_section_max(const std::function<double(double)>& f, double low, double high,
                                             int steps, double x0, double f0) {
  constexpr double kInverseGolden = 0.6180339887498949;
  double best_x = x0, best_f = f0;
  if (!(high > low) || steps < 1) return {best_x, best_f};
  double a = low, b = high;
  double c = b - kInverseGolden * (b - a), d = a + kInverseGolden * (b - a);
  double fc = f(c);
  if (fc > best_f) best_x = c, best_f = fc;
  if (steps == 1) return {best_x, best_f};
  double fd = f(d);
  if (fd > best_f) best_x = d, best_f = fd;
  for (int step = 2; step < steps; ++step) {
    if (fc >= fd) {
      b = d, d = c, fd = fc;
      c = b - kInverseGolden * (b - a);
      fc = f(c);
      if (fc > best_f) best_x = c, best_f = fc;
    } else {
      a = c, c = d, fc = fd;
      d = a + kInverseGolden * (b - a);
      fd = f(d);
      if (fd > best_f) best_x = d, best_f = fd;
    }
  }
  return {best_x, best_f};
}

// The search directions of a candidate's parameters. The joints see only
// the difference of a segment's opposite cables (1-3, 2-4), so the sum of
// their widths is well determined and the split between them only by the
// shape of the reversals: per cable, the search moves each opposite pair
// along their sum and their difference, a valley coordinate by coordinate
// descent would cross only slowly. Every other parameter is its own
// direction.
//
// When every move is long enough to saturate the operators, only the sum
// shows in the data: the difference then wanders with the noise. A move
// along a difference must gain at least kSplitGain in log likelihood (the
// price of a parameter in the ranking below), else the widths stay split
// as they were (evenly, from the per-segment search).
constexpr double kSplitGain = 1.0;

struct SearchDirection {
  Eigen::VectorXd step;
  double min_gain = 0.0;
};

std::vector<SearchDirection> search_directions(const Shape& shape) {
  const int groups = shape.groups();
  const int size = shape.parameters();
  std::vector<SearchDirection> directions;
  const auto unit = [&](int i) { return Eigen::VectorXd(Eigen::VectorXd::Unit(size, i)); };
  if (shape.sharing == HysteresisSharing::per_cable) {
    // Four cables make two opposite pairs, searched along their sum and
    // their difference; three have no pairs, each cable on its own.
    const model::RobotGeometry<double>& geometry = *shape.geometry;
    for (int segment = 0; segment < geometry.segment_count; ++segment) {
      const int first = geometry.first_cable(segment);
      if (geometry.segments[segment].cables.count != 4) {
        for (int c = 0; c < geometry.segments[segment].cables.count; ++c) directions.push_back({unit(first + c), 0.0});
        continue;
      }
      for (int pair = 0; pair < 2; ++pair) {
        const int a = first + pair, b = first + pair + 2;
        directions.push_back({unit(a) + unit(b), 0.0});
        directions.push_back({unit(a) - unit(b), kSplitGain});
      }
    }
  } else {
    for (int g = 0; g < groups; ++g) directions.push_back({unit(g), 0.0});
  }
  for (int k = 0; k < shape.operators; ++k) directions.push_back({unit(groups + k), 0.0});
  return directions;
}

// The interval of t for which parameters + t u stays feasible: widths in
// [0, kMaxHysteresisWidthMm], weights not negative and summing to at most 1.
std::pair<double, double> feasible_steps(const Shape& shape, const Eigen::VectorXd& p, const Eigen::VectorXd& u) {
  double low = -std::numeric_limits<double>::infinity(), high = std::numeric_limits<double>::infinity();
  const auto bound = [&](double value, double slope, double lower, double upper) {
    if (slope > 0) {
      low = std::max(low, (lower - value) / slope);
      high = std::min(high, (upper - value) / slope);
    } else if (slope < 0) {
      low = std::max(low, (upper - value) / slope);
      high = std::min(high, (lower - value) / slope);
    }
  };
  const int groups = shape.groups();
  for (int i = 0; i < p.size(); ++i) {
    bound(p[i], u[i], 0.0, i < groups ? model::kMaxHysteresisWidthMm : 1.0);
  }
  bound(p.tail(shape.operators).sum(), u.tail(shape.operators).sum(), -std::numeric_limits<double>::infinity(), 1.0);
  return {std::min(low, 0.0), std::max(high, 0.0)};
}

// Descent along the shape's directions with the hyperparameters held: a
// first sweep over each direction's whole feasible range, then sweeps
// within refine_span_mm (or a weight's same amount) of where it stands.
Eigen::VectorXd coordinate_search(const Shape& shape, Eigen::VectorXd parameters, const KernelHyperparameters& h,
                                  Likelihood& likelihood, const model::RobotGeometry<double>& geometry,
                                  const HysteresisSearchOptions& options, bool first_sweep = true) {
  const std::vector<SearchDirection> directions = search_directions(shape);
  double current = likelihood(model_for(shape, parameters, geometry), h);
  for (int sweep = first_sweep ? 0 : 1; sweep <= options.refine_sweeps; ++sweep) {
    for (const SearchDirection& direction : directions) {
      const Eigen::VectorXd& u = direction.step;
      auto [low, high] = feasible_steps(shape, parameters, u);
      if (sweep > 0) {
        low = std::max(low, -options.refine_span_mm);
        high = std::min(high, options.refine_span_mm);
      }
      const auto f = [&](double t) { return likelihood(model_for(shape, parameters + t * u, geometry), h); };
      const int steps = sweep == 0 ? options.first_sweep_steps : options.refine_sweep_steps;
      const auto [best, best_value] = golden_section_max(f, low, high, steps, 0.0, current);
      if (!(best_value >= current + direction.min_gain)) continue;
      // Clamped: rounding must not leave a width a hair below zero.
      parameters = (parameters + best * u).cwiseMax(0.0);
      current = best_value;
    }
  }
  return parameters;
}

// Akaike's penalty, one per parameter. Bayes' (log(6 N) / 2, 4.2 here)
// chose shared widths on simulated robots where one width per cable was
// the better model on another session's rows (0.98 against 1.02 mm, 0.93
// against 0.97 mm); on a sequence without hysteresis Akaike's still
// chooses none.
constexpr double kPenaltyPerParameter = 1.0;

// The candidates of identify_hysteresis(), searched in turn on one set of
// likelihood rows; each adds itself to the result beside its structure,
// parameters and hyperparameters.
class CandidateSearch {
 public:
  CandidateSearch(Likelihood& likelihood, const model::RobotGeometry<double>& geometry,
                  const SearchOptions& hyperparameter_search, const HysteresisSearchOptions& options,
                  HysteresisIdentification& result)
      : likelihood_(likelihood),
        geometry_(geometry),
        options_(options),
        result_(result),
        research_(hyperparameter_search),
        segments_(geometry.segment_count),
        cables_(geometry.cable_count()) {
    research_.restarts = 0;
  }

  // None: the commanded rows, hyperparameters re-searched on these rows.
  void add_none(const KernelHyperparameters& joints_only_h) {
    add_candidate(Shape{}, Eigen::VectorXd(), research_from({}, joints_only_h), likelihood_.evaluations());
  }

  // One width and weight for every cable, with the joints-only
  // hyperparameters, then again with those of the effective rows, which
  // the finer sharings then use.
  void add_shared(const KernelHyperparameters& joints_only_h) {
    const int before = likelihood_.evaluations();
    const Shape shared{HysteresisSharing::all_cables, 1, &geometry_};
    Eigen::VectorXd parameters(2);
    parameters << 0.0, 1.0;
    parameters = coordinate_search(shared, parameters, joints_only_h, likelihood_, geometry_, options_);
    h_ = research_from(model_for(shared, parameters, geometry_), joints_only_h).hyperparameters;
    parameters = coordinate_search(shared, parameters, h_, likelihood_, geometry_, options_, false);
    add_candidate(shared, parameters, research_from(model_for(shared, parameters, geometry_), h_), before);
    shared_parameters_ = parameters;
  }

  // Finer sharings start from the shared width and weight: one width per
  // segment, then one per cable from the segments'.
  void add_per_segment_and_per_cable() {
    int before = likelihood_.evaluations();
    const Shape per_segment{HysteresisSharing::per_segment, 1, &geometry_};
    Eigen::VectorXd segment_parameters = Eigen::VectorXd::Constant(segments_ + 1, shared_width());
    segment_parameters[segments_] = shared_weight();
    segment_parameters = coordinate_search(per_segment, segment_parameters, h_, likelihood_, geometry_, options_);
    add_searched(per_segment, segment_parameters, before);

    before = likelihood_.evaluations();
    const Shape per_cable{HysteresisSharing::per_cable, 1, &geometry_};
    Eigen::VectorXd cable_parameters(cables_ + 1);
    for (int c = 0; c < cables_; ++c) cable_parameters[c] = segment_parameters[segment_of(geometry_, c)];
    cable_parameters[cables_] = segment_parameters[segments_];
    cable_parameters_ = coordinate_search(per_cable, cable_parameters, h_, likelihood_, geometry_, options_);
    add_searched(per_cable, cable_parameters_, before);
  }

  // Shapes: K operators of widths r/K .. r sharing the shared weight. A
  // shape of several operators that explains the shared case better than
  // one also gets one width per cable: the per-cable widths of one operator
  // scaled by the ratio of the two shared widths, the shape's weights.
  void add_operator_shapes() {
    double best_shape_criterion = result_.candidates[1].criterion;
    Eigen::VectorXd best_shape_parameters = shared_parameters_;
    for (int k = 2; k <= std::min(options_.operators_max, model::kMaxHysteresisOperators); ++k) {
      const int before = likelihood_.evaluations();
      const Shape shape{HysteresisSharing::all_cables, k, &geometry_};
      Eigen::VectorXd parameters = Eigen::VectorXd::Constant(1 + k, shared_weight() / double(k));
      parameters[0] = shared_width();
      parameters = coordinate_search(shape, parameters, h_, likelihood_, geometry_, options_);
      add_searched(shape, parameters, before);
      if (result_.candidates.back().criterion > best_shape_criterion) {
        best_shape_criterion = result_.candidates.back().criterion;
        best_shape_parameters = parameters;
      }
    }
    const int best_operators = static_cast<int>(best_shape_parameters.size()) - 1;
    if (best_operators <= 1) return;
    const int before = likelihood_.evaluations();
    const Shape shape{HysteresisSharing::per_cable, best_operators, &geometry_};
    Eigen::VectorXd parameters(cables_ + best_operators);
    const double scale = shared_width() > 0.0 ? best_shape_parameters[0] / shared_width() : 1.0;
    for (int c = 0; c < cables_; ++c) {
      parameters[c] = std::min(model::kMaxHysteresisWidthMm, scale * cable_parameters_[c]);
    }
    parameters.tail(best_operators) = best_shape_parameters.tail(best_operators);
    parameters = coordinate_search(shape, parameters, h_, likelihood_, geometry_, options_);
    add_searched(shape, parameters, before);
  }

  // The winner was searched with the hyperparameters of one shared width,
  // which take much of its hysteresis for noise: its parameters are refined
  // once more with its own (then those searched again), kept if better.
  HysteresisCandidate& refined_winner() {
    const auto best = std::max_element(result_.candidates.begin(), result_.candidates.end(),
                                       [](const HysteresisCandidate& a, const HysteresisCandidate& b) {
                                         return a.criterion < b.criterion;
                                       });
    const Searched& winner = searched_[static_cast<std::size_t>(best - result_.candidates.begin())];
    if (winner.shape.sharing == HysteresisSharing::none) return *best;
    const int before_refinement = likelihood_.evaluations();
    const Eigen::VectorXd refined = coordinate_search(winner.shape, winner.parameters, winner.hyperparameters,
                                                      likelihood_, geometry_, options_, false);
    const SearchResult search = research_from(model_for(winner.shape, refined, geometry_), winner.hyperparameters);
    result_.refinement_evaluations = likelihood_.evaluations() - before_refinement;
    if (search.log_marginal_likelihood > best->log_marginal_likelihood) {
      result_.refinement_gain = search.log_marginal_likelihood - best->log_marginal_likelihood;
      best->model = model_for(winner.shape, refined, geometry_);
      best->log_marginal_likelihood = search.log_marginal_likelihood;
      best->criterion = search.log_marginal_likelihood - kPenaltyPerParameter * double(best->parameters);
    }
    return *best;
  }

 private:
  struct Searched {
    Shape shape;
    Eigen::VectorXd parameters;
    KernelHyperparameters hyperparameters;
  };

  double shared_width() const { return shared_parameters_[0]; }
  double shared_weight() const { return shared_parameters_[1]; }

  SearchResult research_from(const model::HysteresisModel<double>& m, const KernelHyperparameters& start) {
    ++result_.hyperparameter_searches;
    const auto [x, y] = likelihood_.normalised_rows(m);
    return maximise_likelihood(x, y, start, research_);
  }

  // A candidate searched with the effective rows' hyperparameters, which
  // are then searched again on its rows.
  void add_searched(const Shape& shape, const Eigen::VectorXd& parameters, int evaluations_before) {
    add_candidate(shape, parameters, research_from(model_for(shape, parameters, geometry_), h_), evaluations_before);
  }

  void add_candidate(const Shape& shape, const Eigen::VectorXd& parameters, const SearchResult& search,
                     int evaluations_before) {
    HysteresisCandidate c;
    c.sharing = shape.sharing;
    c.operators = shape.operators;
    c.parameters = shape.parameters();
    c.model = model_for(shape, parameters, geometry_);
    c.log_marginal_likelihood = search.log_marginal_likelihood;
    c.criterion = search.log_marginal_likelihood - kPenaltyPerParameter * double(c.parameters);
    c.likelihood_evaluations = likelihood_.evaluations() - evaluations_before;
    result_.candidates.push_back(c);
    searched_.push_back({shape, parameters, search.hyperparameters});
  }

  Likelihood& likelihood_;
  const model::RobotGeometry<double>& geometry_;
  const HysteresisSearchOptions& options_;
  HysteresisIdentification& result_;
  SearchOptions research_;
  int segments_;
  int cables_;
  KernelHyperparameters h_;
  Eigen::VectorXd shared_parameters_;
  Eigen::VectorXd cable_parameters_;
  std::vector<Searched> searched_;
};

}  // namespace

HysteresisIdentification identify_hysteresis(const dataset::Dataset& data, const std::vector<int>& train_rows,
                                             const model::RobotGeometry<double>& geometry,
                                             const TrainingOptions& training_options, bool with_payload,
                                             const HysteresisSearchOptions& options) {
  if (!data.has_time) throw std::invalid_argument("hysteresis identification needs a motion sequence (a t_s column)");
  HysteresisIdentification result;
  const int train_count = static_cast<int>(train_rows.size());
  if (train_count < options.min_rows) {
    result.skipped_reason = std::to_string(train_count) + " training row" + (train_count == 1 ? "" : "s") +
                            " in the sequence; identifying the hysteresis needs at least " +
                            std::to_string(options.min_rows);
    return result;
  }
  result.attempted = true;

  const TrainingSet commanded_train =
      make_training_set(data, geometry, training_options.encoding, with_payload).subset(train_rows);
  result.joints_only = train(commanded_train, geometry, training_options, &result.joints_only_report);
  const KernelHyperparameters joints_only_h = shared_hyperparameters(result.joints_only);

  Likelihood likelihood(data, likelihood_rows(train_rows, options.max_rows, training_options.search.seed), geometry,
                        training_options.encoding, with_payload);
  result.rows = likelihood.rows();
  CandidateSearch search(likelihood, geometry, training_options.search, options, result);
  search.add_none(joints_only_h);
  search.add_shared(joints_only_h);
  search.add_per_segment_and_per_cable();
  search.add_operator_shapes();
  const HysteresisCandidate& best = search.refined_winner();
  result.model = best.model;
  result.sharing = best.sharing;
  result.likelihood_evaluations = likelihood.evaluations();
  return result;
}

}  // namespace cdcr::training
