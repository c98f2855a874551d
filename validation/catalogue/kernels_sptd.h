// warpcheck/validation/kernels_sptd.h: Kernel-concept adapters for the SPTD and LTC samplers, shared by the
// registrar (validation/src/registry_sptd.cpp) and the tests (validation/tests/test_sptd.cpp, test_ltc.cpp).
#pragma once

#include <functional>

#include "warpcheck/ltc.h"
#include "warpcheck/sptd.h"
#include "warpcheck/validation/sampler.h"

namespace warpcheck::validation {

// An SPTD restricted to a cap (Dupuy et al. 2017 Sec. 4.2); the whole sphere when the cap's 1 - cos is 2.
template <class T> struct SptdCapKernel {
  using Scalar = T;
  using Geometry = SptdCapGeometry<T>;
  static DirectionSample<T> sample(const Geometry& g, const Vec2<T>& u) { return sample_sptd_cap(g, u); }
  static T pdf(const Geometry& g, const Vec3<T>& w) { return pdf_sptd_cap(g, w); }
  // The support lies in C.
  static Cap<T> bounding_cap(const Geometry& g) {
    Cap<T> c = g.cap;
    if (!normalize_normal(g.cap.axis, c.axis)) c.axis = Vec3<T>(T(0), T(0), T(1));
    return c;
  }
  // The density with the view built once (the battery's quadrature calls it millions of times).
  static std::function<Real(const Vec3L&)> cached_pdf(const Geometry& g) {
    return [v = make_sptd_cap_view(g)](const Vec3L& w) { return Real(pdf_sptd_cap(v, Vec3<T>(w.template cast<T>()))); };
  }
};

// A SamplerUnderTest for an SPTD over a cap in scalar T, with the long double kernel as the reference warp.
// Normalisation check: the kernel's integral of D over C (Eq. 10, through g(C)) against `reference`, an
// independently computed value the caller supplies (quadrature of Eq. 8 over C); skipped when reference <= 0.
template <class T> SamplerUnderTest bind_sptd_cap(const std::string& kernel, const std::string& config,
                                                  const SptdCapGeometry<Real>& g, Real reference_integral = 0) {
  SamplerUnderTest s = bind_kernel<SptdCapKernel<T>, SptdCapKernel<Real>>(kernel, config, g.template cast<T>(), g);
  s.pdf = SptdCapKernel<T>::cached_pdf(g.template cast<T>());
  if (g.sptd.base == SptdBase::kClampedCosine) {
    // The cosine-cap warp near the horizon (sptd.h): x(u0) inverts an area-CDF whose chord length has square-root
    // corners where x passes the ends of the ellipse E and the horizon abscissa x0; y jumps across E at
    // u1 = 1/2 in the crescent case. The Jacobian check must not difference across those.
    const SptdCapView<Real> v = make_sptd_cap_view(g);
    if (v.valid() && !v.cosine.ellipse_only) {
      const auto& c = v.cosine;
      for (Real x : {c.xc - c.A, c.xc + c.A, c.x0})
        if (x > -1 && x < 1) s.kinks_u0.push_back(c.cdf(x) / c.area);
      s.kinks_u1 = {0.5L};
    }
  }
  if (reference_integral > 0) {
    Normalization n;
    n.what = "integral of D over C (Eq. 10 vs quadrature of Eq. 8)";
    n.kernel = [gt = g.template cast<T>()] { return Real(make_sptd_cap_view(gt).base_integral); };
    n.reference = reference_integral;
    s.normalizations.push_back(n);
  }
  return s;
}

// LTC sampling of a polygon (Peters 2021 Sec. 4.1); M is given in the shading frame Frame<T>::from_z(normal).
template <class T> struct LtcKernel {
  using Scalar = T;
  using Geometry = LtcPolygonGeometry<T>;
  static DirectionSample<T> sample(const Geometry& g, const Vec2<T>& u) { return sample_ltc_polygon(g, u); }
  static T pdf(const Geometry& g, const Vec3<T>& w) { return pdf_ltc_polygon(g, w); }
  // The support is P clipped by the transformed horizon: M times the clipped transformed vertices.
  static Cap<T> bounding_cap(const Geometry& g) {
    const LtcPolygonView<T> v = make_ltc_polygon_view(g);
    std::array<Vec3<T>, kMaxClippedVertices> w;
    int n = 0;
    if (v.valid()) {
      for (int i = 0; i < v.transformed.clipped.count; ++i)
        w[n++] = v.frame.to_world(Vec3<T>(v.m * v.transformed.to_world(v.transformed.clipped.v[i])));
    } else {
      for (int i = 0; i < g.polygon.light.count && i < kMaxPolygonVertices; ++i)
        w[n++] = g.polygon.light.vertices[i] - g.polygon.shading.position;
    }
    return bounding_cap_of_directions(w.data(), n);
  }
  static std::function<Real(const Vec3L&)> cached_pdf(const Geometry& g) {
    return [v = make_ltc_polygon_view(g)](const Vec3L& w) {
      return Real(pdf_ltc_polygon(v, Vec3<T>(w.template cast<T>())));
    };
  }
};

// The normalisation of Eq. 10 computed independently: Lambert's formula (polygon.h's long double reference)
// on M^-1 P, with M^-1 from Eigen in long double and the shading frame's coordinates.
inline Real ltc_reference_projected_solid_angle(const LtcPolygonGeometry<Real>& g) {
  const Vec3L n = g.polygon.shading.normal.normalized();
  const Frame<Real> f = Frame<Real>::from_z(n);
  const Eigen::Matrix<Real, 3, 3> mi = g.m.inverse();
  PolygonLightGeometry<Real> t;
  t.shading.position = Vec3L::Zero();
  t.shading.normal = Vec3L(0, 0, 1);
  t.light.count = g.polygon.light.count;
  for (int i = 0; i < g.polygon.light.count; ++i)
    t.light.vertices[i] = mi * f.to_local(Vec3L(g.polygon.light.vertices[i] - g.polygon.shading.position));
  return reference_projected_solid_angle(t);
}

template <class T>
SamplerUnderTest bind_ltc(const std::string& kernel, const std::string& config, const LtcPolygonGeometry<Real>& g) {
  SamplerUnderTest s = bind_kernel<LtcKernel<T>, LtcKernel<Real>>(kernel, config, g.template cast<T>(), g);
  s.pdf = LtcKernel<T>::cached_pdf(g.template cast<T>());
  s.expect_no_sample = !LtcKernel<Real>::sample(g, Vec2<Real>(0.5L, 0.5L)).valid();
  if (s.expect_no_sample) return s;
  // The projected-solid-angle warp picks a sector of M^-1 P by xi_0 (polygon_projected.h, Peters 2021 Sec. 3.2),
  // so the warp's derivative jumps where xi_0 crosses a sector's cumulative area fraction; M is smooth, so the
  // LTC warp has the same kinks. (Measured on the test's random M: a stencil of h = 1e-4 straddling one errs by
  // 1e-5 relative, h = 1e-5 beside it by 1e-16.)
  const LtcPolygonView<Real> v = make_ltc_polygon_view(g);
  Real cumulative = 0;
  for (int i = 0; i + 1 < v.transformed.sector_count; ++i) {
    cumulative += v.transformed.sectors[i].area;
    s.kinks_u0.push_back(cumulative / v.transformed.projected_solid_angle);
  }
  Normalization n;
  n.what = "projected solid angle of M^-1 P (Eq. 10; Lambert)";
  n.kernel = [gt = g.template cast<T>()] { return Real(make_ltc_polygon_view(gt).transformed.projected_solid_angle); };
  n.reference = ltc_reference_projected_solid_angle(g);
  s.normalizations.push_back(n);
  return s;
}

}  // namespace warpcheck::validation
