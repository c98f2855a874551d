// Fixtures shared by test_ltc_mis.cpp and slow_ltc.cpp: a decentral rectangle and LTC transforms.
#pragma once

#include <random>

#include "warpcheck/ltc.h"
#include "warpcheck/validation/sampler.h"

namespace warpcheck {
namespace {

using L = long double;
using validation::Real;
using validation::Vec3L;
using M3 = Mat3<L>;

// A 1.2 x 0.8 rectangle above and to the side of the origin, normal tilted: the decentral case.
PolygonLightGeometry<L> test_polygon() {
  PolygonLightGeometry<L> g;
  g.shading.position = Vec3L(0, 0, 0);
  g.shading.normal = Vec3L(0.1L, -0.2L, 1);
  g.light =
      PolygonLight<L>{Vec3L(0.2L, -0.6L, 1), Vec3L(1.4L, -0.6L, 1), Vec3L(1.4L, 0.2L, 1.2L), Vec3L(0.2L, 0.2L, 1.2L)};
  return g;
}

// Random transforms with |M| > 0: a typical LTC shape (anisotropic scale, shear towards x) plus noise.
M3 random_m(std::mt19937_64& g) {
  std::uniform_real_distribution<double> u(-1, 1);
  for (;;) {
    M3 m;
    m << 0.1L + 0.9L * std::abs(L(u(g))), 0.2L * L(u(g)), 0.8L * L(u(g)), 0.2L * L(u(g)),
        0.1L + 0.9L * std::abs(L(u(g))), 0.2L * L(u(g)), 0.5L * L(u(g)), 0.2L * L(u(g)), 1;
    if (m.determinant() > 0.01L) return m;
  }
}
// Ill-conditioned (condition number ~1e3, |M| ~1e-5): a very narrow specular lobe tilted towards the light.
M3 narrow_m() {
  M3 m;
  m << 0.004L, 0, 0.5L, 0, 0.003L, -0.1L, 0, 0, 1;
  return m;
}

}  // namespace
}  // namespace warpcheck
