#pragma once
// Angle units. The library computes in radians; degrees appear only where a
// figure is reported (the paper's tables give orientation errors in degrees)
// or a default is easier to read in them.

namespace cdcr::model {

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kDegreesPerRadian = 180.0 / kPi;
inline constexpr double kRadiansPerDegree = kPi / 180.0;

}  // namespace cdcr::model
