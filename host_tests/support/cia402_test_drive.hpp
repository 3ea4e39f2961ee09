#pragma once
// A CiA 402 drive as CiA 301 and 402-2 describe its bus side: NMT, an
// expedited SDO server, RPDO1 and TPDO1 released by the SYNC, heartbeat,
// EMCY and the power state machine, with a first-order position loop. For
// the manager's, the runtime's and the C API's unit tests, and the boards'
// budget with the CiA 402 backend (host_tests/qemu/programs), so it holds
// everything in fixed arrays: nothing allocates. The drives on the npm
// `canopen` stack (tools/sim/cia402) check the same against a stack this
// project did not write.

#include <cstddef>
#include <cstdint>

#include <cdcr/firmware/canopen/frames.hpp>
#include <cdcr/hal/can_bus.hpp>

namespace cdcr::firmware::canopen {

// A few values in a fixed array, as much of std::set and std::map as the
// tests use. A full table drops what does not fit and says so in `full`.
template <typename Key, typename Value, std::size_t Capacity>
struct FixedTable {
  Key keys[Capacity] = {};
  Value values[Capacity] = {};
  std::size_t used = 0;
  bool full = false;

  int find(Key key) const {
    for (std::size_t i = 0; i < used; ++i)
      if (keys[i] == key) return int(i);
    return -1;
  }
  std::size_t count(Key key) const { return find(key) >= 0 ? 1 : 0; }
  std::size_t size() const { return used; }
  // The value, or ~0 when there is none (so a test's comparison fails).
  Value at(Key key) const {
    const int i = find(key);
    return i >= 0 ? values[i] : Value(~Value(0));
  }
  void set(Key key, Value value = Value()) {
    const int i = find(key);
    if (i >= 0) {
      values[i] = value;
    } else if (used < Capacity) {
      keys[used] = key;
      values[used++] = value;
    } else {
      full = true;
    }
  }
  void insert(Key key) { set(key); }
  void erase(Key key) {
    const int i = find(key);
    if (i < 0) return;
    for (std::size_t j = std::size_t(i) + 1; j < used; ++j) {
      keys[j - 1] = keys[j];
      values[j - 1] = values[j];
    }
    --used;
  }
};

// The SDO writes in order, as many as fit.
template <std::size_t Capacity>
struct WriteLog {
  std::uint32_t entries[Capacity] = {};
  std::size_t used = 0;
  void push_back(std::uint32_t key) {
    if (used < Capacity) entries[used++] = key;
  }
  std::size_t size() const { return used; }
};

struct TestDrive {
  NodeId node = 0;
  NmtState nmt = NmtState::boot_up;
  bool powered = true;          // answers at all
  bool heartbeat_on = true;     // produces its heartbeat
  bool answers_sync = true;     // sends its TPDO on SYNC
  bool repeat_tpdo = false;     // sends each TPDO twice
  FixedTable<std::uint16_t, bool, 4> refused;             // objects whose writes it aborts (value range)
  FixedTable<std::uint32_t, std::uint32_t, 32> objects;   // (index << 8 | subindex) -> value
  WriteLog<64> written;                                   // in order
  std::uint16_t statusword = 0x0250;              // switch on disabled
  std::uint16_t controlword = 0;
  std::uint16_t pending_controlword = 0;
  std::int32_t pending_target = 0;
  bool has_pending = false;
  double position = 0;
  std::int32_t target = 0;
  std::uint32_t ms = 0;

