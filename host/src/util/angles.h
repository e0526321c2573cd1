// Degrees and radians. Options state angles in degrees; the code compares radians.
#pragma once

namespace tessera {

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kDegToRad = kPi / 180.0;
inline constexpr double kRadToDeg = 180.0 / kPi;

}  // namespace tessera
