// fuzz/targets/common_polygon.h: the invariant checks shared by the polygon families (not a family itself:
// files named common*.h are helpers). A polygon family decodes a geometry with decode_polygon /
// decode_polygon_shading and calls check_polygon_kernel with its sampler and density.
#pragma once

#include "common.h"

namespace warpcheck::fuzz {

enum class PolygonDensity {
  kConstant,  // 1 / Omega: the sample's pdf and pdf(direction) are the same number
  kCosine,    // cos(theta) / A_Sigma: both from the same cosine; relative rounding 8 eps / cos(theta)
  kArea,      // h^2 / (|N.w|^3 Area): both from the same formula; relative rounding 8 eps * 3 / |N.w|
};

template <class T> std::string describe(const PolygonLightGeometry<T>& g, const Vec2<T>& u, const char* kernel) {
  std::ostringstream os;
  os.precision(std::numeric_limits<T>::max_digits10);
  os << kernel << " <" << (sizeof(T) == 4 ? "float" : "double") << ">: " << g.light.count << " vertices";
  for (int i = 0; i < std::min(g.light.count, kMaxPolygonVertices); ++i) os << " " << show(g.light.vertices[i]);
  os << " x " << show(g.shading.position) << " n " << show(g.shading.normal) << " u (" << u[0] << ", " << u[1] << ")\n";
  return os.str();
}

template <class T> bool polygon_input_finite(const PolygonLightGeometry<T>& g) {
  for (int i = 0; i < std::min(g.light.count, kMaxPolygonVertices); ++i)
    if (!all_finite(g.light.vertices[i])) return false;
  return all_finite(g.shading.position) && all_finite(g.shading.normal);
}

// The conditioning kappa of the header comment; for kernels clipped to the horizon also the clip points'
// (|p| + |q| + |V_j|_inf + |V_{j+1}|_inf + |x|_inf) / dist(x, line of the edge) for every edge that crosses
// the horizon: the clip point lies on that line, so its direction is known to eps_T times that ratio.
template <class T> L polygon_kappa(const PolygonLightGeometry<T>& g, bool clipped) {
  const int n = g.light.count;
  L k = kappa_of<T>(g.light.vertices.data(), n, g.shading.position);
  if (!clipped) return k;
  const Vec3<L> x = g.shading.position.template cast<L>(), nl = g.shading.normal.template cast<L>();
  for (int j = 0; j < n; ++j) {
    const Vec3<L> vj = g.light.vertices[j].template cast<L>(), vj1 = g.light.vertices[(j + 1) % n].template cast<L>();
    const Vec3<L> p = vj - x, q = vj1 - x, e = vj1 - vj;
    if (!(nl.dot(p) * nl.dot(q) < 0)) continue;
    const L line_dist = kahan_cross<L>(p, e).norm() / e.norm();
    const L mag = p.norm() + q.norm() + vj.cwiseAbs().maxCoeff() + vj1.cwiseAbs().maxCoeff() + x.cwiseAbs().maxCoeff();
    k = std::max(k, line_dist > 0 ? mag / line_dist : std::numeric_limits<L>::infinity());
  }
  return k;
}

// Signed angular margin of w inside the light (clipped: also above the shading horizon).
template <class T> L polygon_margin(const PolygonLightGeometry<T>& g, const Vec3<T>& w, bool clipped) {
  L m = polygon_cone_margin(g.light, g.shading.position, w);
  if (clipped) m = std::min(m, g.shading.normal.template cast<L>().normalized().dot(w.template cast<L>().normalized()));
  return m;
}

template <class T, class Sample, class Pdf>
void check_polygon_kernel(FuzzedDataProvider& in, const PolygonLightGeometry<T>& g, const char* name, bool clipped,
                          PolygonDensity density, Sample&& sample, Pdf&& pdf) {
  const bool finite_input = polygon_input_finite(g);
  const bool valid_polygon = check_polygon(g.light) == NoSample::kNone;
  const L tol = finite_input && valid_polygon ? L(kTolUlps) * eps<T>() * polygon_kappa(g, clipped) : L(0);
  const int samples = in.ConsumeIntegralInRange<int>(1, 3);
  for (int k = 0; k < samples; ++k) {
    const Vec2<T> u = unit_square<T>(in);
    const DirectionSample<T> s = sample(u);
    const std::string geo = describe(g, u, name);
    check_sample_shape(s, geo);
    if (!finite_input) WARPCHECK_FUZZ_REQUIRE(!s.valid(), "a sample from non-finite input", geo);
    if (!s.valid()) continue;
    WARPCHECK_FUZZ_REQUIRE(valid_polygon, "a sample from a polygon that check_polygon rejects", geo);
    const L margin = polygon_margin(g, s.direction, clipped);
    WARPCHECK_FUZZ_REQUIRE(margin >= -tol, "direction outside the polygon",
                           geo << "direction " << show(s.direction) << " margin " << margin << " tol " << tol << "\n");
    L rel = 8 * eps<T>();
    if (density == PolygonDensity::kCosine || density == PolygonDensity::kArea) {
      // The cosine both densities are computed from (shading normal resp. light normal, in T).
      const Vec3<T> axis = density == PolygonDensity::kCosine ? Vec3<T>(g.shading.normal) : polygon_area_vector(g.light);
      const L c = std::abs(axis.template cast<L>().normalized().dot(s.direction.template cast<L>()));
      rel = c > 0 ? rel * (density == PolygonDensity::kArea ? 3 : 1) / c : L(1);
    }
    check_pdf_consistency<T>(s.pdf, pdf(s.direction), rel, margin, tol, geo);
  }
  // The density at an arbitrary unit direction: finite, >= 0, zero for invalid geometry and well outside.
  const Vec3<T> w = safe_normalized(in.ConsumeBool() ? vec3<T>(in)
                                                     : Vec3<T>(polygon_centroid(g.light) - g.shading.position + vec3<T>(in)));
  const T p = pdf(w);
  const std::string geo = describe(g, Vec2<T>(Vec2<T>::Zero()), name) + "pdf at w " + show(w) + "\n";
  WARPCHECK_FUZZ_REQUIRE(std::isfinite(p) && p >= T(0), "pdf not finite and >= 0", geo << "pdf " << p << "\n");
  if (!finite_input || !valid_polygon) {
    WARPCHECK_FUZZ_REQUIRE(p == T(0), "pdf > 0 for invalid geometry", geo << "pdf " << p << "\n");
  } else if (!w.isZero()) {
    const L margin = polygon_margin(g, w, clipped);
    if (margin < -tol)
      WARPCHECK_FUZZ_REQUIRE(p == T(0), "pdf > 0 outside the polygon",
                             geo << "pdf " << p << " margin " << margin << " tol " << tol << "\n");
  }
}

}  // namespace warpcheck::fuzz
