#pragma once
// The effective cable lengths and history inputs of every row of a motion
// sequence (hysteresis.hpp): the state is carried from row to row, each
// session starts after the homing move (start_at_home) or at power-up with
// the state unknown (a recording without the homing move), and the cables
// move from one row to the next in a straight line. The host tools' replay
// and evaluation run it in float32 on an image's block, as the board does.

#include <cstdint>

#include <Eigen/Core>

#include "cdcr/model/hysteresis.hpp"

namespace cdcr::model {

// How every session of a sequence starts.
enum class SessionStart : std::uint8_t {
  homed,     // after the homing move: the state is the block's homing state
  power_up,  // without it: the state unknown, the first row only its position
};

// Runs the state over the rows: commanded_mm is rows x cables (any scalar,
// converted to S row by row); session_starts the first row of every session,
// increasing, the first 0 (none: one session from row 0). After each row's
// update, row(i, state) sees the state.
template <typename S, int MaxSegments, typename DerivedIn, typename Row>
Status for_each_sequence_row(const HysteresisModel<S>& model, const RobotGeometry<S, MaxSegments>& geometry,
                             const Eigen::MatrixBase<DerivedIn>& commanded_mm, const int* session_starts,
                             int session_count, SessionStart start, Row row) {
  if (commanded_mm.cols() != model.cables) return Status::invalid_segment_count;
  HysteresisState<S> state;
  CableVector<S, MaxSegments> lengths;
  int next_session = 0;
  for (Eigen::Index i = 0; i < commanded_mm.rows(); ++i) {
    const bool starts = i == 0 || (next_session < session_count && session_starts[next_session] == i);
    if (starts && start == SessionStart::power_up) reset_unknown(state, model);
    if (starts && start == SessionStart::homed) {
      if (const Status s = start_at_home(state, model, geometry); s != Status::ok) return s;
    }
    while (next_session < session_count && session_starts[next_session] <= i) ++next_session;
    lengths = commanded_mm.row(i).transpose().template cast<S>();
    update_hysteresis(state, model, lengths);
    row(i, state);
  }
  return Status::ok;
}

// The effective lengths of every row, and with `history` (not null) the
// history inputs (history_inputs) from the same run; effective_mm and
// *history, sized rows x cables by the caller, receive them.
template <typename S, int MaxSegments, typename DerivedIn, typename DerivedOut, typename DerivedHistory = DerivedOut>
Status effective_lengths_over_sequence(const HysteresisModel<S>& model, const RobotGeometry<S, MaxSegments>& geometry,
                                       const Eigen::MatrixBase<DerivedIn>& commanded_mm, const int* session_starts,
                                       int session_count, Eigen::MatrixBase<DerivedOut>& effective_mm,
                                       SessionStart start = SessionStart::homed,
                                       Eigen::MatrixBase<DerivedHistory>* history = nullptr) {
  CableVector<S, MaxSegments> effective;
  S values[kMaxCables];
  return for_each_sequence_row(model, geometry, commanded_mm, session_starts, session_count, start,
                               [&](Eigen::Index i, const HysteresisState<S>& state) {
                                 effective_lengths(state, model, effective);
                                 effective_mm.row(i) =
                                     effective.transpose().template cast<typename DerivedOut::Scalar>();
                                 if (history == nullptr) return;
                                 history_inputs(state, model, values);
                                 for (int c = 0; c < model.cables; ++c) {
                                   (*history)(i, c) = static_cast<typename DerivedHistory::Scalar>(values[c]);
                                 }
                               });
}

}  // namespace cdcr::model
