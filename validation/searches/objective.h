// Values shared by the searches' objectives (searches.h): NaN marks a point outside a search's domain (the engine
// passes over it), +inf an error without bound; angles in the parameter boxes are in degrees.
#pragma once

#include <limits>
#include <numbers>

namespace warpcheck::validation {

using L = long double;
inline constexpr L kNaN = std::numeric_limits<L>::quiet_NaN();
inline constexpr L kInf = std::numeric_limits<L>::infinity();
inline constexpr L kDeg = std::numbers::pi_v<L> / 180;

}  // namespace warpcheck::validation
