// The identifier shift (hal/shifted_can_bus.hpp): modulo 2,048 both ways,
// filters moved where they stay exact and refused where they would not.
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include <cdcr/hal/shifted_can_bus.hpp>

namespace cdcr::hal {
namespace {

class Wire final : public CanBus {
 public:
  CanStatus send(const CanFrame& frame) override {
    sent.push_back(frame);
    return CanStatus::ok;
  }
  CanStatus receive(CanFrame& frame) override {
    if (incoming.empty()) return CanStatus::empty;
    frame = incoming.back();
    incoming.pop_back();
    return CanStatus::ok;
  }
  bool set_filters(const CanFilter* f, std::size_t count) override {
    filters.assign(f, f + count);
    return true;
  }
  CanErrorCounters error_counters() const override { return {}; }
  std::vector<CanFrame> sent, incoming;
  std::vector<CanFilter> filters;
};

CanFrame with_id(std::uint32_t id) {
  CanFrame f;
  f.id = id;
  return f;
}

TEST(ShiftedCanBus, ShiftsModulo2048BothWays) {
  Wire wire;
  ShiftedCanBus bus(wire, 0x700);  // a base of 0x000: -0x100
  ASSERT_EQ(bus.send(with_id(0x100)), CanStatus::ok);
  ASSERT_EQ(bus.send(with_id(0x17F)), CanStatus::ok);
  EXPECT_EQ(wire.sent[0].id, 0x000u);
  EXPECT_EQ(wire.sent[1].id, 0x07Fu);
  // Every identifier comes back to a distinct one: a bijection.
  std::vector<bool> seen(2048, false);
  for (std::uint32_t id = 0; id < 2048; ++id) {
    wire.incoming.push_back(with_id(id));
    CanFrame out;
    ASSERT_EQ(bus.receive(out), CanStatus::ok);
    ASSERT_LT(out.id, 2048u);
    ASSERT_FALSE(seen[out.id]) << id;
    seen[out.id] = true;
    ASSERT_EQ((out.id + 0x700) % 2048, id);
  }
  // An invalid frame reaches the bus as it is, to be refused there.
  ASSERT_EQ(bus.send(with_id(0x800)), CanStatus::ok);
  EXPECT_EQ(wire.sent.back().id, 0x800u);
}

TEST(ShiftedCanBus, MovesFiltersThatStayExactAndRefusesOthers) {
  Wire wire;
  ShiftedCanBus bus(wire, 0x200);
  const CanFilter exact[] = {{0x100, 0x7F8}, {0x150, 0x7FE}, {0x140, 0x7FF}};
  ASSERT_TRUE(bus.set_filters(exact, 3));
  EXPECT_EQ(wire.filters[0].id, 0x300u);
  EXPECT_EQ(wire.filters[1].id, 0x350u);
  EXPECT_EQ(wire.filters[2].mask, 0x7FFu);
  const CanFilter coarse[] = {{0x100, 0x700}};  // a carry out of bit 7 would move what it compares
  EXPECT_FALSE(bus.set_filters(coarse, 1));
  ShiftedCanBus unaligned(wire, 0x204);
  EXPECT_FALSE(unaligned.set_filters(exact, 1));
  // No shift: everything passes through untouched, any filter.
  ShiftedCanBus none(wire, 0);
  EXPECT_TRUE(none.set_filters(coarse, 1));
  EXPECT_EQ(wire.filters[0].mask, 0x700u);
}

}  // namespace
}  // namespace cdcr::hal
