// warpcheck/mis.h: multiple importance sampling for a mixed diffuse + specular BRDF lit by a polygon light,
// Peters 2021 Sections 4.2 (weighted balance heuristic) and 4.3 (clamped optimal MIS).
//
// Two techniques: j = 0 projected solid angle (the LTC with M_0 = I) and j = 1 the LTC with M_1 (ltc.h), with
// normalised densities p_j (Eq. 12) and
//   c_j = L_e a_j int_P p_{M_j}                                  (Sec. 4.2, the unshadowed LTC shading)
//   w_j^w = c_j p_j / sum_k c_k p_k                              (weighted balance heuristic)
//   w_j^c = v w_j^w + (1 - v) p_j / sum_k p_k                    (clamped optimal MIS, Sec. 4.3)
//   w_j^b = p_j / sum_k p_k                                      (the balance heuristic, for comparison)
// Estimators: multi-sample, sum_j f(w_j) w_j(w_j) / p_j(w_j) with one sample per technique; one-sample
// (Veach & Guibas 1995), technique j chosen with probability q_j = c_j / sum_k c_k, f(w) w_j(w) / (q_j p_j(w)).
// A technique whose light is empty after clipping is disabled (Sec. 4.1): p_j = 0, c_j = 0.
// Single channel (the paper computes c_j per colour channel and chooses the one-sample technique by luminance).
#pragma once

#include <array>
#include <functional>

#include "warpcheck/ltc.h"

namespace warpcheck {

enum class MisHeuristic : std::uint8_t { kBalance, kWeightedBalance, kClampedOptimal };

template <class T> struct MixedPolygonShading {
  PolygonLightGeometry<T> polygon;
  Mat3<T> m_specular = Mat3<T>::Identity();         // M_1
  T albedo_diffuse = T(1), albedo_specular = T(0);  // a_0, a_1
  T emitted = T(1);                                 // L_e
};

template <class T> struct MisView {
  std::array<LtcPolygonView<T>, 2> technique;
  std::array<T, 2> c{T(0), T(0)};  // c_j; 0 for a disabled technique
  bool any() const { return technique[0].valid() || technique[1].valid(); }
  T sum_c() const { return c[0] + c[1]; }
  std::array<T, 2> pdfs(const Vec3<T>& w) const {
    return {pdf_ltc_polygon(technique[0], w), pdf_ltc_polygon(technique[1], w)};
  }
};

template <class T> MisView<T> make_mis_view(const MixedPolygonShading<T>& s) {
  MisView<T> v;
  v.technique[0] = make_ltc_polygon_view(LtcPolygonGeometry<T>{s.polygon, Mat3<T>::Identity()});
  v.technique[1] = make_ltc_polygon_view(LtcPolygonGeometry<T>{s.polygon, s.m_specular});
  const T a[2] = {s.albedo_diffuse, s.albedo_specular};
  for (int j = 0; j < 2; ++j) v.c[j] = v.technique[j].valid() ? s.emitted * a[j] * v.technique[j].integral : T(0);
  return v;
}

// The idealised integrand L_e (a_0 p_{M_0} + a_1 p_{M_1}) (Eq. 11), zero outside the polygon.
template <class T> T idealized_integrand(const MixedPolygonShading<T>& s, const MisView<T>& v, const Vec3<T>& w) {
  if (!v.technique[0].valid() && !v.technique[1].valid()) return T(0);
  // Inside P: either technique's support test (P clipped by the respective horizon) decides.
  const auto p = v.pdfs(w);
  if (!(p[0] > T(0)) && !(p[1] > T(0))) return T(0);
  const LtcPolygonView<T>& any = v.technique[0].valid() ? v.technique[0] : v.technique[1];
  const Vec3<T> l = any.frame.to_local(w) / w.norm();
  const T d0 = ltc_density_local<T>(Mat3<T>::Identity(), T(1), l);
  const T d1 = v.technique[1].valid() ? ltc_density_local(v.technique[1].m_inv, v.technique[1].det_inv, l) : T(0);
  return s.emitted * (s.albedo_diffuse * d0 + s.albedo_specular * d1);
}

// The MIS weight of technique j at a direction with densities p (Sec. 4.2, 4.3).
template <class T> T mis_weight(MisHeuristic h, int j, const std::array<T, 2>& p, const std::array<T, 2>& c, T v) {
  const T sum_p = p[0] + p[1];
  const T balance = sum_p > T(0) ? p[j] / sum_p : T(0);
  const T sum_cp = c[0] * p[0] + c[1] * p[1];
  const T weighted = sum_cp > T(0) ? c[j] * p[j] / sum_cp : balance;
  switch (h) {
    case MisHeuristic::kBalance:
      return balance;
    case MisHeuristic::kWeightedBalance:
      return weighted;
    case MisHeuristic::kClampedOptimal:
      return v * weighted + (T(1) - v) * balance;
  }
  return T(0);
}

// Multi-sample estimator: one sample per technique, u[j] its random numbers. f is the integrand
// (L_e V f_r cos in a renderer).
template <class T, class F>
T mis_estimate_multi(const MisView<T>& v, MisHeuristic h, T vis, const std::array<Vec2<T>, 2>& u, F&& f) {
  T sum = 0;
  for (int j = 0; j < 2; ++j) {
    if (!v.technique[j].valid()) continue;
    const DirectionSample<T> s = sample_ltc_polygon(v.technique[j], u[j]);
    if (!s.valid()) continue;
    std::array<T, 2> p = v.pdfs(s.direction);
    p[j] = s.pdf;  // the sample's own density (identical to pdf_ltc_polygon up to rounding)
    const T fw = f(s.direction);
    if (fw != T(0)) sum += fw * mis_weight(h, j, p, v.c, vis) / s.pdf;
  }
  return sum;
}

// One-sample estimator: technique j with probability q_j = c_j / sum c (chosen by `select` in [0, 1)).
// Unbiased when every technique with a nonzero weight has q_j > 0 (a_j > 0, as Sec. 4.2 requires of a_0).
template <class T, class F>
T mis_estimate_one(const MisView<T>& v, MisHeuristic h, T vis, T select, const Vec2<T>& u, F&& f) {
  const T total = v.sum_c();
  if (!(total > T(0))) return T(0);
  const T q0 = v.c[0] / total;
  const int j = select < q0 ? 0 : 1;
  const T q = j == 0 ? q0 : T(1) - q0;
  if (!(q > T(0)) || !v.technique[j].valid()) return T(0);
  const DirectionSample<T> s = sample_ltc_polygon(v.technique[j], u);
  if (!s.valid()) return T(0);
  std::array<T, 2> p = v.pdfs(s.direction);
  p[j] = s.pdf;
  const T fw = f(s.direction);
  return fw != T(0) ? fw * mis_weight(h, j, p, v.c, vis) / (q * s.pdf) : T(0);
}

}  // namespace warpcheck
