#include "cdcr/linux/socketcan_bus.hpp"

#include <cerrno>
#include <cstring>
#include <string>

#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

namespace cdcr::linux_host {

namespace {

constexpr std::uint32_t kStandardIdMask = 0x7FF;

std::string describe(const char* step, int error_number) {
  std::string text = std::string(step) + ": " + std::strerror(error_number);
  if (error_number == EAFNOSUPPORT) text += " (this kernel has no SocketCAN support)";
  return text;
}

}  // namespace

SocketCanBus::~SocketCanBus() { close(); }

void SocketCanBus::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

bool SocketCanBus::open(const std::string& interface_name, std::string& error, bool fd_frames) {
  close();
  fd_frames_ = false;
  bus_off_ = false;
  counters_ = {};
  socket_rx_drops_ = 0;
  if (interface_name.empty() || interface_name.size() >= IFNAMSIZ) {
    error = "invalid CAN interface name '" + interface_name + "'";
    return false;
  }
  const int fd = ::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
  if (fd < 0) {
    error = describe("socket(AF_CAN, SOCK_RAW, CAN_RAW)", errno);
    return false;
  }
  ifreq request{};
  std::memcpy(request.ifr_name, interface_name.c_str(), interface_name.size() + 1);
  if (::ioctl(fd, SIOCGIFINDEX, &request) != 0) {
    const int e = errno;
    ::close(fd);
    error = e == ENODEV ? "no CAN interface '" + interface_name + "'" : describe(("interface " + interface_name).c_str(), e);
    return false;
  }
  const int interface_index = request.ifr_ifindex;  // the MTU request below reuses the union
  if (fd_frames) {
    if (::ioctl(fd, SIOCGIFMTU, &request) != 0 || request.ifr_mtu != int(CANFD_MTU)) {
      ::close(fd);
      error = "CAN interface '" + interface_name + "' does not carry CAN FD frames (its MTU is not " +
              std::to_string(CANFD_MTU) + ")";
      return false;
    }
    const int enable_fd = 1;
    if (::setsockopt(fd, SOL_CAN_RAW, CAN_RAW_FD_FRAMES, &enable_fd, sizeof(enable_fd)) != 0) {
      const int e = errno;
      ::close(fd);
      error = describe("CAN_RAW_FD_FRAMES", e);
      return false;
    }
  }
  // Controller problems arrive as error frames; ask for all of them so the
  // counters see what the controller saw.
  const can_err_mask_t error_mask = CAN_ERR_MASK;
  ::setsockopt(fd, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &error_mask, sizeof(error_mask));
  // Receive-queue drops are reported with every message, so overruns are
  // counted without polling the interface statistics.
  const int enable = 1;
  ::setsockopt(fd, SOL_SOCKET, SO_RXQ_OVFL, &enable, sizeof(enable));

  sockaddr_can address{};
  address.can_family = AF_CAN;
  address.can_ifindex = interface_index;
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) != 0) {
    const int e = errno;
    ::close(fd);
    error = describe(("bind to " + interface_name).c_str(), e);
    return false;
  }
  fd_ = fd;
  fd_frames_ = fd_frames;
  return true;
}

hal::CanStatus SocketCanBus::send(const hal::CanFrame& frame) {
  if (!hal::is_valid(frame, fd_frames_)) {
    counters_.tx_dropped += 1;
    return hal::CanStatus::invalid_frame;
  }
  if (fd_ < 0 || bus_off_) {
    counters_.tx_dropped += 1;
    return hal::CanStatus::bus_off;
  }
  // A classical frame goes as can_frame (CAN_MTU), an FD frame as
  // canfd_frame (CANFD_MTU): the kernel tells the two apart by size.
  canfd_frame out{};
  out.can_id = frame.id;
  out.len = frame.dlc;
  if (frame.bit_rate_switch()) out.flags |= CANFD_BRS;
  std::memcpy(out.data, frame.data, frame.dlc);
  const std::size_t size = frame.fd() ? CANFD_MTU : CAN_MTU;
  const ssize_t written = ::write(fd_, &out, size);
  if (written == ssize_t(size)) return hal::CanStatus::ok;
  counters_.tx_dropped += 1;
  if (written < 0 && (errno == ENETDOWN || errno == ENXIO || errno == ENODEV)) return hal::CanStatus::bus_off;
  // EAGAIN / ENOBUFS: the interface's transmit queue is full.
  return hal::CanStatus::queue_full;
}

