// The firmware's CiA 402 manager (firmware/canopen/drive_manager.hpp)
// against drives on a CANopen stack this project did not write: the npm
// `canopen` package with the project's CiA 402 layer (tools/sim/cia402),
// one node process for the drives, its frames on a pipe (drive_sim.js
// --stdio). Each cycle the manager's frames go out, then a barrier line
// that the simulator answers once it has answered them, so no answer is
// missed on a loaded machine; cycles are paced to at least 1 ms of real
// time, as the drives' heartbeats run on their own clock.
//
//   CDCR_NODE, CDCR_DRIVE_SIM: node and drive_sim.js (set by ctest).

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include <cdcr/firmware/canopen/drive_manager.hpp>

namespace cdcr::firmware::canopen {
namespace {

// The simulator's stdin and stdout as a bus, one frame a line (III#HEX).
class PipeBus final : public hal::CanBus {
 public:
  explicit PipeBus(const std::vector<std::string>& arguments) {
    int to_child[2], from_child[2];
    if (pipe(to_child) != 0 || pipe(from_child) != 0) std::abort();
    child_ = fork();
    if (child_ == 0) {
      dup2(to_child[0], 0);
      dup2(from_child[1], 1);
      close(to_child[1]);
      close(from_child[0]);
      std::vector<char*> argv;
      for (const std::string& a : arguments) argv.push_back(const_cast<char*>(a.c_str()));
      argv.push_back(nullptr);
      execv(argv[0], argv.data());
      _exit(127);
    }
    close(to_child[0]);
    close(from_child[1]);
    out_ = to_child[1];
    in_ = from_child[0];
    signal(SIGPIPE, SIG_IGN);
  }
  ~PipeBus() {
    close(out_);
    int status = 0;
    for (int i = 0; i < 50 && waitpid(child_, &status, WNOHANG) == 0; ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    kill(child_, SIGKILL);
    waitpid(child_, &status, 0);
    close(in_);
  }

  hal::CanStatus send(const hal::CanFrame& frame) override {
    char line[32];
    int used = std::snprintf(line, sizeof line, "%03X#", unsigned(frame.id));
    for (int i = 0; i < frame.dlc; ++i) used += std::snprintf(line + used, sizeof line - used, "%02X", frame.data[i]);
    outgoing_ += line;
    outgoing_ += '\n';
    return hal::CanStatus::ok;
  }
  hal::CanStatus receive(hal::CanFrame& frame) override {
    if (incoming_.empty()) return hal::CanStatus::empty;
    frame = incoming_.front();
    incoming_.pop_front();
    return hal::CanStatus::ok;
  }
  bool set_filters(const hal::CanFilter*, std::size_t) override { return true; }
  hal::CanErrorCounters error_counters() const override { return {}; }

  // The cycle's frames and the barrier out; every answer in, up to the
  // barrier's. False if the simulator stopped answering (10 s).
  bool exchange() {
    outgoing_ += "#\n";
    const char* data = outgoing_.data();
    std::size_t left = outgoing_.size();
    while (left > 0) {
      const ssize_t n = write(out_, data, left);
      if (n <= 0) return false;
      data += n;
      left -= std::size_t(n);
    }
    outgoing_.clear();
    for (;;) {
      const auto newline = buffer_.find('\n');
      if (newline != std::string::npos) {
        const std::string line = buffer_.substr(0, newline);
        buffer_.erase(0, newline + 1);
        if (line == "#") return true;
        take_line(line);
        continue;
      }
      pollfd ready{in_, POLLIN, 0};
      if (poll(&ready, 1, 10000) <= 0) return false;
      char chunk[4096];
      const ssize_t n = read(in_, chunk, sizeof chunk);
      if (n <= 0) return false;
      buffer_.append(chunk, std::size_t(n));
    }
  }

 private:
  void take_line(const std::string& line) {
    unsigned id = 0;
    if (line.size() < 4 || line[3] != '#' || std::sscanf(line.c_str(), "%3x#", &id) != 1) return;
    hal::CanFrame frame;
    frame.id = id;
    const std::string hex = line.substr(4);
    frame.dlc = std::uint8_t(hex.size() / 2);
    for (int i = 0; i < frame.dlc; ++i) frame.data[i] = std::uint8_t(std::stoul(hex.substr(2 * i, 2), nullptr, 16));
    incoming_.push_back(frame);
  }

  pid_t child_ = -1;
  int out_ = -1, in_ = -1;
  std::string outgoing_, buffer_;
  std::deque<hal::CanFrame> incoming_;
};

class ManagerOnNpmStack : public ::testing::Test {
 protected:
  static constexpr int kDrives = 4;

