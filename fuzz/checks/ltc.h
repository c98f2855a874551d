// fuzz/checks/ltc.h: polygon lights sampled proportionally to a linearly transformed cosine, Peters 2021 Sec. 4.1
// (lib/warpcheck/ltc.h): transform the polygon by M^-1, sample the result by projected solid angle (Sec. 3), map the
// direction back by M. Polygons and shading points come from common.h's polygon decoders; the matrix M (in the
// shading frame) leans to ill-conditioning: near-singular (singular values down to 2^-(digits + 40)), rank one plus
// a tiny identity, huge shears, the fitted form of Heitz et al. 2016 ([[a, 0, b], [0, c, 0], [d, 0, 1]]), scaled by
// 2^+-300 (|M| overflows or underflows), reflecting (|M| < 0: no LTC), raw entries (NaN / Inf).
//
// Invariants beyond common.h's (shape, non-finite input, never a sample from a polygon check_polygon rejects):
//  - a sample lies inside the polygon (polygon.h's margins, not clipped: the LTC clips only in the
//    transformed space) and inside the LTC's support {w : (M^-1 w)_z >= 0}, a half-space in world directions
//    whose boundary great circle has the normal m_3 = the third row of M^-1 (long double);
//  - the sample's pdf agrees with pdf(direction) (check_pdf_consistency_probed);
//  - the view's normaliser, the projected solid angle A_Sigma of M^-1 P summed over the sampler's sectors,
//    equals Lambert's formula on M^-1 P computed in long double (polygon.h's independent reference);
//  - a reflecting M (|M| < 0 by more than rounding) gives no sample;
//  - pdf at an arbitrary direction: finite, >= 0, 0 for invalid geometry and outside polygon or support.
//
// Tolerances (the conditioning of M), with sigma_1 >= sigma_3 the singular values of M (long double SVD) and e =
// kTolUlps eps_T. The kernel computes M^-1 in T (Eigen's cofactor inverse, not backward stable for near-singular M);
// we measure its error instead of bounding it: E = M Minv_T - I in long double, so that Minv_T l = M^-1 (I + E) l,
// i.e. every direction l the kernel transforms by Minv_T is transformed exactly after a world-space move of at most
// |E| (Frobenius). Then, at a world direction w with c = M^-1 w / |M^-1 w| (exact):
//  * the transformed polygon is the exact transform of the polygon moved by e kappa_w (world rounding,
//    polygon.h) + |E|;
//  * the sampler's direction c' is inside it up to that family's tolerance e kappa_t (kappa_t: the transformed
//    polygon's conditioning seen from the origin, clipped to z >= 0); M c' in T has the forward error e |M| |c'|,
//    i.e. an angle e sigma_1 / |M c|, and normalize(M .) stretches angles at c by at most sigma_1 / |M c|:
//   tol(w) = e kappa_w + 2 |E| + e (sigma_1 / |M c|) (1 + kappa_t).
// pdf(w) evaluates the density at Minv_T l(w), the exact transform of a direction within |E| of w: the probe radius
// of the pdf comparison is 2 |E| + e sigma_1 / |M c| (the sample's own forward error).
#pragma once

#include <Eigen/SVD>

#include "polygon.h"
#include "warpcheck/ltc.h"

