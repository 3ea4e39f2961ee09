#pragma once
// Identification of the cables' friction hysteresis from a motion sequence
// (a dataset with a time column), jointly with the GP that learns what is
// left: the GP's inputs become the joints of the effective cable lengths,
// the lengths that bend the segments, which the play operators of
// model/hysteresis.hpp compute row by row from the commanded ones.
//
// Structure by evidence. Each candidate is a sharing of the widths (one
// width for every cable, one per segment, one per cable) and a shape: K play
// operators per cable with widths in the fixed ratio r (k + 1) / K and
// weights w_1..w_K shared by every cable (sum <= 1); when a shape of
// several operators beats one operator with shared widths, that shape with
// one width per cable is a candidate too. A candidate's
// parameters are searched by coordinate descent, each coordinate by golden
// section, maximising the GP's log marginal likelihood on the training rows
// with the hyperparameters held (the joints-only model's, re-searched once
// after the shared width is found); then the hyperparameters are searched
// again for that candidate, and the candidates, "none" (the joints-only
// model) among them, are ranked by the likelihood less one per parameter
// (Akaike's information criterion).

#include <string>
#include <vector>

#include <Eigen/Core>

#include "cdcr/model/geometry.hpp"
#include "cdcr/model/hysteresis.hpp"
#include "cdcr/model/hysteresis_sequence.hpp"
#include "dataset/dataset.hpp"
#include "trainer.hpp"

namespace cdcr::training {

// The effective cable lengths of every row of a sequence: each session
// starts at home after the homing move (model::start_at_home), or at
// power-up with the state unknown, then the state follows the commanded
// rows one by one; with `history` (not null), where each cable last moved
// too (model::history_inputs), from the same run. Throws
// std::invalid_argument for session starts that do not begin at row 0 or do
// not increase. An empty model returns the commanded lengths.
Eigen::MatrixXd effective_cables(const Eigen::MatrixXd& commanded_mm, const std::vector<int>& session_starts,
                                 const model::HysteresisModel<double>& hysteresis,
                                 const model::RobotGeometry<double>& geometry,
                                 model::SessionStart start = model::SessionStart::homed,
                                 Eigen::MatrixXd* history = nullptr);

// How the data's sessions start: after the homing move, or at power-up.
inline model::SessionStart session_start(const dataset::Dataset& data) {
  return data.sessions_homed ? model::SessionStart::homed : model::SessionStart::power_up;
}

// The training set of a sequence with the hysteresis applied: bends, nominal
// poses and error twists from the effective lengths of every row (the state
// runs over all rows, so any subset of it is a valid split), and the
// commanded lengths kept in commanded_mm. cables_mm holds the effective ones.
// A history encoding adds where each cable last moved, from the model's last
// operator (history_inputs).
TrainingSet make_sequence_training_set(const dataset::Dataset& data, const model::HysteresisModel<double>& hysteresis,
                                       const model::RobotGeometry<double>& geometry, model::InputEncoding encoding,
                                       bool with_payload = true);

// Which cables share a width.
enum class HysteresisSharing { none, all_cables, per_segment, per_cable };
const char* to_string(HysteresisSharing sharing);

// Fewer training rows than this and the sequence is not identified: the
// joints-only model is trained (a width needs reversals of every cable
// sharing it, and the likelihood's differences between candidates are
// noise on fewer rows).
inline constexpr int kMinHysteresisRows = 50;

struct HysteresisSearchOptions {
  int min_rows = kMinHysteresisRows;
  // The likelihood is evaluated on at most this many training rows (drawn at
  // random, seeded): one Cholesky factor of that size per evaluation.
  int max_rows = 700;
  int operators_max = 3;  // shapes K = 1..operators_max shared by all cables
  // Golden-section steps per search direction: a first sweep over the whole
  // range, then refine_sweeps sweeps within refine_span_mm of where each
  // parameter stands.
  int first_sweep_steps = 10;
  int refine_sweeps = 2;
  int refine_sweep_steps = 6;
  double refine_span_mm = 0.25;
};

struct HysteresisCandidate {
  HysteresisSharing sharing = HysteresisSharing::none;
  int operators = 0;
  int parameters = 0;
  model::HysteresisModel<double> model;
  double log_marginal_likelihood = 0.0;  // after the hyperparameters' re-search (normalised units)
  double criterion = 0.0;                // log_marginal_likelihood - parameters; higher wins
  int likelihood_evaluations = 0;        // with the hyperparameters held
};

struct HysteresisIdentification {
  bool attempted = false;
  std::string skipped_reason;  // why not, when not attempted
  // The chosen model: empty when "none" wins or identification was skipped.
  model::HysteresisModel<double> model;
  HysteresisSharing sharing = HysteresisSharing::none;
  int rows = 0;  // training rows the likelihood saw
  std::vector<HysteresisCandidate> candidates;
  int likelihood_evaluations = 0;  // Cholesky factors with the hyperparameters held
  // The chosen candidate's last refinement, with its own hyperparameters:
  // its evaluations (part of likelihood_evaluations) and what it gained in
  // log likelihood (0: kept as it was).
  int refinement_evaluations = 0;
  double refinement_gain = 0.0;
  int hyperparameter_searches = 0; // L-BFGS-B searches besides the joints-only model's
  // The joints-only model on the same training rows (train() with the same
  // options): the start of the search and the figure to beat.
  TrainedModel joints_only;
  TrainingReport joints_only_report;
};

// Identifies the hysteresis of `data` (a sequence: has_time) from the rows
// `train_rows` (the state still runs over every row). Skipped, with the
// reason, when there are fewer than options.min_rows of them.
HysteresisIdentification identify_hysteresis(const dataset::Dataset& data, const std::vector<int>& train_rows,
                                             const model::RobotGeometry<double>& geometry,
                                             const TrainingOptions& training_options, bool with_payload = true,
                                             const HysteresisSearchOptions& options = {});

}  // namespace cdcr::training
