// cdcr-can-relay IFACE: a SocketCAN interface on stdin and stdout, one
// classical CAN frame a line, in can-utils' compact form:
//   III#HEX      standard identifier (3 hex digits), 0..8 data bytes
//   IIIIIIII#HEX extended identifier (8 hex digits)
//   III#R        remote request
// Frames from the bus go to stdout, lines on stdin go to the bus. The relay's
// own frames are not read back (CAN_RAW_RECV_OWN_MSGS stays off), while the
// default loopback lets other sockets on this host see them. It ends when
// stdin closes. Any error: one line on stderr, exit status 1.
//
// Build: g++ -std=c++17 -O2 -Wall -Wextra -o cdcr-can-relay can_relay.cpp

#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

namespace {

[[noreturn]] void fail(const std::string& message) {
  std::fprintf(stderr, "cdcr-can-relay: %s\n", message.c_str());
  std::exit(1);
}

std::string system_error(const char* what) { return std::string(what) + ": " + std::strerror(errno); }

int open_can(const char* interface) {
  if (std::strlen(interface) >= IFNAMSIZ) fail(std::string("interface name too long: ") + interface);
  const int fd = socket(PF_CAN, SOCK_RAW, CAN_RAW);
  if (fd < 0) fail(system_error("socket(PF_CAN, SOCK_RAW, CAN_RAW)"));
  ifreq request{};
  std::strncpy(request.ifr_name, interface, IFNAMSIZ - 1);
  if (ioctl(fd, SIOCGIFINDEX, &request) < 0) fail(std::string(interface) + ": " + std::strerror(errno));
  sockaddr_can address{};
  address.can_family = AF_CAN;
  address.can_ifindex = request.ifr_ifindex;
  if (bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) < 0)
    fail(std::string("bind to ") + interface + ": " + std::strerror(errno));
  return fd;
}

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

bool parse_line(const std::string& line, can_frame& frame) {
  frame = can_frame{};
  const std::size_t hash = line.find('#');
  if (hash != 3 && hash != 8) return false;
  canid_t id = 0;
  for (std::size_t i = 0; i < hash; ++i) {
    const int digit = hex_digit(line[i]);
    if (digit < 0) return false;
    id = (id << 4) | canid_t(digit);
  }
  if (hash == 3 && id > CAN_SFF_MASK) return false;
  if (hash == 8) {
    if (id > CAN_EFF_MASK) return false;
    id |= CAN_EFF_FLAG;
  }
  const std::string data = line.substr(hash + 1);
  if (data == "R" || data == "r") {
    frame.can_id = id | CAN_RTR_FLAG;
    return true;
  }
  if (data.size() % 2 != 0 || data.size() > 2 * CAN_MAX_DLEN) return false;
  for (std::size_t i = 0; i < data.size(); i += 2) {
    const int high = hex_digit(data[i]);
    const int low = hex_digit(data[i + 1]);
    if (high < 0 || low < 0) return false;
    frame.data[i / 2] = static_cast<__u8>((high << 4) | low);
  }
  frame.can_id = id;
  frame.can_dlc = static_cast<__u8>(data.size() / 2);
  return true;
}

void format_frame(const can_frame& frame, std::string& out) {
  static const char digits[] = "0123456789ABCDEF";
  char id[16];
  if (frame.can_id & CAN_EFF_FLAG)
    std::snprintf(id, sizeof id, "%08X#", unsigned(frame.can_id & CAN_EFF_MASK));
  else
    std::snprintf(id, sizeof id, "%03X#", unsigned(frame.can_id & CAN_SFF_MASK));
  out += id;
  if (frame.can_id & CAN_RTR_FLAG) {
    out += 'R';
  } else {
    const int length = frame.can_dlc > CAN_MAX_DLEN ? CAN_MAX_DLEN : frame.can_dlc;
    for (int i = 0; i < length; ++i) {
      out += digits[frame.data[i] >> 4];
      out += digits[frame.data[i] & 0xF];
    }
  }
  out += '\n';
}

void write_all(int fd, const std::string& text) {
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = write(fd, text.data() + done, text.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      fail(system_error("write to stdout"));
    }
    done += std::size_t(n);
  }
}

// A full transmit queue (ENOBUFS) drains at the bus rate: wait for room.
void send_frame(int fd, const can_frame& frame) {
  for (int attempt = 0;; ++attempt) {
    const ssize_t n = write(fd, &frame, sizeof frame);
    if (n == ssize_t(sizeof frame)) return;
    if (n >= 0) fail("short write to the CAN socket");
    if (errno == EINTR) continue;
    if ((errno == ENOBUFS || errno == EAGAIN) && attempt < 100) {
      pollfd writable{fd, POLLOUT, 0};
      poll(&writable, 1, 10);
      continue;
    }
    fail(system_error("write to the CAN socket"));
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2 || argv[1][0] == '-') {
    std::fprintf(stderr, "usage: cdcr-can-relay IFACE\n");
    return 1;
  }
  std::signal(SIGPIPE, SIG_IGN);  // a closed stdout is an error from write, not a silent death
  const int can = open_can(argv[1]);

  std::string input;
  std::string output;
  unsigned long line_number = 0;
  pollfd fds[2] = {{can, POLLIN, 0}, {STDIN_FILENO, POLLIN, 0}};
  for (;;) {
    if (poll(fds, 2, -1) < 0) {
      if (errno == EINTR) continue;
      fail(system_error("poll"));
    }
    if (fds[0].revents & (POLLERR | POLLNVAL)) fail("the CAN socket failed");
    if (fds[0].revents & POLLIN) {
      // Everything pending goes out in one write: at 1 kHz a write per frame costs.
      output.clear();
      can_frame frame;
      for (;;) {
        const ssize_t n = recv(can, &frame, sizeof frame, MSG_DONTWAIT);
        if (n < 0) {
          if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) break;
          fail(system_error("read from the CAN socket"));
        }
        if (n != ssize_t(sizeof frame)) fail("a CAN frame of unexpected size");
        format_frame(frame, output);
      }
      write_all(STDOUT_FILENO, output);
    }
    if (fds[1].revents & (POLLIN | POLLHUP | POLLERR)) {
      char buffer[65536];
      const ssize_t n = read(STDIN_FILENO, buffer, sizeof buffer);
      if (n < 0) {
        if (errno == EINTR) continue;
        fail(system_error("read from stdin"));
      }
      // At the end a last line may lack its newline.
      if (n == 0 && input.empty()) return 0;
      if (n == 0) input += '\n';
      input.append(buffer, std::size_t(n));
      std::size_t start = 0;
      for (std::size_t end; (end = input.find('\n', start)) != std::string::npos; start = end + 1) {
        std::string line = input.substr(start, end - start);
        ++line_number;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (line.empty()) continue;
        can_frame frame;
        if (!parse_line(line, frame)) fail("bad line " + std::to_string(line_number) + " on stdin: '" + line + "'");
        send_frame(can, frame);
      }
      input.erase(0, start);
    }
  }
}
