#pragma once
// CanBus on a SocketCAN raw socket (11-bit identifiers; classical frames,
// and CAN FD frames on an interface with the FD MTU), non-blocking. Acceptance filters go to the kernel (CAN_RAW_FILTER), so
// unwanted traffic never reaches the runtime's receive budget.

#include <cstddef>
#include <cstdint>
#include <string>

#include <cdcr/hal/can_bus.hpp>

namespace cdcr::linux_host {

class SocketCanBus final : public hal::CanBus {
 public:
  // Filters a socket accepts; the kernel takes more, but the runtime needs few.
  static constexpr std::size_t kMaxFilters = 16;

  SocketCanBus() = default;
  ~SocketCanBus();
  SocketCanBus(const SocketCanBus&) = delete;
  SocketCanBus& operator=(const SocketCanBus&) = delete;

  // Binds to the named interface; with `fd`, CAN FD frames too, which the
  // interface must carry (its MTU is CANFD_MTU: `ip link set can0 mtu 72`,
  // or a controller configured with `fd on`). On failure returns false,
  // holds no socket and describes the cause in `error` (one line), e.g. a
  // missing interface, a kernel without AF_CAN or an interface without FD.
  bool open(const std::string& interface_name, std::string& error, bool fd = false);
  void close();
  bool is_open() const { return fd_ >= 0; }

  hal::CanStatus send(const hal::CanFrame& frame) override;
  // Error frames are counted (and bus-off noted), never returned as data.
  hal::CanStatus receive(hal::CanFrame& frame) override;
  bool set_filters(const hal::CanFilter* filters, std::size_t count) override;
  hal::CanErrorCounters error_counters() const override {
    hal::CanErrorCounters counters = counters_;
    counters.rx_overruns += socket_rx_drops_;
    return counters;
  }
  bool fd_capable() const override { return fd_frames_; }

 private:
  void note_error_frame(std::uint32_t can_id, const std::uint8_t* data);

  int fd_ = -1;
  bool fd_frames_ = false;
  bool bus_off_ = false;
  hal::CanErrorCounters counters_;
  std::uint32_t socket_rx_drops_ = 0;  // the kernel's running count for this socket
};

}  // namespace cdcr::linux_host