namespace warpcheck::fuzz {

template <class T> Mat3<T> rotation_from(FuzzedDataProvider& in) {
  const Vec3<T> z = safe_normalized(vec3<T>(in));
  const Frame<T> f = Frame<T>::from_z(z.isZero() ? Vec3<T>(T(0), T(0), T(1)) : z);
  Mat3<T> r;
  r.col(0) = f.x, r.col(1) = f.y, r.col(2) = f.z;
  return r;
}

template <class T> Mat3<T> decode_ltc_matrix(FuzzedDataProvider& in) {
  const int digits = std::numeric_limits<T>::digits;
  Mat3<T> m = Mat3<T>::Identity();
  switch (in.ConsumeIntegralInRange<int>(0, 7)) {
    case 0: {  // the identity (projected solid angle sampling), one entry moved by a tiny amount
      const int i = in.ConsumeIntegralInRange<int>(0, 2), j = in.ConsumeIntegralInRange<int>(0, 2);
      m(i, j) += tiny<T>(in, T(1));
      break;
    }
    case 1:  // raw entries
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) m(i, j) = scalar<T>(in);
      break;
    case 2: {  // the fitted form of isotropic BRDFs (Heitz et al. 2016, Sec. 4: m00, m02, m11, m20; m22 = 1)
      m(0, 0) = scalar<T>(in), m(0, 2) = scalar<T>(in), m(1, 1) = scalar<T>(in), m(2, 0) = scalar<T>(in);
      break;
    }
    case 3: {  // near-singular: R1 diag(1, s1, s2) R2, s = 2^-k down to below eps
      const Mat3<T> r1 = rotation_from<T>(in), r2 = rotation_from<T>(in);
      const int k1 = in.ConsumeIntegralInRange<int>(0, digits + 40),
                k2 = in.ConsumeIntegralInRange<int>(0, digits + 40);
      const Vec3<T> s(T(1), std::ldexp(T(1), -k1), std::ldexp(T(1), -k2));
      m = r1 * s.asDiagonal() * r2;
      break;
    }
    case 4: {  // rank one plus a tiny identity
      const Vec3<T> a = vec3<T>(in), b = vec3<T>(in);
      m = a * b.transpose() + Mat3<T>::Identity() * tiny<T>(in, T(1));
      break;
    }
    case 5: {  // a huge shear
      const int i = in.ConsumeIntegralInRange<int>(0, 2), j = in.ConsumeIntegralInRange<int>(0, 2);
      const T shear = scalar<T>(in);
      m(i, j) += std::ldexp(shear, in.ConsumeIntegralInRange<int>(0, digits + 20));
      break;
    }
    case 6: {  // a reflection (|M| < 0): no LTC
      Vec3<T> s(T(1), T(1), T(-1));
      const Mat3<T> r1 = rotation_from<T>(in), r2 = rotation_from<T>(in);
      m = r1 * s.asDiagonal() * r2;
      break;
    }
    default: {  // the fitted form scaled by 2^k: |M| overflows or underflows; the LTC itself is scale invariant
      m(0, 0) = scalar<T>(in), m(0, 2) = scalar<T>(in), m(1, 1) = scalar<T>(in), m(2, 0) = scalar<T>(in);
      m *= std::ldexp(T(1), in.ConsumeIntegralInRange<int>(-300, 300));
      break;
    }
  }
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m(i, j) = finite_or_zero(m(i, j));
  return m;
}

template <class T> std::string describe(const LtcPolygonGeometry<T>& g, const Vec2<T>& u, const char* kernel) {
  std::ostringstream os;
  os.precision(std::numeric_limits<T>::max_digits10);
  os << describe(g.polygon, u, kernel) << "M [";
  for (int i = 0; i < 3; ++i) os << (i ? "; " : "") << g.m(i, 0) << " " << g.m(i, 1) << " " << g.m(i, 2);
  os << "]\n";
  return os.str();
}