hal::CanStatus SocketCanBus::receive(hal::CanFrame& frame) {
  if (fd_ < 0) return hal::CanStatus::bus_off;
  for (;;) {
    canfd_frame in{};
    iovec buffer{&in, sizeof(in)};
    alignas(cmsghdr) char control[CMSG_SPACE(sizeof(std::uint32_t))];
    msghdr message{};
    message.msg_iov = &buffer;
    message.msg_iovlen = 1;
    message.msg_control = control;
    message.msg_controllen = sizeof(control);
    const ssize_t got = ::recvmsg(fd_, &message, MSG_DONTWAIT);
    if (got < 0) {
      if (errno == EINTR) continue;
      if (errno == ENETDOWN) return hal::CanStatus::bus_off;
      return bus_off_ ? hal::CanStatus::bus_off : hal::CanStatus::empty;
    }
    for (cmsghdr* c = CMSG_FIRSTHDR(&message); c != nullptr; c = CMSG_NXTHDR(&message, c)) {
      if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SO_RXQ_OVFL) {
        std::uint32_t dropped = 0;
        std::memcpy(&dropped, CMSG_DATA(c), sizeof(dropped));
        // The kernel's count is cumulative for the socket.
        socket_rx_drops_ = dropped;
      }
    }
    const bool fd_frame = got == ssize_t(CANFD_MTU);
    if (!fd_frame && got != ssize_t(CAN_MTU)) continue;  // not a frame
    if (in.can_id & CAN_ERR_FLAG) {
      note_error_frame(in.can_id, in.data);
      continue;
    }
    // Remote and extended frames are not part of the protocol.
    if (in.can_id & (CAN_RTR_FLAG | CAN_EFF_FLAG)) continue;
    bus_off_ = false;
    frame.id = in.can_id & kStandardIdMask;
    const std::uint8_t limit = fd_frame ? hal::kMaxFdDataBytes : hal::kMaxDataBytes;
    frame.dlc = in.len > limit ? limit : in.len;
    frame.flags = fd_frame ? std::uint8_t(hal::kCanFdFrame | ((in.flags & CANFD_BRS) ? hal::kCanBitRateSwitch : 0)) : 0;
    std::memset(frame.data, 0, sizeof(frame.data));
    std::memcpy(frame.data, in.data, frame.dlc);
    return hal::CanStatus::ok;
  }
}

void SocketCanBus::note_error_frame(std::uint32_t can_id, const std::uint8_t* data) {
  counters_.bus_errors += 1;
  if (can_id & CAN_ERR_BUSOFF) bus_off_ = true;
  if (can_id & CAN_ERR_RESTARTED) bus_off_ = false;
  // A controller FIFO overflow loses frames before the socket sees them.
  if ((can_id & CAN_ERR_CRTL) && (data[1] & CAN_ERR_CRTL_RX_OVERFLOW)) counters_.rx_overruns += 1;
}

bool SocketCanBus::set_filters(const hal::CanFilter* filters, std::size_t count) {
  if (count > kMaxFilters || fd_ < 0) return false;
  can_filter kernel_filters[kMaxFilters];
  for (std::size_t i = 0; i < count; ++i) {
    kernel_filters[i].can_id = filters[i].id & kStandardIdMask;
    // The flag bits in the mask keep extended and remote frames out.
    kernel_filters[i].can_mask = (filters[i].mask & kStandardIdMask) | CAN_EFF_FLAG | CAN_RTR_FLAG;
  }
  if (count == 0) {
    // No filter: every frame, as the interface defines it.
    kernel_filters[0] = {0, 0};
    count = 1;
  }
  return ::setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_FILTER, kernel_filters, socklen_t(count * sizeof(can_filter))) == 0;
}

}  // namespace cdcr::linux_host
