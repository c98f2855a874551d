// fuzz/targets/polygon_arvo.h: the baseline Arvo 1995 (spherical triangles, as a fan), implemented as
// published in lib/warpcheck/polygon_solid_angle.h. Its findings are recorded (triage "known"), not fixed.
#pragma once

#include "common_polygon.h"
#include "warpcheck/polygon_solid_angle.h"

namespace warpcheck::fuzz {

template <class T> void check_polygon_arvo(FuzzedDataProvider& in) {
  PolygonLightGeometry<T> g;
  g.light = decode_polygon<T>(in);
  g.shading = decode_polygon_shading<T>(in, g.light);
  const ArvoFanView<T> v = make_arvo_fan_view(g);
  check_polygon_kernel<T>(
      in, g, "polygon_arvo", false, PolygonDensity::kConstant,
      [&](const Vec2<T>& u) { return sample_arvo_triangle_fan(v, u); },
      [&](const Vec3<T>& w) { return pdf_arvo_triangle_fan(g, w); });
}

}  // namespace warpcheck::fuzz