// The transform in long double from the exact inputs: shading frame, M^-1, conditioning, and the transformed
// polygon seen from the origin with normal z (what the sampler samples).
struct LtcReference {
  bool defined = false;  // a finite M with sigma_min > 0 and a normalisable shading normal
  Frame<L> frame = Frame<L>::from_z(Vec3<L>(0, 0, 1));
  Mat3<L> m = Mat3<L>::Zero(), m_inv = Mat3<L>::Zero();
  L det = 0, sigma1 = 0, sigma3 = 0;
  L inverse_error = std::numeric_limits<L>::infinity();  // |M Minv_T - I|_F
  // The stretch sigma_1 / |M c| of normalize(M .) at c = M^-1 w / |M^-1 w|, for a world direction w.
  L stretch(const Vec3<L>& w) const {
    const Vec3<L> c = m_inv * frame.to_local(w);
    const L cn = c.norm();
    return cn > 0 ? sigma1 / (m * Vec3<L>(c / cn)).norm() : std::numeric_limits<L>::infinity();
  }
  Vec3<L> m3 = Vec3<L>::Zero();  // the third row of M^-1: the support's boundary normal
  PolygonLightGeometry<L> transformed;
};
template <class T> LtcReference ltc_reference(const LtcPolygonGeometry<T>& g) {
  LtcReference r;
  r.m = g.m.template cast<L>();
  if (!r.m.allFinite() || !polygon_input_finite(g.polygon)) return r;
  r.det = r.m.determinant();
  const Vec3<L> n = g.polygon.shading.normal.template cast<L>();
  const L nn = n.norm();
  const Eigen::JacobiSVD<Mat3<L>> svd(r.m);
  const L smax = svd.singularValues()(0), smin = svd.singularValues()(2);
  if (!(smin > 0) || !(nn > 0) || !std::isfinite(nn)) return r;
  r.defined = true;
  r.sigma1 = smax, r.sigma3 = smin;
  Mat3<T> inv_t;  // the kernel's (ltc_inverse, as make_ltc_polygon_view computes it); both residuals
  T det_t;
  if (ltc_inverse(g.m, &inv_t, &det_t))
    r.inverse_error = std::max((r.m * inv_t.template cast<L>() - Mat3<L>::Identity()).norm(),
                               (inv_t.template cast<L>() * r.m - Mat3<L>::Identity()).norm());
  r.frame = Frame<L>::from_z(Vec3<L>(n / nn));
  // LU with full pivoting, not the cofactor formula: that one's inverse of an ill-conditioned M is a right inverse
  // only, even in long double (|X M - I| = 2.2 at cond(M) 6e10), and not inverse(): it divides by 0 for a singular M.
  // sigma_min > 0 above; a zero pivot is tested all the same.
  Eigen::FullPivLU<Mat3<L>> lu(r.m);
  lu.setThreshold(L(0));  // any nonzero pivot counts, as the cofactor formula accepted any nonzero determinant
  if (!(lu.rank() == 3)) return r.defined = false, r;
  r.m_inv = lu.inverse();
  if (!r.m_inv.allFinite()) return r.defined = false, r;
  r.m3 = r.m_inv.row(2).transpose();
  r.transformed.shading.position = Vec3<L>::Zero();
  r.transformed.shading.normal = Vec3<L>(0, 0, 1);
  r.transformed.light.count = std::clamp(g.polygon.light.count, 0, kMaxPolygonVertices);
  const Vec3<L> x = g.polygon.shading.position.template cast<L>();
  for (int i = 0; i < r.transformed.light.count; ++i)
    r.transformed.light.vertices[i] =
        r.m_inv * r.frame.to_local(Vec3<L>(g.polygon.light.vertices[i].template cast<L>() - x));
  return r;
}

// Step (1) of the normaliser check: the kernel's transformed polygon kt = M^-1 P (ltc_transformed_polygon of its
// local polygon, in T) against the exact one, vertex by vertex. Its vertices are the exact transforms of world
// vertices moved by e kappa_w + |E|, which M^-1 stretches as angles by |l_k| / (sigma_3 |M^-1 l_k|), plus the
// product's rounding (e). A light non-planar beyond the offsets' rounding is flattened by the kernel
// (make_polygon_view, polygon.h): vertex k moves by its distance d_k from the plane, which turns its direction by up
// to |d_k| / |V_k - x| before M^-1 stretches it. A vertex at the shading point (length 0) has an unbounded stretch
// and is skipped.
template <class T> void check_ltc_transformed_vertices(const LtcPolygonGeometry<T>& g,
                                                       const PolygonLightGeometry<T>& kt, const LtcReference& ref,
                                                       L kappa_w, const Mutation& mutate) {
  const L e = L(kTolUlps) * eps<T>();
  const PolygonLightGeometry<L> kt_l = kt.template cast<L>();
  const PolygonLifts lifts = polygon_lifts(g.polygon.light);
  for (int i = 0; i < ref.transformed.light.count && i < kt.light.count; ++i) {
    const Vec3<L> r = ref.transformed.light.vertices[i], k = mutate.transformed_vertex(kt_l.light.vertices[i]);
    const Vec3<L> l = ref.m * r;
    const L rn = r.norm(), kn = k.norm();
    if (!(rn > 0) || !(kn > 0)) continue;
    const L stretch = l.norm() / (ref.sigma3 * rn);
    const L allowed = stretch * (e * kappa_w + ref.inverse_error + std::abs(lifts.d[i]) / l.norm()) + e;
    const L angle = 2 * std::asin(std::min(L(1), Vec3<L>(r / rn - k / kn).norm() / 2));
    if (allowed < L(0.5))
      WARPCHECK_FUZZ_REQUIRE(angle <= allowed, "a vertex of M^-1 P off its exact transform",
                             describe(g, Vec2<T>(Vec2<T>::Zero()), PolygonLtc<T>::name) + "view: "
                                 << "vertex " << i << " angle " << angle << " allowed " << allowed << "\n");
  }
}

