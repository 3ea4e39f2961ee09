#pragma once
// A CANopen manager for CiA 402 drives, one drive per cable, heap-free and
// never blocking: every step is a state that a cycle advances by at most a
// few frames.
//
//   reset       NMT reset communication to every drive
//   boot        wait for each drive's boot-up message (boot_timeout)
//   configure   the SDO writes of cia402::configuration_writes, one request
//               outstanding per drive, at most kMaxSdoRequestsPerCycle a
//               cycle, each answered within sdo_timeout
//   start       NMT start; the drives' heartbeats say operational
//   enable      the CiA 402 transitions 2, 3, 4 by the RPDO's controlword,
//               the target held at the drive's actual position
//               (enable_timeout)
//   operational every cycle the RPDOs with the setpoints, then the SYNC;
//               the TPDOs the drives answer with are the next cycle's
//               cable lengths
//   fault       every drive commanded to quick stop (it brakes and holds
//               there: the backbone does not drop), the SYNC goes on;
//               recover() starts again from reset, and resets a drive's
//               CiA 402 fault on the way
//
// Cable length = drive position (counts) / counts_per_mm + offset_mm; the
// sign of counts_per_mm is the drive's direction.

#include <cstdint>

#include "cdcr/firmware/canopen/cia402.hpp"
#include "cdcr/firmware/capacity.hpp"
#include "cdcr/firmware/canopen/frames.hpp"
#include "cdcr/hal/can_bus.hpp"

namespace cdcr::firmware::canopen {

using firmware::kMaxDriveBuses;
using firmware::kMaxDrives;
// SDO requests sent per cycle while configuring, over every drive.
inline constexpr int kMaxSdoRequestsPerCycle = 4;

struct DriveChannel {
  std::uint8_t bus = 0;        // which of the manager's buses
  NodeId node = 0;             // unique on its bus
  double counts_per_mm = 0.0;  // signed: the drive's direction
  double offset_mm = 0.0;      // cable length at position 0
};

struct DriveManagerConfig {
  DriveChannel drives[kMaxDrives] = {};  // cable i is drive i
  int drive_count = 0;
  int bus_count = 1;
  cia402::DriveTiming timing{};
  std::uint32_t boot_timeout_ms = 2000;
  std::uint32_t sdo_timeout_ms = 100;
  std::uint32_t enable_timeout_ms = 1000;
  // A drive whose heartbeat is this many producer periods late is lost.
  std::uint32_t heartbeat_periods_lost = 3;
  // Cycles without a TPDO before the drive's input is stale.
  std::uint32_t stale_cycles = 10;
  // How fast a drive's target may move toward its setpoint.
  double max_speed_mm_per_s = 20.0;
};

enum class DriveConfigStatus : std::uint8_t {
  ok,
  no_drives,         // drive_count 0 or above kMaxDrives
  bus_invalid,       // bus_count 0 or above kMaxDriveBuses, a drive on a bus beyond it
  node_invalid,      // a node id outside 1..127
  node_repeated,     // two cables on one drive (one node id twice on a bus)
  scale_invalid,     // counts_per_mm zero, NaN or beyond 1e6
  offset_invalid,    // offset NaN or beyond +-1e4 mm
  timing_invalid,    // cycle period 0, window beyond the period, heartbeat 0
};
DriveConfigStatus validate(const DriveManagerConfig& config);
const char* to_string(DriveConfigStatus status);

enum class DrivePhase : std::uint8_t { reset, boot, configure, start, enable, operational, fault };
const char* to_string(DrivePhase phase);

enum class DriveFault : std::uint8_t {
  none,
  config_invalid,     // validate() refused the configuration: detail the DriveConfigStatus
  boot_silent,        // no boot-up message within boot_timeout
  sdo_aborted,        // a configuration write refused: detail the abort code, object the write
  sdo_timeout,        // no SDO answer within sdo_timeout
  sdo_unexpected,     // an SDO answer for another object, or not a download's
  enable_timeout,     // not in Operation enabled within enable_timeout
  heartbeat_lost,     // no heartbeat within heartbeat_periods_lost periods
  nmt_left,           // the heartbeat says the drive left NMT operational
  emergency,          // an EMCY: detail its error code
  drive_fault,        // the statusword's fault bit: detail the statusword
  left_operation,     // no longer Operation enabled: detail the statusword
  input_stale,        // no TPDO within stale_cycles
  setpoint_range,     // a setpoint beyond the drive's 32-bit position range
};
const char* to_string(DriveFault fault);

struct DriveFaultReport {
  DriveFault fault = DriveFault::none;
  NodeId node = 0;        // the drive it is about (0: none)
  int cable = -1;         // its cable
  std::uint32_t detail = 0;
  ObjectAddress object{};  // the SDO write it is about
};

class DriveManager {
 public:
  // An invalid configuration (validate) leaves the manager in fault
  // before it sends anything.
  explicit DriveManager(const DriveManagerConfig& config) { configure(config); }
  DriveManager() { configure(DriveManagerConfig{}); }
  // Starts over with a new configuration, from reset.
  void configure(const DriveManagerConfig& config);

