#include "sim/random_stream.hpp"

#include <cmath>

namespace cdcr::sim {
namespace {

// SplitMix64 finaliser: nearby seeds (1, 2, 3, ...) and stream ids become
// unrelated generator states.
std::uint64_t mix(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

constexpr double kTwoPi = 6.283185307179586476925;

}  // namespace

RandomStream::RandomStream(std::uint64_t seed, StreamId stream)
    : bits_(mix(mix(seed) ^ static_cast<std::uint64_t>(stream))) {}

double RandomStream::uniform() { return static_cast<double>(bits_() >> 11) * 0x1.0p-53; }

double RandomStream::normal() {
  if (has_spare_) {
    has_spare_ = false;
    return spare_normal_;
  }
  // 1 - uniform() lies in (0, 1], so the logarithm is finite.
  const double radius = std::sqrt(-2.0 * std::log(1.0 - uniform()));
  const double angle = kTwoPi * uniform();
  spare_normal_ = radius * std::sin(angle);
  has_spare_ = true;
  return radius * std::cos(angle);
}

}  // namespace cdcr::sim
