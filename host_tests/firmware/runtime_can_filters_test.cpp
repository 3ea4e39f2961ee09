// A controller that refuses the acceptance filters hands the runtime every
// frame on the bus. The runtime must say so (a standing fault in every
// STATUS) rather than run unfiltered in silence, and still run: foreign
// frames are ignored, not counted as malformed, and the per-cycle receive
// cap bounds the work.

#include <cstddef>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "runtime_test_fixture.hpp"

namespace cdcr::firmware {
namespace {

namespace protocol = firmware::protocol;
using test_support::RuntimeTest;

// A controller without acceptance filters: set_filters always fails.
class FilterlessCan final : public hal::CanBus {
 public:
  explicit FilterlessCan(hal::CanBus& bus) : bus_(bus) {}
  hal::CanStatus send(const hal::CanFrame& frame) override { return bus_.send(frame); }
  hal::CanStatus receive(hal::CanFrame& frame) override { return bus_.receive(frame); }
  bool set_filters(const hal::CanFilter*, std::size_t) override { return false; }
  hal::CanErrorCounters error_counters() const override { return bus_.error_counters(); }

 private:
  hal::CanBus& bus_;
};

TEST_F(RuntimeTest, RefusedFiltersAreAStandingFaultAndTheRuntimeRuns) {
  make_platform(test_support::small_image());
  FilterlessCan controller(platform->bus.node(0));
  start_runtime(hal::Hal{platform->clock, platform->timer, controller, platform->storage, platform->console});
  EXPECT_FALSE(runtime->can_filters_accepted());
  EXPECT_EQ(runtime->state(), RuntimeState::run);  // the image is fine: compensated, not degraded
  EXPECT_EQ(runtime->active_fault(), FaultCode::can_filters_refused);
  EXPECT_EQ(runtime->active_fault_detail(), FaultDetail());
  bool logged = false;
  for (const std::string& line : platform->console.lines) {
    logged = logged || line.find(to_string(FaultCode::can_filters_refused)) != std::string::npos;
  }
  EXPECT_TRUE(logged);

  // Another node's traffic, which filters would have kept out: frames of
  // the protocol the runtime does not take, and frames of no protocol.
  hal::CanBus& other_node = platform->bus.node(3);
  hal::CanFrame setpoint, pose, foreign;
  ASSERT_TRUE(protocol::encode(protocol::CableSetpoint{7, {100, 110, 120, 130}}, setpoint));  // no such drive here
  protocol::encode(protocol::PosePositionXy{1, 2}, pose);
  foreign.id = 0x7F0;
  foreign.dlc = 3;
  host_frames();
  for (int k = 0; k < 50; ++k) {
    for (const hal::CanFrame* frame : {&setpoint, &pose, &foreign}) other_node.send(*frame);
    cycles(1);
  }
  EXPECT_EQ(runtime->state(), RuntimeState::run);
  EXPECT_EQ(runtime->statistics().poses_published, 50u);
  EXPECT_EQ(runtime->statistics().rejected_frames, 0u);
  EXPECT_EQ(runtime->active_fault(), FaultCode::can_filters_refused);

  int statuses = 0;
  for (const hal::CanFrame& frame : host_frames()) {
    protocol::Status decoded;
    if (protocol::decode(frame, decoded) != protocol::DecodeStatus::ok) continue;
    ++statuses;
    EXPECT_EQ(decoded.state, RuntimeState::run);
    EXPECT_EQ(decoded.fault, FaultCode::can_filters_refused);
  }
  EXPECT_EQ(statuses, 50 / kStatusEveryCycles);
}

}  // namespace
}  // namespace cdcr::firmware