  // A fatal failure here skips the test's body.
  void SetUp() override {
    node_ = std::getenv("CDCR_NODE");
    sim_ = std::getenv("CDCR_DRIVE_SIM");
    ASSERT_TRUE(node_ != nullptr && sim_ != nullptr) << "CDCR_NODE and CDCR_DRIVE_SIM are set by ctest";
  }

  void start(const std::vector<std::string>& faults = {}) {
    std::vector<std::string> arguments{node_, sim_, "--stdio", "--nodes", "1,2,3,4", "--tau-ms", "2",
                                       "--initial-counts", "0,1000,-2000,3000"};
    for (const std::string& fault : faults) {
      arguments.push_back("--fault");
      arguments.push_back(fault);
    }
    bus_ = std::make_unique<PipeBus>(arguments);
    config_.drive_count = kDrives;
    for (int i = 0; i < kDrives; ++i) config_.drives[i] = {0, NodeId(i + 1), 1000.0, 100.0};
    config_.timing = {1000, 500, 20};
    config_.max_speed_mm_per_s = 20.0;
    manager_ = std::make_unique<DriveManager>(config_);
  }

  // The drives' answers to the last cycle.
  void take_frames() {
    hal::CanFrame frame;
    while (bus_->receive(frame) == hal::CanStatus::ok) manager_->take(frame, 0);
  }
  // One cycle, at least 1 ms of real time.
  void cycle() {
    const auto begin = std::chrono::steady_clock::now();
    take_frames();
    hal::CanBus* const buses[kMaxDriveBuses] = {bus_.get(), nullptr, nullptr, nullptr};
    manager_->run_cycle(buses);
    ASSERT_TRUE(bus_->exchange()) << "the drive simulator stopped answering";
    std::this_thread::sleep_until(begin + std::chrono::milliseconds(1));
  }
  int run_until(DrivePhase phase, int limit) {
    for (int n = 1; n <= limit; ++n) {
      cycle();
      if (manager_->phase() == phase) return n;
    }
    return -1;
  }
  std::string fault_text() const {
    const DriveFaultReport& fault = manager_->fault();
    return std::string(to_string(fault.fault)) + " node " + std::to_string(fault.node) + " detail " +
           std::to_string(fault.detail);
  }

