#pragma once
// How often the runtime puts its own frames on the bus, in cycles: the ways
// a configuration fits its bus (protocol/bus_budget.hpp) while the estimate
// still runs every cycle. The defaults are the runtime's behaviour before
// there was a choice: a pose every cycle, a variance begun as soon as the
// previous one ended, STATUS and STATS every kStatusEveryCycles.

#include "cdcr/firmware/capacity.hpp"

namespace cdcr::firmware {

// The longest interval a rate may name: a second at 1 kHz.
inline constexpr int kMaxPublishEvery = 1000;

struct PublishRates {
  // POSE_POSITION_XY, POSE_POSITION_Z and POSE_ORIENTATION at most every
  // this many cycles (a pose needs a complete cable set in its cycle).
  int pose_every = 1;
  // A pose variance begins at most every this many cycles; its radii
  // (POSE_UNCERTAINTY) go out when it ends, a few cycles on.
  int uncertainty_every = 1;
  // STATUS and STATS, in the cycles that are a multiple of it.
  int status_every = kStatusEveryCycles;

  constexpr bool valid() const {
    return 1 <= pose_every && pose_every <= kMaxPublishEvery && 1 <= uncertainty_every &&
           uncertainty_every <= kMaxPublishEvery && 1 <= status_every && status_every <= kMaxPublishEvery;
  }
};

}  // namespace cdcr::firmware
