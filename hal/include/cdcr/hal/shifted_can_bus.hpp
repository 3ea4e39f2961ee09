#pragma once
// A CanBus that moves every identifier by a fixed offset, modulo the 11-bit
// space, so that a protocol written at fixed identifiers can sit anywhere on
// a shared bus (beside CANopen's, say). Its user sends and receives at the
// protocol's own identifiers; the bus beneath carries them shifted.
//
// The shift is a bijection of the 2,048 identifiers: a frame lands on one
// of the protocol's identifiers only if it was sent at that identifier
// shifted, so foreign traffic received unfiltered stays foreign. Acceptance
// filters move with it; a filter stays exact when its mask covers bits 3 to
// 10 and the offset is a multiple of 8 (the carry of the addition then
// stays within the bits the mask compares). Other filters are refused, as a
// controller refuses what it cannot hold.

#include <cstddef>
#include <cstdint>

#include "cdcr/hal/can_bus.hpp"

namespace cdcr::hal {

class ShiftedCanBus final : public CanBus {
 public:
  static constexpr std::uint32_t kIdentifiers = kMaxStandardId + 1;
  static constexpr std::uint32_t kFilterMaskBits = 0x7F8;  // what a shifted filter's mask must cover

  // `offset` is taken modulo 2,048; it must be a multiple of 8.
  ShiftedCanBus(CanBus& bus, std::uint32_t offset) : bus_(bus), offset_(offset % kIdentifiers) {}

  std::uint32_t offset() const { return offset_; }
  static constexpr bool valid_offset(std::uint32_t offset) { return offset % 8 == 0; }
  // An identifier as the bus beneath carries it, and back.
  static constexpr std::uint32_t shifted(std::uint32_t id, std::uint32_t offset) {
    return (id + offset % kIdentifiers) % kIdentifiers;
  }
  static constexpr std::uint32_t unshifted(std::uint32_t id, std::uint32_t offset) {
    return (id + kIdentifiers - offset % kIdentifiers) % kIdentifiers;
  }

  CanStatus send(const CanFrame& frame) override {
    if (offset_ == 0 || !is_valid(frame, bus_.fd_capable())) return bus_.send(frame);
    CanFrame shifted = frame;
    shifted.id = ShiftedCanBus::shifted(frame.id, offset_);
    return bus_.send(shifted);
  }

  CanStatus receive(CanFrame& frame) override {
    const CanStatus status = bus_.receive(frame);
    if (status == CanStatus::ok && offset_ != 0) frame.id = unshifted(frame.id, offset_);
    return status;
  }

  bool set_filters(const CanFilter* filters, std::size_t count) override {
    if (offset_ == 0) return bus_.set_filters(filters, count);
    if (count > kMaxCanFilters || !valid_offset(offset_)) return false;
    CanFilter shifted[kMaxCanFilters];
    for (std::size_t i = 0; i < count; ++i) {
      if ((filters[i].mask & kFilterMaskBits) != kFilterMaskBits) return false;
      shifted[i].id = ShiftedCanBus::shifted(filters[i].id, offset_);
      shifted[i].mask = filters[i].mask;
    }
    return bus_.set_filters(shifted, count);
  }

  CanErrorCounters error_counters() const override { return bus_.error_counters(); }
  bool fd_capable() const override { return bus_.fd_capable(); }

 private:
  CanBus& bus_;
  std::uint32_t offset_;
};

}  // namespace cdcr::hal
