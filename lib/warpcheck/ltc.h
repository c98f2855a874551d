// warpcheck/ltc.h: sampling a polygon light proportionally to a linearly transformed cosine (LTC),
// Peters 2021 Section 4.1 (LTCs from Heitz, Dupuy, Hill & Neubelt 2016).
//
// For M in R^{3x3} with |M| > 0, given in the shading frame (z = the shading normal), the LTC is
//   p_M(w) = (1/pi) max(0, (M^-1 w)_z / |M^-1 w|) |M^-1| / |M^-1 w|^3.
// Sampling (Sec. 4.1): transform the polygon's vertices by M^-1, clip to z >= 0, sample the transformed
// polygon by projected solid angle (polygon_projected.h, Peters 2021 Sec. 3), transform the direction back by
// M and normalise. The samples fall into the polygon P, distributed proportionally to p_M; the density is
// normalised by Eq. 10, int_P p_M = A_Sigma(M^-1 P) / pi, the projected solid angle the sampler computes anyway:
//   pdf(w) = p_M(w) pi / A_Sigma = pdf_projected(M^-1 w / |M^-1 w|) |M^-1| / |M^-1 w|^3.
// Like the paper's implementation we clip only against the horizon of the transformed space: samples may lie
// below the shading horizon (where a BRDF is zero; the caller's integrand handles that).
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

// M^-1 and |M| for |M| > 0, from Gaussian elimination with full pivoting (Eigen's FullPivLU): false for a singular
// or reflecting M and for one whose inverse or 1 / |M| overflows. Not the cofactor formula of Eigen's inverse() /
// computeInverseAndDetWithCheck for 3x3: it is not backward stable, and for an ill-conditioned M its inverse is
// a right inverse only (found by fuzz_ltc_double f84856d2: cond(M) 6e10, |M X - I| 1.6e-58 but |X M - I| 2.2, so
// the sample's pdf from M c and pdf(direction) from X w, 0.83 % apart; issue 7). LU with pivoting gives an X
// with X = (M + dM)^-1, |dM| ~ eps |M|, both residuals ~ eps cond(M) (1.8e-62 and 4e-62 there). The
// determinant is the pivots' product, tested before inverse() divides by the pivots: a zero pivot makes it 0.
// (An earlier cofactor determinant() was 1.4e-17 where inverse()'s own expansion was 0: a division by zero under
// UBSan, fuzz_ltc_double d6818c25; issue 7.)
template <class T> bool ltc_inverse(const Mat3<T>& m, Mat3<T>* m_inv, T* det) {
  if (!m.allFinite()) return false;
  const Eigen::FullPivLU<Mat3<T>> lu(m);
  *det = lu.determinant();
  if (!(*det > T(0)) || !std::isfinite(*det) || !std::isfinite(T(1) / *det)) return false;
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
  Mat3<T> m = Mat3<T>::Identity(), m_inv = Mat3<T>::Identity();
  T det = T(1), det_inv = T(1);
  PolygonProjectedView<T> transformed;  // M^-1 P, seen from the origin with normal z, clipped to z >= 0
  // pdf()'s test "w in P", in world space (polygon_inward_planes): M^-1 w is in the cone of M^-1 P iff w is in P's,
  // but the transformed cone's planes come from rounded vertices M^-1 (V - x), whose differences lose a short
  // edge's direction (found by fuzz_ltc_double, 834135fe: vertices 3e51 apart at 2e67 were both snapped onto the
  // horizon, the edge's plane became the horizon with an orientation of rounding noise, pdf 0 at samples 0.09
  // rad inside; issue 7). The world edges V_{j+1} - V_j are exact.
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

// The rounding of M^-1 P's computed vertices relative to |M^-1 v|_inf, the vertex_rounding of check_polygon and
// make_polygon_view for the transformed polygon. M^-1 P is convex, but its vertices carry the rounding of the frame
// change (a few eps |v|) and of the product: 3 eps |M^-1|_F |v|_2 <= 3 eps cond_F(M) |M^-1 v|_2 <= 3 sqrt(3) eps
// cond_F(M) |M^-1 v|_inf. check_polygon forgives reflex turns up to that rounding (and no further: polygon.h), and
// make_polygon_view flattens the polygon where that rounding leaves it non-planar.
template <class T> T ltc_vertex_rounding(const Mat3<T>& m, const Mat3<T>& m_inv) {
  const T eps = std::numeric_limits<T>::epsilon();
  return kPolygonVertexRounding<T> + T(3) * std::sqrt(T(3)) * eps * (m.norm() * m_inv.norm());
}

template <class T> LtcPolygonView<T> make_ltc_polygon_view(const LtcPolygonGeometry<T>& g) {
  LtcPolygonView<T> v;
  const PolygonView<T> pv = make_polygon_view(g.polygon);
  if (!pv.valid()) return v.reason = pv.reason, v;
  if (!g.m.allFinite()) return v.reason = NoSample::kNonFinite, v;
  v.frame = pv.frame;
  v.planes = polygon_inward_planes(g.polygon, pv, v.inward.data());
  v.m = g.m;
  // |M| > 0 (Sec. 4.1). A singular or reflecting M has no LTC; an M whose inverse overflows neither.
  if (!ltc_inverse(g.m, &v.m_inv, &v.det)) return v.reason = NoSample::kInvalidGeometry, v;
  v.det_inv = T(1) / v.det;
  v.transformed = make_polygon_projected_view(ltc_transformed_polygon(pv, v.m_inv), ltc_vertex_rounding(g.m, v.m_inv));
  if (!v.transformed.valid()) return v.reason = v.transformed.reason, v;
  v.integral = v.transformed.projected_solid_angle / kPi<T>;
  return v;
}

// pdf(w) = pdf_projected(c) |M c|^3 / |M| at c = M^-1 w / |M^-1 w| (the sampler's Jacobian, with |M^-1 w| = 1 / |M c|).
// |M c| from M itself, not 1 / |Minv_T w|: the computed inverse is Minv_T = M^-1 (I + E) with |E| up to eps cond(M),
// so Minv_T w = M^-1 w' for a w' = (I + E) w that is turned by up to |E| (harmless: the density is smooth) and
// stretched by up to |E|, which 1 / |Minv_T w|^3 turns into a relative error of 3 |E| of the density (found by
// fuzz_ltc_double, b98e6f95: cond(M) 1024, |E| 8.9e-14, sample pdf and pdf(direction) 8.3e-14 apart = 3 (E w).w;
// issue 7). c depends only on the direction of w', and |M c| = |w'| / |Minv_T w|: the density at w' / |w'| exactly.
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
// M^-1 P is often a thin, strongly decentral polygon, where 2 iterations leave the warp's true density off its
// reported pdf: `warpcheck validate --kernel polygon-ltc --config lobe-away --scalar double --samples 1000000`
// measured pdf-consistency 1.3e-4 (near xi_0 = 1) with 2 iterations and 5.7e-8 with 4. Correct first: 4.
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
