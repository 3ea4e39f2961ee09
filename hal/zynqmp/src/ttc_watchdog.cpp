#include "cdcr/zynqmp/ttc_watchdog.hpp"

namespace cdcr::zynqmp {
namespace {

// The first counter's registers (UG1087, TTC); the second and third counters
// sit 4 bytes further each.
enum RegisterOffset : std::uint32_t {
  kClockControl = 0x00,
  kCounterControl = 0x0C,
  kCounterValue = 0x18,
  kMatch1 = 0x30,
  kMatch2 = 0x3C,
  kMatch3 = 0x48,
  kInterruptStatus = 0x54,  // clears on read
  kInterruptEnable = 0x60,
};

constexpr std::uint32_t kClockPrescaleEnable = 1u << 0;
constexpr std::uint32_t kClockPrescaleShift = 1;  // 4 bits: divide by 2^(1 + value)

constexpr std::uint32_t kCounterDisable = 1u << 0;
constexpr std::uint32_t kCounterReset = 1u << 4;
constexpr std::uint32_t kCounterWaveDisable = 1u << 5;  // the waveform output is not used
// Counting up, overflow mode (no interval), match mode off.
constexpr std::uint32_t kCounterRunning = kCounterWaveDisable;

constexpr std::uint32_t kInterruptOverflow = 1u << 4;

}  // namespace

// Reading the interrupt register clears it.
std::uint32_t TtcWatchdog::take_interrupt_flags() { return reg(kInterruptStatus); }


bool TtcWatchdog::start(std::uint64_t timeout_ns) {
  stop();
  const TtcTimeout timeout = ttc_timeout(clock_hz_, timeout_ns);
  if (timeout.timeout_counts == 0) return false;
  reg(kInterruptEnable) = 0;  // polled; see the header for the interrupt
  reg(kMatch1) = 0;           // no match events (the header says why)
  reg(kMatch2) = 0;
  reg(kMatch3) = 0;
  reg(kClockControl) =
      timeout.prescaled ? kClockPrescaleEnable | (timeout.prescale_exponent << kClockPrescaleShift) : 0;
  take_interrupt_flags();
  reg(kCounterControl) = kCounterRunning | kCounterReset;
  timeout_ns_ = timeout_ns;
  timeout_counts_ = timeout.timeout_counts;
  expired_ = false;
  return true;
}

void TtcWatchdog::stop() {
  reg(kCounterControl) = kCounterDisable | kCounterWaveDisable;
  take_interrupt_flags();
  timeout_counts_ = 0;
}

void TtcWatchdog::kick() {
  // An expiry before this kick still counts: look before restarting.
  (void)expired();
  reg(kCounterControl) = kCounterRunning | kCounterReset;
}

bool TtcWatchdog::expired() {
  if (timeout_counts_ == 0) return expired_;  // stopped
  if ((take_interrupt_flags() & kInterruptOverflow) != 0 || count() >= timeout_counts_) expired_ = true;
  return expired_;
}

std::uint32_t TtcWatchdog::count() const { return reg(kCounterValue) & 0xFFFFu; }

}  // namespace cdcr::zynqmp
