#pragma once
// Whether the GP takes where each cable last moved (model::history_inputs),
// by evidence, beside the play operators the identification chose: friction
// whose effect is not a lag of the cable's length (capstan friction along a
// bent segment changes the tension that reaches the anchor, and so the bend
// and the compression, by an amount that depends on the whole configuration)
// is a function of the configuration and the direction of the last move,
// which the GP can learn where an operator's constant lag cannot.
//
// The history is read from one more play operator per cable, of weight 0
// (it leaves the effective lengths as they are), appended to the hysteresis
// model so that the board's tracker keeps it with the others. Candidates:
// kHistoryWidthsMm; each is the search's log marginal likelihood on the same
// training rows as the model without it, less half the log of the rows per
// extra parameter, its length scales and its width (Schwarz's criterion).
// The other choices take one per parameter (Akaike's); here that kept the
// history on the real-like babbling runs, where it cost the held-out error
// 2 to 3 % (1.06 -> 1.09 and 1.02 -> 1.04 mm): four more inputs per segment
// thin out a sparse model's points on the board, which the exact GP's
// likelihood on the search rows does not see.
//
// Offered only where the inputs fit the board's (kMaxInputs: one and two
// segments do, the paper's four do not), where the identification ran (a
// sequence of at least kMinHysteresisRows training rows), and where a
// cable has an operator to spare.

#include <string>
#include <vector>

#include "cdcr/model/geometry.hpp"
#include "cdcr/model/hysteresis.hpp"
#include "dataset/dataset.hpp"
#include "trainer.hpp"

namespace cdcr::training {

// Widths of the history operator tried (mm): a sign of the last move for
// any move of a tenth of a millimetre, and two that forget small moves.
inline constexpr double kHistoryWidthsMm[] = {0.05, 0.2, 0.8};

struct HistoryCandidate {
  double width_mm = 0.0;
  double log_marginal_likelihood = 0.0;
};

struct HistoryChoice {
  bool searched = false;
  bool chosen = false;
  // The hysteresis model with the history operator appended when chosen;
  // else the one given.
  model::HysteresisModel<double> model;
  double width_mm = 0.0;  // the chosen history operator's
  double without_log_likelihood = 0.0;
  std::vector<HistoryCandidate> candidates;
  int extra_parameters = 0;  // the history's length scales and its width
  double penalty = 0.0;      // what a candidate must gain: extra_parameters x ln(search_rows) / 2
  int search_rows = 0;
  std::string reason;  // one line
};

// The hysteresis model with a history operator of `width_mm` appended to
// every cable (weight 0, its homing lag that of the homing move); an empty
// model becomes one of that operator alone. Throws std::invalid_argument
// when the cables have no operator to spare.
model::HysteresisModel<double> with_history_operator(const model::HysteresisModel<double>& hysteresis,
                                                     double width_mm, const model::RobotGeometry<double>& geometry);

// `data` is the sequence, `train_rows` its training rows, `hysteresis` the
// identification's choice (empty: none), `encoding` the inputs without the
// history; options as the trainer's.
HistoryChoice choose_history_inputs(const dataset::Dataset& data, const std::vector<int>& train_rows,
                                    const model::HysteresisModel<double>& hysteresis,
                                    const model::RobotGeometry<double>& geometry, const TrainingOptions& options,
                                    bool with_payload = true);

}  // namespace cdcr::training