// Step (2): A_Sigma of the view against Lambert's formula (polygon.h's reference) for the kernel's own kt, as
// make_polygon_view accepts it: flattened onto its plane where the rounding of its vertices (cond(M) eps,
// ltc_vertex_rounding) leaves it non-planar beyond the offsets' own rounding. The sampler's clip points and edges
// move by e (1 + kappa_t) as angles, over a boundary of length <= 2 pi, and the sector sum rounds (16 eps). The two
// steps have separate bounds: one bound for both would have to carry step (1)'s displacement through step (2)'s
// leverage kappa_t, and A_Sigma's sensitivity to the world's rounding is the problem's conditioning, not the
// kernel's error. Flattening moves each vertex by at most the non-planarity, which step (1) bounds.
template <class T> void check_ltc_normaliser(const LtcPolygonGeometry<T>& g, const LtcPolygonView<T>& view,
                                             const PolygonLightGeometry<T>& kt, const Mutation& mutate) {
  const L e = L(kTolUlps) * eps<T>();
  const PolygonView<T> kpv = make_polygon_view(kt, ltc_vertex_rounding(view.m, view.m_inv));
  PolygonLightGeometry<L> flat_l = kt.template cast<L>();
  if (kpv.valid() && kpv.flattened)
    for (int i = 0; i < kpv.local.count; ++i)
      flat_l.light.vertices[i] = kpv.frame.to_world(kpv.local.v[i]).template cast<L>();
  const L a_ref = reference_projected_solid_angle(flat_l);
  const L kappa_k = polygon_kappa<L, T>(flat_l, true);
  const L rel = a_ref > 0 ? kTwoPi<L> * e * (1 + kappa_k) / a_ref + 16 * eps<T>() : L(1);
  const L a = L(mutate.normaliser(view.transformed.projected_solid_angle));
  if (rel < L(0.5))
    WARPCHECK_FUZZ_REQUIRE(std::abs(a / a_ref - 1) <= rel, "A_Sigma(M^-1 P) differs from Lambert's formula",
                           describe(g, Vec2<T>(Vec2<T>::Zero()), PolygonLtc<T>::name) + "view: "
                               << "A_Sigma " << a << " reference (of the kernel's M^-1 P) " << a_ref << " ratio - 1 "
                               << (a / a_ref - 1) << " allowed " << rel << "\n");
}

