#pragma once
// A controller's acceptance filters, for the backends that filter in
// software (the simulated bus, the QEMU boards' mailbox): set_filters()
// semantics of hal::CanBus, in fixed storage.

#include <array>
#include <cstddef>
#include <cstdint>

#include "cdcr/hal/can_bus.hpp"

namespace cdcr::hal {

template <std::size_t MaxFilters = kMaxCanFilters>
class CanFilterBank {
 public:
  // Replaces the filters; false, and the old ones kept, if there are more
  // than MaxFilters.
  bool assign(const CanFilter* filters, std::size_t count) {
    if (count > MaxFilters) return false;
    for (std::size_t i = 0; i < count; ++i) filters_[i] = filters[i];
    count_ = count;
    return true;
  }

  // With no filter set, every frame is accepted.
  bool accepts(std::uint32_t id) const {
    if (count_ == 0) return true;
    for (std::size_t i = 0; i < count_; ++i) {
      if ((id & filters_[i].mask) == (filters_[i].id & filters_[i].mask)) return true;
    }
    return false;
  }

 private:
  std::array<CanFilter, MaxFilters> filters_{};
  std::size_t count_ = 0;
};

}  // namespace cdcr::hal