  const char* node_ = nullptr;
  const char* sim_ = nullptr;
  DriveManagerConfig config_;
  std::unique_ptr<PipeBus> bus_;
  std::unique_ptr<DriveManager> manager_;
};

TEST_F(ManagerOnNpmStack, BootConfigureEnableAndFollow) {
  start();
  // 18 writes a drive, answered in the cycle they are sent: about 20 cycles.
  const int cycles = run_until(DrivePhase::operational, 500);
  ASSERT_GT(cycles, 0) << fault_text();
  EXPECT_LT(cycles, 60);
  cycle();
  take_frames();
  ASSERT_TRUE(manager_->positions_fresh());
  // Where each drive stood at power-up: enabled there, nothing moved.
  EXPECT_DOUBLE_EQ(manager_->length_mm(0), 100.0);
  EXPECT_DOUBLE_EQ(manager_->length_mm(1), 101.0);
  EXPECT_DOUBLE_EQ(manager_->length_mm(2), 98.0);
  EXPECT_DOUBLE_EQ(manager_->length_mm(3), 103.0);
  for (int i = 0; i < kDrives; ++i) EXPECT_EQ(manager_->statusword(i) & 0x6F, 0x27) << "operation enabled";
  const double setpoints[kDrives] = {101.5, 100.0, 98.25, 102.0};
  ASSERT_TRUE(manager_->set_setpoints(setpoints, kDrives));
  // 1.5 mm at 20 mm/s: 75 cycles of ramp, then the drives' 2 ms lag.
  for (int n = 0; n < 150; ++n) cycle();
  ASSERT_EQ(manager_->phase(), DrivePhase::operational) << fault_text();
  take_frames();
  for (int i = 0; i < kDrives; ++i) EXPECT_NEAR(manager_->length_mm(i), setpoints[i], 0.0015) << "drive " << i;
  EXPECT_EQ(manager_->repeated_pdos(), 0u);
}

TEST_F(ManagerOnNpmStack, RefusedWriteIsTheDrivesAbort) {
  start({"refuse:2:6060"});
  ASSERT_GT(run_until(DrivePhase::fault, 500), 0);
  EXPECT_EQ(manager_->fault().fault, DriveFault::sdo_aborted) << fault_text();
  EXPECT_EQ(manager_->fault().node, 2);
  EXPECT_EQ(manager_->fault().detail, sdo::kAbortReadOnly);
  EXPECT_EQ(manager_->fault().object.index, 0x6060);
}

TEST_F(ManagerOnNpmStack, DriveThatNeverAnswers) {
  start({"silent:3"});
  config_.boot_timeout_ms = 300;
  manager_ = std::make_unique<DriveManager>(config_);
  const int cycles = run_until(DrivePhase::fault, 1000);
  EXPECT_EQ(manager_->fault().fault, DriveFault::boot_silent) << fault_text();
  EXPECT_EQ(manager_->fault().node, 3);
  EXPECT_GE(cycles, 300);
}

TEST_F(ManagerOnNpmStack, HeartbeatStops) {
  start({"heartbeat-stop:4@400"});
  ASSERT_GT(run_until(DrivePhase::operational, 500), 0) << fault_text();
  ASSERT_GT(run_until(DrivePhase::fault, 2000), 0);
  EXPECT_EQ(manager_->fault().fault, DriveFault::heartbeat_lost) << fault_text();
  EXPECT_EQ(manager_->fault().node, 4);
}

TEST_F(ManagerOnNpmStack, EmergencyThenRecovery) {
  start({"emcy:1:2310@300"});
  ASSERT_GT(run_until(DrivePhase::operational, 500), 0) << fault_text();
  ASSERT_GT(run_until(DrivePhase::fault, 2000), 0);
  EXPECT_EQ(manager_->fault().fault, DriveFault::emergency) << fault_text();
  EXPECT_EQ(manager_->fault().node, 1);
  EXPECT_EQ(manager_->fault().detail, 0x2310u);
  manager_->recover();
  ASSERT_GT(run_until(DrivePhase::operational, 1000), 0) << fault_text();
  for (int n = 0; n < 20; ++n) cycle();
  EXPECT_EQ(manager_->phase(), DrivePhase::operational) << fault_text();
}

TEST_F(ManagerOnNpmStack, TpdoTwiceIsCountedLateIsMissed) {
  start({"tpdo-twice:2@200", "tpdo-late:3:3@400"});
  ASSERT_GT(run_until(DrivePhase::operational, 500), 0) << fault_text();
  bool missed = false;
  for (int n = 0; n < 500; ++n) {
    take_frames();
    missed = missed || !manager_->positions_fresh();
    hal::CanBus* const buses[kMaxDriveBuses] = {bus_.get(), nullptr, nullptr, nullptr};
    manager_->run_cycle(buses);
    ASSERT_TRUE(bus_->exchange());
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  EXPECT_EQ(manager_->phase(), DrivePhase::operational) << fault_text();
  EXPECT_GT(manager_->repeated_pdos(), 100u);
  EXPECT_TRUE(missed) << "the late TPDOs left cycles without every position";
}

}  // namespace
}  // namespace cdcr::firmware::canopen
