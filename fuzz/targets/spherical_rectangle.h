// fuzz/targets/spherical_rectangle.h: the baseline Urena et al. 2013 (spherical rectangles), as published in
// lib/warpcheck/spherical_rectangle.h. Inputs lean to rectangles. Its findings are recorded (triage "known"), not
// fixed.
#pragma once

#include "common_polygon.h"
#include "warpcheck/spherical_rectangle.h"

namespace warpcheck::fuzz {

template <class T> void check_spherical_rectangle(FuzzedDataProvider& in) {
  PolygonLightGeometry<T> g;
  g.light = decode_polygon<T>(in, /*rectangle_bias=*/in.ConsumeIntegralInRange<int>(0, 7) != 0);
  g.shading = decode_polygon_shading<T>(in, g.light);
  const SphericalRectangleView<T> v = make_spherical_rectangle_view(g);
  check_polygon_kernel<T>(
      in, g, "spherical_rectangle", false, PolygonDensity::kConstant,
      [&](const Vec2<T>& u) { return sample_spherical_rectangle(v, u); },
      [&](const Vec3<T>& w) { return pdf_spherical_rectangle(g, w); });
}

}  // namespace warpcheck::fuzz