  std::uint16_t heartbeat_ms() const {
    return objects.count(0x101700) != 0 ? std::uint16_t(objects.at(0x101700)) : 0;
  }
  void step_power_state(std::uint16_t cw) {
    const bool fault_reset = (cw & 0x80) && !(controlword & 0x80);
    controlword = cw;
    switch (statusword) {
      case 0x0218:  // fault
        if (fault_reset) statusword = 0x0250;
        return;
      case 0x0250:
        if ((cw & 0x87) == 0x06) statusword = 0x0231;
        return;
      case 0x0231:
        if ((cw & 0x8F) == 0x07) statusword = 0x0233;
        if ((cw & 0x8F) == 0x0F) statusword = 0x0237;
        if ((cw & 0x02) == 0) statusword = 0x0250;
        return;
      case 0x0233:
        if ((cw & 0x8F) == 0x0F) statusword = 0x0237;
        if ((cw & 0x8F) == 0x06) statusword = 0x0231;
        if ((cw & 0x02) == 0) statusword = 0x0250;
        return;
      case 0x0237:
        if ((cw & 0x86) == 0x02) statusword = 0x0217;  // quick stop
        else if ((cw & 0x8F) == 0x07) statusword = 0x0233;
        else if ((cw & 0x8F) == 0x06) statusword = 0x0231;
        else if ((cw & 0x02) == 0) statusword = 0x0250;
        return;
      case 0x0217:
        if ((cw & 0x02) == 0) statusword = 0x0250;
        return;
    }
  }
  void fault(hal::CanBus& bus, std::uint16_t error_code) {
    statusword = 0x0218;
    Emergency emergency;
    emergency.node = node;
    emergency.error_code = error_code;
    emergency.error_register = 0x03;
    bus.send(emergency_frame(emergency));
  }

  void take(const hal::CanFrame& frame, hal::CanBus& bus) {
    if (!powered) return;
    if (frame.id == kNmtId && frame.dlc == 2 && (frame.data[1] == 0 || frame.data[1] == node)) {
      switch (frame.data[0]) {
        case 0x82:
        case 0x81:
          objects.erase(0x101700);
          nmt = NmtState::pre_operational;
          bus.send(heartbeat_frame({node, NmtState::boot_up}));
          break;
        case 0x01: nmt = NmtState::operational; break;
        case 0x02: nmt = NmtState::stopped; break;
        case 0x80: nmt = NmtState::pre_operational; break;
      }
      return;
    }
    if (frame.id == kSdoClientBase + node && nmt != NmtState::stopped) {
      const std::uint16_t index = std::uint16_t(frame.data[1] | (frame.data[2] << 8));
      const std::uint8_t sub = frame.data[3];
      hal::CanFrame reply;
      reply.id = kSdoServerBase + node;
      reply.dlc = 8;
      reply.data[1] = frame.data[1];
      reply.data[2] = frame.data[2];
      reply.data[3] = sub;
      if ((frame.data[0] & 0xE3) == 0x23 && !refused.count(index)) {
        const int size = 4 - ((frame.data[0] >> 2) & 3);
        std::uint32_t value = 0;
        for (int i = 0; i < size; ++i) value |= std::uint32_t(frame.data[4 + i]) << (8 * i);
        objects.set((std::uint32_t(index) << 8) | sub, value);
        written.push_back((std::uint32_t(index) << 8) | sub);
        reply.data[0] = 0x60;
      } else {
        reply.data[0] = 0x80;
        const std::uint32_t code = sdo::kAbortValueRange;
        for (int i = 0; i < 4; ++i) reply.data[4 + i] = std::uint8_t(code >> (8 * i));
      }
      bus.send(reply);
      return;
    }
    if (nmt != NmtState::operational) return;
    DriveCommand command;
    if (decode_rpdo(frame, command) && command.node == node) {
      pending_controlword = command.controlword;
      pending_target = command.target_position;
      has_pending = true;
      return;
    }
    if (frame.id == kSyncId && frame.dlc == 0) {
      if (has_pending) {
        step_power_state(pending_controlword);
        if (statusword == 0x0237) target = pending_target;
        has_pending = false;
      }
      // A first-order position loop: half the way each cycle.
      if (statusword == 0x0237) position += 0.5 * (double(target) - position);
      if (!answers_sync) return;
      const hal::CanFrame tpdo = tpdo_frame({node, statusword, std::int32_t(position)});
      bus.send(tpdo);
      if (repeat_tpdo) bus.send(tpdo);
    }
  }
  // One millisecond of the drive's own time.
  void tick(hal::CanBus& bus) {
    ++ms;
    const std::uint16_t period = heartbeat_ms();
    if (powered && heartbeat_on && period > 0 && ms % period == 0) bus.send(heartbeat_frame({node, nmt}));
  }
};

}  // namespace cdcr::firmware::canopen
