#include "sim/direct_drives.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace cdcr::sim {

namespace {
enum Kind : std::uint8_t { kNone, kInjected };
}

DirectCableDrives::DirectCableDrives(const std::vector<double>& initial_cables_mm, double max_rate_mm_per_s,
                                     double cycle_s)
    : cables_mm_(initial_cables_mm), setpoints_mm_(initial_cables_mm), step_mm_(max_rate_mm_per_s * cycle_s) {
  if (cables_mm_.empty() || !(step_mm_ > 0) || !std::isfinite(step_mm_))
    throw std::invalid_argument("direct drives: cables, a positive rate and a positive cycle are needed");
}

bool DirectCableDrives::start() {
  started_ = true;
  health_ = hal::DrivesHealth{};
  health_.condition = hal::DrivesCondition::ready;
  return true;
}

// The cables move in the cycle between the setpoints and the next report.
void DirectCableDrives::receive() {
  if (health_.failed()) return;
  for (std::size_t i = 0; i < cables_mm_.size(); ++i) {
    const double error = setpoints_mm_[i] - cables_mm_[i];
    cables_mm_[i] += std::clamp(error, -step_mm_, step_mm_);
  }
}

bool DirectCableDrives::lengths(double* lengths_mm, int count) {
  if (!started_ || health_.condition != hal::DrivesCondition::ready || count != int(cables_mm_.size())) return false;
  std::copy(cables_mm_.begin(), cables_mm_.end(), lengths_mm);
  return true;
}

bool DirectCableDrives::command(const double* setpoints_mm, int count) {
  if (health_.condition != hal::DrivesCondition::ready || count != int(setpoints_mm_.size())) return false;
  for (int i = 0; i < count; ++i) {
    if (!(setpoints_mm[i] > 0) || !std::isfinite(setpoints_mm[i])) return false;
  }
  std::copy(setpoints_mm, setpoints_mm + count, setpoints_mm_.begin());
  return true;
}

bool DirectCableDrives::recover() {
  if (!health_.failed()) return false;
  // A recovered drive holds where it stopped.
  setpoints_mm_ = cables_mm_;
  return start();
}

void DirectCableDrives::fail(int cable, hal::DrivesCondition condition) {
  if (cable < 0 || cable >= int(cables_mm_.size())) throw std::out_of_range("direct drives: no such cable");
  health_.condition = condition;
  health_.drive = std::uint8_t(cable + 1);
  health_.cable = std::int16_t(cable);
  health_.kind = kInjected;
  health_.detail = 0;
}

const char* DirectCableDrives::describe(std::uint8_t kind) const { return kind == kInjected ? "injected" : "none"; }

}  // namespace cdcr::sim
