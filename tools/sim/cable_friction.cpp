#include "sim/cable_friction.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "sim/random_stream.hpp"

namespace cdcr::sim {

CableFriction::CableFriction(int cables, const HysteresisConfig& config, std::uint64_t seed,
                             std::uint64_t session_seed)
    : cables_(cables) {
  if (cables < 1 || cables > model::kMaxCables) {
    throw std::invalid_argument("cable friction needs 1 to " + std::to_string(model::kMaxCables) + " cables, got " +
                                std::to_string(cables));
  }
  RandomStream robot(seed, StreamId::hysteresis);
  for (int c = 0; c < cables; ++c) {
    const double max_lag = robot.uniform(config.max_lag_min_mm, config.max_lag_max_mm);
    const double total_weight = robot.uniform(config.total_weight_min, config.total_weight_max);
    const double slope = robot.uniform(-config.density_slope_max, config.density_slope_max);
    std::array<double, kOperators> density{};
    double density_sum = 0.0;
    for (int k = 0; k < kOperators; ++k) {
      const double u = (k + 0.5) / kOperators;  // r_k / R_c
      density[k] = 1.0 + slope * (2.0 * u - 1.0);
      density_sum += density[k];
    }
    // L_c = sum_k w_k r_k = R_c sum_k w_k u_k: the widest play follows from the lag drawn.
    double lag_per_width = 0.0;
    for (int k = 0; k < kOperators; ++k) {
      weights_[c][k] = total_weight * density[k] / density_sum;
      lag_per_width += weights_[c][k] * (k + 0.5) / kOperators;
    }
    const double widest_mm = max_lag / lag_per_width;  // R_c
    for (int k = 0; k < kOperators; ++k) widths_mm_[c][k] = widest_mm * (k + 0.5) / kOperators;
    density_width_mm_[c] = widest_mm;
    max_lag_mm_[c] = max_lag;
  }
  // The power-up state: what a random history left. Moves of up to twice the
  // widest play in either direction reach every state a real robot can be in.
  RandomStream history(session_seed, StreamId::hysteresis_state);
  for (int c = 0; c < cables; ++c) {
    for (int move = 0; move < HysteresisConfig::kPowerUpMoves; ++move) {
      const double dx = history.uniform(-2.0 * density_width_mm_[c], 2.0 * density_width_mm_[c]);
      for (int k = 0; k < kOperators; ++k) {
        const double r = widths_mm_[c][k];
        lags_mm_[c][k] = std::clamp(lags_mm_[c][k] + dx, -r, r);
      }
    }
  }
}

double CableFriction::largest_width_mm() const {
  double widest = 0.0;
  for (int c = 0; c < cables_; ++c) widest = std::max(widest, widths_mm_[c][kOperators - 1]);
  return widest;
}

void CableFriction::move_to(const Cables& commanded_mm) {
  if (commanded_mm.size() != cables_) {
    throw std::invalid_argument("expected " + std::to_string(cables_) + " cable lengths, got " +
                                std::to_string(commanded_mm.size()));
  }
  for (int c = 0; c < cables_; ++c) {
    if (has_position_) {
      const double dx = commanded_mm[c] - commanded_mm_[c];
      for (int k = 0; k < kOperators; ++k) {
        const double r = widths_mm_[c][k];
        lags_mm_[c][k] = std::clamp(lags_mm_[c][k] + dx, -r, r);
      }
    }
    commanded_mm_[c] = commanded_mm[c];
  }
  has_position_ = true;
}

CableFriction::Cables CableFriction::effective_mm() const {
  if (!has_position_) throw std::logic_error("cable friction: no position yet (move_to first)");
  Cables effective(cables_);
  for (int c = 0; c < cables_; ++c) {
    double lag = 0.0;
    for (int k = 0; k < kOperators; ++k) lag += weights_[c][k] * lags_mm_[c][k];
    effective[c] = commanded_mm_[c] - lag;
  }
  return effective;
}

}  // namespace cdcr::sim