template <class T> void check_ltc(FuzzedDataProvider& in, const Mutation& mutate = {}) {
  LtcPolygonGeometry<T> g;
  g.polygon.light = decode_polygon<T>(in);
  g.polygon.shading = decode_polygon_shading<T>(in, g.polygon.light);
  g.m = decode_ltc_matrix<T>(in);
  const LtcPolygonView<T> view = make_ltc_polygon_view(g);
  const bool finite_input = polygon_input_finite(g.polygon) && g.m.allFinite();
  const bool valid_polygon = check_polygon(g.polygon.light) == NoSample::kNone;
  const LtcReference ref = ltc_reference(g);
  const L e = L(kTolUlps) * eps<T>();
  const bool checkable = finite_input && valid_polygon && ref.defined;
  const L kappa_t = checkable ? polygon_kappa<L, T>(ref.transformed, true) : L(0);
  const L kappa_w = checkable ? polygon_kappa(g.polygon, false) : L(0);
  auto tol_at = [&](const Vec3<T>& w) {
    return e * kappa_w + 2 * ref.inverse_error + e * ref.stretch(w.template cast<L>().normalized()) * (1 + kappa_t);
  };
  const L m3n = ref.m3.norm();
  // Margins of a world direction: inside the polygon (outer / inner as in polygon.h) and in the support.
  auto margins = [&](const Vec3<T>& w) {
    PolygonMargins pm = polygon_margins(g.polygon, w, false);
    const L support = m3n > 0 ? ref.m3.dot(ref.frame.to_local(w.template cast<L>().normalized())) / m3n : L(0);
    pm.inner = std::min(pm.inner, support), pm.outer = std::min(pm.outer, support);
    return pm;
  };
  // A reflecting transform: |M| < 0 beyond the rounding of the determinant (a few eps of the product of the
  // columns' norms, Hadamard's bound).
  const L hadamard = ref.m.col(0).norm() * ref.m.col(1).norm() * ref.m.col(2).norm();
  const bool reflecting = finite_input && ref.det < -e * hadamard;
  if (view.valid() && checkable) {
    const PolygonLightGeometry<T> kt = ltc_transformed_polygon(make_polygon_view(g.polygon), view.m_inv);
    check_ltc_transformed_vertices(g, kt, ref, kappa_w, mutate);
    check_ltc_normaliser(g, view, kt, mutate);
  }

  const int samples = in.ConsumeIntegralInRange<int>(1, 3);
  for (int k = 0; k < samples; ++k) {
    const Vec2<T> u = unit_square<T>(in);
    const DirectionSample<T> s = mutate.sample(sample_ltc_polygon(view, u));
    const std::string geo = describe(g, u, PolygonLtc<T>::name);
    check_sample_shape(s, geo);
    if (!finite_input) WARPCHECK_FUZZ_REQUIRE(!s.valid(), "a sample from non-finite input", geo);
    if (!s.valid()) continue;
    WARPCHECK_FUZZ_REQUIRE(valid_polygon, "a sample from a polygon that check_polygon rejects", geo);
    WARPCHECK_FUZZ_REQUIRE(!reflecting, "a sample from a reflecting M", geo << "|M| " << ref.det << "\n");
    if (!ref.defined) continue;  // M singular in long double although not in T: no reference
    const PolygonMargins pm = margins(s.direction);
    const L tol = tol_at(s.direction);
    WARPCHECK_FUZZ_REQUIRE(pm.outer >= -tol, "direction outside the polygon or the LTC's support",
                           geo << "direction " << show(s.direction) << " margin " << pm.outer << " tol " << tol
                               << " |E| " << ref.inverse_error << " sigma_1 / sigma_3 " << ref.sigma1 / ref.sigma3
                               << "\n");
    const L radius = 2 * ref.inverse_error + e * ref.stretch(s.direction.template cast<L>().normalized());
    check_pdf_consistency_probed<T>(
        s.pdf, s.direction, [&](const Vec3<T>& w) { return mutate.pdf(pdf_ltc_polygon(view, w)); }, radius,
        16 * eps<T>(), pm.inner, tol, geo);
  }
  // The density at an arbitrary unit direction.
  const Vec3<T> w = safe_normalized(
      in.ConsumeBool() ? vec3<T>(in)
                       : Vec3<T>(polygon_centroid(g.polygon.light) - g.polygon.shading.position + vec3<T>(in)));
  const T p = mutate.pdf(pdf_ltc_polygon(view, w));
  const std::string geo = describe(g, Vec2<T>(Vec2<T>::Zero()), PolygonLtc<T>::name) + "pdf at w " + show(w) + "\n";
  WARPCHECK_FUZZ_REQUIRE(std::isfinite(p) && p >= T(0), "pdf not finite and >= 0", geo << "pdf " << p << "\n");
  if (!view.valid() || !finite_input || !valid_polygon || reflecting)
    WARPCHECK_FUZZ_REQUIRE(p == T(0), "pdf > 0 for invalid geometry", geo << "pdf " << p << "\n");
  else if (checkable && !w.isZero()) {
    const L margin = margins(w).outer, tol = tol_at(w);
    if (margin < -tol)
      WARPCHECK_FUZZ_REQUIRE(p == T(0), "pdf > 0 outside the polygon or the LTC's support",
                             geo << "pdf " << p << " margin " << margin << " tol " << tol << "\n");
  }
}

}  // namespace warpcheck::fuzz