  using Buses = hal::CanBus* const (&)[kMaxDriveBuses];
  // A frame from bus `bus`; false if it is none of its drives'.
  bool take(const hal::CanFrame& frame, int bus);
  // Advances by one cycle and sends this cycle's frames on the buses
  // (config.bus_count of them); call after every frame of the cycle was
  // taken.
  void run_cycle(Buses buses);
  // The setpoints of every cable, in mm; false (and nothing changed) for a
  // length the drive's position cannot hold.
  bool set_setpoints(const double* lengths_mm, int count);
  // After a fault: start again from reset, resetting a drive's CiA 402
  // fault on the way.
  void recover();

  DrivePhase phase() const { return phase_; }
  const DriveFaultReport& fault() const { return fault_; }
  int drive_count() const { return config_.drive_count; }
  const DriveManagerConfig& config() const { return config_; }
  // Every drive's position arrived since the last SYNC.
  bool positions_fresh() const;
  // The cable lengths of the latest TPDOs, mm.
  double length_mm(int cable) const;
  std::int32_t actual_counts(int cable) const { return drives_[cable].actual; }
  std::int32_t target_counts(int cable) const { return drives_[cable].target; }
  std::uint16_t statusword(int cable) const { return drives_[cable].statusword; }
  // TPDOs seen twice after one SYNC (the second ignored).
  std::uint32_t repeated_pdos() const { return repeated_pdos_; }
  std::uint32_t cycles_in_phase() const { return cycles_in_phase_; }

 private:
  struct Drive {
    bool booted = false;
    int next_write = 0;
    bool sdo_pending = false;
    std::uint32_t sdo_sent_cycle = 0;
    bool heartbeat_seen = false;
    NmtState nmt = NmtState::boot_up;
    bool seen_operational = false;  // a heartbeat said so since the NMT start
    std::uint32_t heartbeat_cycle = 0;
    bool tpdo_seen = false;        // since the last SYNC
    bool has_position = false;
    std::uint32_t tpdo_cycle = 0;  // the cycle of the last TPDO
    std::uint16_t statusword = 0;
    std::int32_t actual = 0;
    std::int32_t target = 0;
    bool reset_sent = false;
  };

  int find(int bus, NodeId node) const;
  void enter(DrivePhase phase);
  void fail(DriveFault fault, int cable, std::uint32_t detail = 0, ObjectAddress object = {});
  void take_sdo(int cable, const SdoReply& reply);
  void take_tpdo(int cable, const DriveState& state);
  void broadcast(Buses buses, const hal::CanFrame& frame);
  void run_configure(Buses buses);
  void send_process_data(Buses buses, bool operating);
  void check_heartbeats();
  std::uint32_t cycles_of_ms(std::uint32_t ms) const;

  DriveManagerConfig config_;
  Drive drives_[kMaxDrives];
  DrivePhase phase_ = DrivePhase::reset;
  DriveFaultReport fault_;
  std::uint32_t cycle_ = 0;
  std::uint32_t phase_start_ = 0;
  std::uint32_t cycles_in_phase_ = 0;
  std::uint32_t repeated_pdos_ = 0;
  int sdo_cursor_ = 0;
  std::int32_t setpoint_[kMaxDrives] = {};
  // From the configuration, so that a cycle multiplies and steps in whole
  // counts (a board without a double FPU divides in software).
  double mm_per_count_[kMaxDrives] = {};
  std::int32_t ramp_counts_[kMaxDrives] = {};  // the speed limit's step a cycle
  bool has_setpoints_ = false;
  bool resetting_faults_ = false;
};

}  // namespace cdcr::firmware::canopen
