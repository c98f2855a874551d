// The circles on which a pdf may jump or kink (Boundary: boundary planes' great circles and boundary caps' edges),
// in a cap's frame, and where they meet the quadratures' radial lines and rings (internal to the battery).
#pragma once

#include <vector>

#include "warpcheck/validation/battery.h"

namespace warpcheck::validation::battery {

// {w : m.w = c} in the cap's frame, m a unit vector: a great circle (c = 0) or a cap's edge (m its axis,
// c = 1 - omc).
struct Circle {
  Vec3L m;
  Real c;
};

std::vector<Circle> local_circles(const Boundary& b, const Frame<Real>& fr);

// Polar angles theta in (0, pi) where the half great circle at azimuth (cos, sin) = (c, s) meets each circle.
void line_crossing_angles(const std::vector<Circle>& circles, Real c, Real s, std::vector<Real>& theta);

// Azimuths in (0, 2 pi) where the ring of polar angle theta = (cos_t, sin_t) meets each circle.
void ring_crossing_azimuths(const std::vector<Circle>& circles, Real cos_t, Real sin_t, std::vector<Real>& phi);

// The points (unit vectors) where two circles meet.
std::vector<Vec3L> circle_intersections(const Circle& a, const Circle& b);

// Polar angles where a circle touches a ring (its extreme polar angles): a ring's integral kinks there.
std::vector<Real> polar_tangencies(const std::vector<Circle>& circles);

// Azimuths where a small circle touches a radial line (when it holds neither pole): a line's integral kinks there.
std::vector<Real> azimuth_tangencies(const std::vector<Circle>& circles);

}  // namespace warpcheck::validation::battery
