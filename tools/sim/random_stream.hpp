#pragma once
// A reproducible random stream. std::mt19937_64's output sequence is fixed by
// the C++ standard, but the standard distributions are not: libstdc++ and
// libc++ turn the same bits into different normals. The conversions here are
// spelled out, so a seed names the same robot and the same data on every
// platform.

#include <cstdint>
#include <random>

namespace cdcr::sim {

// Independent streams derived from one user seed: the physical robot, the
// workspace sampler, the per-sample noise and the per-sample payload never
// share draws, so switching one source off leaves the others' values
// untouched.
enum class StreamId : std::uint64_t {
  robot = 1,
  workspace = 2,
  noise = 3,
  payload = 4,
  hysteresis = 5,        // the friction of every cable: a property of the robot (seed)
  hysteresis_state = 6,  // the friction state at power-up (session seed)
};

class RandomStream {
 public:
  RandomStream(std::uint64_t seed, StreamId stream);

  // Uniform in [0, 1), 53 random bits.
  double uniform();
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  // Standard normal (Box-Muller, both values used).
  double normal();
  double normal(double sigma) { return sigma * normal(); }

 private:
  std::mt19937_64 bits_;
  double spare_normal_ = 0.0;
  bool has_spare_ = false;
};

}  // namespace cdcr::sim
