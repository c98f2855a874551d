// fuzz/targets/polygon_solid_angle.h: solid-angle sampling of polygons, Peters 2021 Section 5, whole polygon
// and clipped to the shading horizon (lib/warpcheck/polygon_solid_angle.h).
#pragma once

#include "common_polygon.h"
#include "warpcheck/polygon_solid_angle.h"

namespace warpcheck::fuzz {

template <class T> void check_polygon_solid_angle(FuzzedDataProvider& in) {
  PolygonLightGeometry<T> g;
  g.light = decode_polygon<T>(in);
  g.shading = decode_polygon_shading<T>(in, g.light);
  const bool clipped = in.ConsumeBool();
  const PolygonSolidAngleView<T> v = make_polygon_solid_angle_view(g, clipped);
  check_polygon_kernel<T>(
      in, g, clipped ? "polygon_solid_angle_clipped" : "polygon_solid_angle", clipped, PolygonDensity::kConstant,
      [&](const Vec2<T>& u) { return sample_polygon_solid_angle(v, u); },
      [&](const Vec3<T>& w) { return pdf_polygon_solid_angle(g, w, clipped); });
}

}  // namespace warpcheck::fuzz
