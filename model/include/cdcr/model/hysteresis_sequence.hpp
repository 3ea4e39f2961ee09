#pragma once
// The effective cable lengths of every row of a motion sequence
// (hysteresis.hpp): the state is carried from row to row, each session
// starts after the homing move (start_at_home), and the cables move from one
// row to the next in a straight line. The host tools' replay and evaluation
// run it in float32 on an image's block, as the board does.

#include <Eigen/Core>

#include "cdcr/model/hysteresis.hpp"

namespace cdcr::model {

// commanded_mm: rows x cables (any scalar, converted to S row by row);
// session_starts: the first row of every session, increasing, the first 0
// (none: one session from row 0). effective_mm, sized rows x cables by the
// caller, receives the effective lengths.
template <typename S, int MaxSegments, typename DerivedIn, typename DerivedOut>
Status effective_lengths_over_sequence(const HysteresisModel<S>& model, const RobotGeometry<S, MaxSegments>& geometry,
                                       const Eigen::MatrixBase<DerivedIn>& commanded_mm, const int* session_starts,
                                       int session_count, Eigen::MatrixBase<DerivedOut>& effective_mm) {
  if (commanded_mm.cols() != model.cables) return Status::invalid_segment_count;
  HysteresisState<S> state;
  CableVector<S, MaxSegments> row, effective;
  int next_session = 0;
  for (Eigen::Index i = 0; i < commanded_mm.rows(); ++i) {
    const bool starts = i == 0 || (next_session < session_count && session_starts[next_session] == i);
    if (starts) {
      if (const Status s = start_at_home(state, model, geometry); s != Status::ok) return s;
    }
    while (next_session < session_count && session_starts[next_session] <= i) ++next_session;
    row = commanded_mm.row(i).transpose().template cast<S>();
    update_hysteresis(state, model, row);
    effective_lengths(state, model, effective);
    effective_mm.row(i) = effective.transpose().template cast<typename DerivedOut::Scalar>();
  }
  return Status::ok;
}

}  // namespace cdcr::model
