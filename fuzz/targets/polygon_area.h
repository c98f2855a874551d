// fuzz/targets/polygon_area.h: the baseline Turk 1992 (uniform area sampling, density per solid angle), as
// published in lib/warpcheck/polygon_solid_angle.h. Its findings are recorded (triage "known"), not fixed.
#pragma once

#include "common_polygon.h"
#include "warpcheck/polygon_solid_angle.h"

namespace warpcheck::fuzz {

template <class T> void check_polygon_area(FuzzedDataProvider& in) {
  PolygonLightGeometry<T> g;
  g.light = decode_polygon<T>(in);
  g.shading = decode_polygon_shading<T>(in, g.light);
  const TurkAreaView<T> v = make_turk_area_view(g);
  check_polygon_kernel<T>(
      in, g, "polygon_area", false, PolygonDensity::kArea, [&](const Vec2<T>& u) { return sample_turk_area(v, u); },
      [&](const Vec3<T>& w) { return pdf_turk_area(g, w); });
}

}  // namespace warpcheck::fuzz
