// warpcheck/ltc.h: sampling a polygon light proportionally to a linearly transformed cosine (LTC),
// Peters 2021 Section 4.1 (LTCs from Heitz, Dupuy, Hill & Neubelt 2016).
//
// For M with |M| > 0, in the shading frame: p_M(w) = (1/pi) max(0, (M^-1 w)_z / |M^-1 w|) |M^-1| / |M^-1 w|^3.
// Sampling (Sec. 4.1): sample M^-1 P by projected solid angle (polygon_projected.h), map back by M and normalise;
// by Eq. 10, int_P p_M = A_Sigma(M^-1 P) / pi, so pdf(w) = pdf_projected(M^-1 w / |M^-1 w|) |M^-1| / |M^-1 w|^3.
// As in the paper, only the transformed horizon clips: samples may lie below the shading horizon.
#pragma once

#include <Eigen/LU>

#include "warpcheck/polygon_projected.h"

namespace warpcheck {

template <class T> using Mat3 = Eigen::Matrix<T, 3, 3>;

template <class T> struct LtcPolygonGeometry {
  PolygonLightGeometry<T> polygon;
  Mat3<T> m = Mat3<T>::Identity();  // the LTC's transform, in the shading frame

  template <class U> LtcPolygonGeometry<U> cast() const { return {polygon.template cast<U>(), m.template cast<U>()}; }
};

// M^-1 and |M| > 0 by LU with full pivoting (false for a singular, reflecting or overflowing M): X = (M + dM)^-1 with
// |dM| ~ eps |M|, both residuals ~eps cond(M), unlike the cofactor inverse. The pivots' product is tested first.
template <class T> bool ltc_inverse(const Mat3<T>& m, Mat3<T>* m_inv, T* det) {
  if (!m.allFinite()) return false;
  const Eigen::FullPivLU<Mat3<T>> lu(m);
  *det = lu.determinant();
  if (!(*det > T(0)) || !std::isfinite(*det) || !has_finite_reciprocal(*det)) return false;
  *m_inv = lu.inverse();
  return m_inv->allFinite();
}

// The LTC density p_M at a unit direction given in the shading frame (m_inv = M^-1, det_inv = |M^-1|).
template <class T> T ltc_density_local(const Mat3<T>& m_inv, T det_inv, const Vec3<T>& l) {
  const Vec3<T> o = m_inv * l;
  const T len2 = o.squaredNorm();
  if (!(o.z() > T(0)) || !(len2 > T(0))) return T(0);
  return o.z() * det_inv / (kPi<T> * len2 * len2);  // (o_z / |o|) / |o|^3
}

template <class T> struct LtcPolygonView {
  NoSample reason = NoSample::kNone;
  Frame<T> frame = Frame<T>::from_z(Vec3<T>(T(0), T(0), T(1)));  // the shading frame
  Mat3<T> m = Mat3<T>::Identity(), m_inv = Mat3<T>::Identity();  // M as ltc_unit_scale scales it, and its inverse
  T det = T(1), det_inv = T(1);
  PolygonProjectedView<T> transformed;  // M^-1 P, seen from the origin with normal z, clipped to z >= 0
  // pdf()'s test "w in P", by P's own planes in world space (polygon_inward_planes): equivalent to M^-1 w in the
  // cone of M^-1 P, but from exact world edges V_{j+1} - V_j instead of rounded transformed vertices.
  std::array<Vec3<T>, kMaxPolygonVertices> inward{};
  int planes = 0;
  T integral = 0;  // int_P p_M = A_Sigma(M^-1 P) / pi (Eq. 10)

  bool valid() const { return reason == NoSample::kNone; }
  // p_M at a world direction (not normalised over P).
  T ltc_density(const Vec3<T>& w) const {
    const T len = w.norm();
    return len > T(0) ? ltc_density_local(m_inv, det_inv, Vec3<T>(frame.to_local(w) / len)) : T(0);
  }
};

// The transformed polygon as a polygon light seen from the origin with normal z.
template <class T> PolygonLightGeometry<T> ltc_transformed_polygon(const PolygonView<T>& pv, const Mat3<T>& m_inv) {
  PolygonLightGeometry<T> tg;
  tg.shading.position = Vec3<T>::Zero();
  tg.shading.normal = Vec3<T>(T(0), T(0), T(1));
  tg.light.count = pv.local.count;
  for (int i = 0; i < pv.local.count; ++i) tg.light.vertices[i] = m_inv * pv.local.v[i];
  return tg;
}

// M^-1 P scaled exactly (by a power of two) so that its largest coordinate lies in [1, 2). Eq. 10 integrates over
// M^-1 P as a cone of directions seen from the origin, which no positive scale changes, but its coordinates are P's
// (in the shading frame) times M^-1: a light far away or very close, or an ill-conditioned M, puts them where
// check_polygon's squared area (a product of four coordinates) under- or overflows and the light is refused.
template <class T> PolygonLightGeometry<T> ltc_unit_magnitude(PolygonLightGeometry<T> tg) {
  T magnitude = 0;
  for (int i = 0; i < tg.light.count; ++i) magnitude = std::max(magnitude, max_abs(tg.light.vertices[i]));
  if (!(magnitude > T(0)) || !std::isfinite(magnitude)) return tg;
  const int e = std::ilogb(magnitude);
  for (int i = 0; i < tg.light.count; ++i) tg.light.vertices[i] = ldexp(tg.light.vertices[i], -e);
  return tg;
}

// M scaled exactly (by a power of two) so that its largest entry lies in [1, 2). p_M does not change under M -> s M
// (s > 0), and neither do the samples and pdfs, but |M c|^3 and |M^-1| of an M of scale 1e12 in float (1e102 in
// double, or a smaller anisotropic one) over- or underflow where their product does not. The scaling is exact
// unless an entry falls below T's normal range relative to the largest; where M's own arithmetic stays in range,
// the samples and pdfs are bit for bit those of M unscaled.
template <class T> Mat3<T> ltc_unit_scale(const Mat3<T>& m) {
  const T magnitude = m.cwiseAbs().maxCoeff();
  if (!(magnitude > T(0)) || !std::isfinite(magnitude)) return m;
  const int e = std::ilogb(magnitude);
  return m.unaryExpr([e](T x) { return scale_by_power_of_two(x, -e); });
}

// The rounding of M^-1 P's vertices relative to |M^-1 v|_inf (check_polygon's vertex_rounding): the frame change's
// and the product's, 3 eps |M^-1|_F |v|_2 <= 3 sqrt(3) eps cond_F(M) |M^-1 v|_inf.
template <class T> T ltc_vertex_rounding(const Mat3<T>& m, const Mat3<T>& m_inv) {
  const T eps = std::numeric_limits<T>::epsilon();
  return kPolygonVertexRounding<T> + T(3) * std::sqrt(T(3)) * eps * (m.norm() * m_inv.norm());
}

template <class T> NoSample fill_ltc_polygon_view(const LtcPolygonGeometry<T>& g, LtcPolygonView<T>& v) {
  const PolygonView<T> pv = make_polygon_view(g.polygon);
  if (!pv.valid()) return pv.reason;
  if (!g.m.allFinite()) return NoSample::kNonFinite;
  v.frame = pv.frame;
  v.planes = polygon_inward_planes(g.polygon, pv, v.inward.data());
  v.m = ltc_unit_scale(g.m);
  // |M| > 0 (Sec. 4.1). A singular or reflecting M has no LTC; an M whose inverse overflows neither.
  if (!ltc_inverse(v.m, &v.m_inv, &v.det)) return NoSample::kInvalidGeometry;
  v.det_inv = T(1) / v.det;
  v.transformed.reason = fill_polygon_projected_view<T, false>(  // in place, not copied
      ltc_unit_magnitude(ltc_transformed_polygon(pv, v.m_inv)), ltc_vertex_rounding(v.m, v.m_inv), v.transformed);
  if (!v.transformed.valid()) return v.transformed.reason;
  v.integral = v.transformed.projected_solid_angle / kPi<T>;
  return NoSample::kNone;
}

template <class T> LtcPolygonView<T> make_ltc_polygon_view(const LtcPolygonGeometry<T>& g) {
  LtcPolygonView<T> v;  // filled in place: no copy of the view on return
  v.reason = fill_ltc_polygon_view(g, v);
  return v;
}

// pdf(w) = pdf_projected(c) |M c|^3 / |M| at c = M^-1 w / |M^-1 w|. |M c| from M, not 1 / |M^-1 w|: the computed
// inverse's error (eps cond(M)) would stretch w and enter cubed, whereas c's direction is off harmlessly.
template <class T> T pdf_ltc_polygon(const LtcPolygonView<T>& v, const Vec3<T>& w) {
  if (!v.valid() || !all_finite(w)) return T(0);
  const T len = w.norm();
  if (!(len > T(0))) return T(0);
  for (int j = 0; j < v.planes; ++j)
    if (v.inward[j].dot(w) < T(0)) return T(0);
  const Vec3<T> o = v.m_inv * Vec3<T>(v.frame.to_local(w) / len);
  const T olen = o.norm();
  if (!(olen > T(0)) || !(o.z() > T(0))) return T(0);  // (M^-1 w)_z > 0: the LTC's support, z >= 0 of M^-1 P
  const Vec3<T> c = o / olen;
  const T mlen = (v.m * c).norm();
  const T pc = c.z() / v.transformed.projected_solid_angle;
  const T p = pc * (mlen * mlen * mlen) * v.det_inv;
  return p > T(0) && std::isfinite(p) ? p : T(0);
}

// Tangent-line iterations of the decentral sector inversion (Peters 2021 Sec. 3.3; the paper's default is 2).
// M^-1 P is often thin and strongly decentral, where 2 iterations leave the warp's density measurably off its pdf
// (docs/measurements.md): 4.
inline constexpr int kLtcSectorIterations = 4;

template <class T> DirectionSample<T> sample_ltc_polygon(const LtcPolygonView<T>& v, const Vec2<T>& u,
                                                         int iterations = kLtcSectorIterations) {
  if (!v.valid()) return DirectionSample<T>::none(v.reason);
  const DirectionSample<T> c = sample_polygon_projected_solid_angle(v.transformed, u, iterations);
  if (!c.valid()) return c;
  // w = M w_c / |M w_c|; the Jacobian dw_c/dw = |M^-1| / |M^-1 w|^3 = |M w_c|^3 / |M| for unit w_c.
  const Vec3<T> mw = v.m * c.direction;
  const T mlen = mw.norm();
  if (!(mlen > T(0)) || !std::isfinite(mlen)) return DirectionSample<T>::none(NoSample::kTooSmall);
  DirectionSample<T> s;
  s.direction = v.frame.to_world(Vec3<T>(mw / mlen));
  s.direction /= s.direction.norm();
  s.pdf = c.pdf * (mlen * mlen * mlen) * v.det_inv;
  if (!(s.pdf > T(0)) || !std::isfinite(s.pdf)) return DirectionSample<T>::none(NoSample::kTooSmall);
  return s;
}

template <class T> DirectionSample<T> sample_ltc_polygon(const LtcPolygonGeometry<T>& g, const Vec2<T>& u) {
  return sample_ltc_polygon(make_ltc_polygon_view(g), u);
}
template <class T> T pdf_ltc_polygon(const LtcPolygonGeometry<T>& g, const Vec3<T>& w) {
  return pdf_ltc_polygon(make_ltc_polygon_view(g), w);
}

// ---- Catalogue trait (warpcheck/catalogue.h) -----------------------------------------------------------------

template <class T> struct PolygonLtc {
  static constexpr const char* name = "polygon-ltc";
  static constexpr const char* description = "LTC over a polygon, Heitz et al. 2016 with Peters 2021 Sec. 4.1";
  using Scalar = T;
  using Geometry = LtcPolygonGeometry<T>;
  using View = LtcPolygonView<T>;
  static View view(const Geometry& g) { return make_ltc_polygon_view(g); }
  static DirectionSample<T> sample(const View& v, const Vec2<T>& u) { return sample_ltc_polygon(v, u); }
  static T pdf(const View& v, const Vec3<T>& w) { return pdf_ltc_polygon(v, w); }
  // The support is P clipped by the transformed horizon: M times the clipped transformed vertices.
  static Cap<T> bounding_cap(const Geometry& g) {
    const View v = view(g);
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
  static T normaliser(const View& v) { return v.transformed.projected_solid_angle; }  // of M^-1 P (Eq. 10)
  // P's edges and the image of the horizon under M (a plane through the origin maps to one, normal M^-T z).
  static std::vector<Vec3<T>> boundary_planes(const Geometry& g) {
    std::vector<Vec3<T>> planes = polygon_edge_planes(g.polygon);
    const View v = view(g);
    const Vec3<T> horizon = v.frame.to_world(Vec3<T>(v.m_inv.transpose() * Vec3<T>(T(0), T(0), T(1))));
    if (horizon.norm() > T(0)) planes.push_back(horizon.normalized());
    return planes;
  }
  // The sectors of M^-1 P picked by u0 (polygon_projected.h): M is smooth, so the LTC warp has their kinks.
  static std::vector<T> kinks_u0(const Geometry& g) {
    const View v = view(g);
    std::vector<T> kinks;
    if (!v.valid()) return kinks;
    T cumulative = 0;
    for (int i = 0; i + 1 < v.transformed.sector_count; ++i) {
      cumulative += v.transformed.sectors[i].area;
      kinks.push_back(cumulative / v.transformed.projected_solid_angle);
    }
    return kinks;
  }
};

}  // namespace warpcheck
