#pragma once
// Source 7 of the simulator: the friction hysteresis of every cable (the
// operator is described with HysteresisConfig in simulator_config.hpp). The
// simulator's own operator, independent of the model's (cdcr/model/
// hysteresis.hpp): a trainer that identifies the model's few play operators
// from data must not find the simulator's exact shape.
//
// The state (every play's lag, and the commanded lengths it belongs to)
// persists across moves. Until the first move_to the position is unknown;
// that call only records where the cables are.

#include <array>
#include <cstdint>

#include <cdcr/model/limits.hpp>
#include <cdcr/model/types.hpp>

#include "sim/simulator_config.hpp"

namespace cdcr::sim {

class CableFriction {
 public:
  static constexpr int kOperators = HysteresisConfig::kOperators;
  using Cables = model::CableVector<double>;

  // The friction of `cables` cables: parameters from (seed, StreamId::
  // hysteresis), the power-up state from (session_seed, StreamId::
  // hysteresis_state). Throws std::invalid_argument for a cable count
  // outside 1..kMaxCables.
  CableFriction(int cables, const HysteresisConfig& config, std::uint64_t seed, std::uint64_t session_seed);

  int cables() const { return cables_; }
  // L_c: the lag after a long move in one direction, the loop's half-width.
  double max_lag_mm(int cable) const { return max_lag_mm_[cable]; }
  double width_mm(int cable, int k) const { return widths_mm_[cable][k]; }
  double weight(int cable, int k) const { return weights_[cable][k]; }
  double lag_mm(int cable, int k) const { return lags_mm_[cable][k]; }
  // The widest play of any cable: a move of twice this in one direction
  // saturates every play, whatever the state before.
  double largest_width_mm() const;

  bool has_position() const { return has_position_; }
  const std::array<double, model::kMaxCables>& commanded_mm() const { return commanded_mm_; }

  // The cables move in a straight line from the last position to
  // `commanded_mm` (each cable monotonically, so one clamp per play is
  // exact); the first call only records the position.
  void move_to(const Cables& commanded_mm);

  // The effective lengths at the current position (the commanded ones minus
  // every cable's weighted lag). Before the first move_to: std::logic_error.
  Cables effective_mm() const;

 private:
  int cables_ = 0;
  bool has_position_ = false;
  std::array<double, model::kMaxCables> max_lag_mm_{};
  std::array<double, model::kMaxCables> density_width_mm_{};  // R_c: the widths' density spans (0, R_c]
  std::array<double, model::kMaxCables> commanded_mm_{};
  std::array<std::array<double, kOperators>, model::kMaxCables> widths_mm_{};
  std::array<std::array<double, kOperators>, model::kMaxCables> weights_{};
  std::array<std::array<double, kOperators>, model::kMaxCables> lags_mm_{};
};

}  // namespace cdcr::sim
