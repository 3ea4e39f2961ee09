#pragma once
// The simulated robot's cable drives as a hal::Drives backend: no bus, no
// frames. Each cycle every cable moves toward its setpoint at a limited
// rate and its length is the next cycle's input, as a drive that held its
// position loop perfectly would report it. For runs and tests of the
// runtime with drives behind Hal::drives without a CANopen stack; a fault
// can be injected on one cable's drive (silent or faulted) and is held
// until recover().

#include <vector>

#include <cdcr/hal/drives.hpp>

namespace cdcr::sim {

class DirectCableDrives final : public hal::Drives {
 public:
  // `cycle_s`: the runtime's period; lengths start at initial_cables_mm.
  DirectCableDrives(const std::vector<double>& initial_cables_mm, double max_rate_mm_per_s, double cycle_s);

  bool start() override;
  void receive() override;
  bool lengths(double* lengths_mm, int count) override;
  bool command(const double* setpoints_mm, int count) override;
  void transmit() override {}
  hal::DrivesHealth health() const override { return health_; }
  bool recover() override;
  const char* describe(std::uint8_t kind) const override;
  int drive_count() const override { return int(cables_mm_.size()); }

  // Cable `cable`'s drive stops answering (silent) or reports a fault; its
  // drive number in health() is cable + 1.
  void fail(int cable, hal::DrivesCondition condition);

  const std::vector<double>& cables_mm() const { return cables_mm_; }
  const std::vector<double>& setpoints_mm() const { return setpoints_mm_; }

 private:
  std::vector<double> cables_mm_;
  std::vector<double> setpoints_mm_;
  double step_mm_;
  hal::DrivesHealth health_;
  bool started_ = false;
};

}  // namespace cdcr::sim
