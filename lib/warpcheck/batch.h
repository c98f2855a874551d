// warpcheck/batch.h: many samples of one light at once, written so that the compiler vectorises the loop.
//
// sample_*_batch maps n primary samples to n directions of one light's view, stored as a structure of arrays, one
// sample per SIMD lane. Sine and cosine are Taylor polynomials after an exact quadrant reduction (libm's vectorise
// only under -ffast-math, which this project forbids), so the batch agrees with the scalar kernel to a few ulps.
#pragma once

#include <cstddef>

#include "warpcheck/sphere.h"

namespace warpcheck {

namespace batch_detail {

// Taylor terms of sin and cos on |a| <= pi/4 whose first omitted term is below 2^-digits: float 6 ((pi/4)^13 / 13! =
// 7.8e-12), double 10 ((pi/4)^21 / 21! = 1.2e-21), up to 113 bits 16 ((pi/4)^33 / 33! = 2.6e-41).
template <class T> constexpr int sincos_terms() {
  constexpr int d = std::numeric_limits<T>::digits;
  return d <= 24 ? 6 : d <= 53 ? 10 : d <= 64 ? 12 : 16;
}

// sin(a), cos(a) for |a| <= pi/4 by Horner's scheme in a^2 with coefficients 1/(2k+1)!, 1/(2k)! (constexpr).
template <class T> inline void sincos_quarter(T a, T& s, T& c) {
  constexpr int n = sincos_terms<T>();
  const T a2 = a * a;
  T ps = T(0), pc = T(0);
  // Horner from the highest term, p_k = 1/(2k+1)! - a^2 p_{k+1}; the coefficients are compile-time constants.
  constexpr auto coef = [] {
    struct C {
      T s[n];
      T c[n];
    } r{};
    long double f = 1;  // k!
    for (int k = 0; k <= 2 * n; ++k) {
      if (k > 0) f *= k;
      if (k % 2 == 1 && k / 2 < n) r.s[k / 2] = T(1.0L / f);
      if (k % 2 == 0 && k / 2 < n) r.c[k / 2] = T(1.0L / f);
    }
    return r;
  }();
  for (int k = n - 1; k >= 0; --k) {
    ps = coef.s[k] - a2 * ps;
    pc = coef.c[k] - a2 * pc;
  }
  s = a * ps;
  c = pc;
}

// sin(2 pi u), cos(2 pi u) for u in [0, 1]: quadrant q = trunc(4u + 1/2) (vectorises without SSE4.1), r = u - q/4 in
// [-1/8, 1/8] exactly (Sterbenz), a = 2 pi r; then rotate by q quarter turns.
template <class T> inline void sincos_2pi(T u, T& s, T& c) {
  // No selects (GCC 12 does not if-convert them under -ftrapping-math): the quarter turn is applied exactly by
  // arithmetic, w in {0, 1} blending w ca + (1 - w) sa (one product an exact 0) and exact +-1 sign factors.
  const int q = int(u * T(4) + T(0.5));  // 0..4; q = 4 is a full turn, the same as q = 0
  const T r = u - T(q) * T(0.25);
  T sa, ca;
  sincos_quarter(kTwoPi<T> * r, sa, ca);
  const T w = T(q & 1);                                    // q = 1, 3: swap sine and cosine
  const T sin_sign = T(1) - T(2) * T((q >> 1) & 1);        // q = 2, 3: sine negative
  const T cos_sign = T(1) - T(2) * T(((q + 1) >> 1) & 1);  // q = 1, 2: cosine negative
  s = sin_sign * (w * ca + (T(1) - w) * sa);
  c = cos_sign * (w * sa + (T(1) - w) * ca);
}

}  // namespace batch_detail

// Output of a batch: caller-owned arrays of length n (structure of arrays).
template <class T> struct DirectionBatch {
  T* x;
  T* y;
  T* z;
  T* pdf;
};

// Solid-angle sampling of a sphere (sample_sphere_solid_angle's formulas) for n primary samples, with the polynomial
// sincos and u clamped to [0, 1]. Returns kNone (every output a sample) or the view's reason (every output zero).
template <class T> NoSample sample_sphere_solid_angle_batch(const SphereView<T>& v, const T* __restrict u0,
                                                            const T* __restrict u1, std::size_t n,
                                                            DirectionBatch<T> out) {
  T* __restrict ox = out.x;
  T* __restrict oy = out.y;
  T* __restrict oz = out.z;
  T* __restrict op = out.pdf;
  if (!v.valid()) {
    for (std::size_t i = 0; i < n; ++i) ox[i] = oy[i] = oz[i] = op[i] = T(0);
    return v.reason;
  }
  const T omc_max = v.one_minus_cos_max, pdf = sphere_solid_angle_density(v);
  const T fx0 = v.frame.x.x(), fx1 = v.frame.x.y(), fx2 = v.frame.x.z();
  const T fy0 = v.frame.y.x(), fy1 = v.frame.y.y(), fy2 = v.frame.y.z();
  const T fz0 = v.frame.z.x(), fz1 = v.frame.z.y(), fz2 = v.frame.z.z();
  // Blocks of kBlock samples in three loops without calls; square roots and clamps as Eigen array expressions
  // (std::sqrt and ?: stop GCC 12 from vectorising). The select on u >= 0 maps a NaN u to 0.
  constexpr std::size_t kBlock = 128;
  using ArrayMap = Eigen::Map<Eigen::Array<T, Eigen::Dynamic, 1>>;
  alignas(64) T ua[kBlock], ub[kBlock], sin_theta[kBlock], cos_theta[kBlock], sin_phi[kBlock], cos_phi[kBlock],
      norm[kBlock];
  using ConstMap = Eigen::Map<const Eigen::Array<T, Eigen::Dynamic, 1>>;
  for (std::size_t i0 = 0; i0 < n; i0 += kBlock) {
    const std::size_t m = n - i0 < kBlock ? n - i0 : kBlock;
    ArrayMap(ua, m) = (ConstMap(u0 + i0, m) >= T(0)).select(ConstMap(u0 + i0, m).min(T(1)), T(0));
    ArrayMap(ub, m) = (ConstMap(u1 + i0, m) >= T(0)).select(ConstMap(u1 + i0, m).min(T(1)), T(0));
    for (std::size_t j = 0; j < m; ++j) {
      // 1 - cos(theta) = u0 (1 - cos(theta_max)), sin^2 = (1 - cos)(1 + cos) >= 0 without a clamp (u0 in [0, 1]).
      const T one_minus_cos = ua[j] * omc_max;
      cos_theta[j] = T(1) - one_minus_cos;
      sin_theta[j] = one_minus_cos * (T(2) - one_minus_cos);
      batch_detail::sincos_2pi(ub[j], sin_phi[j], cos_phi[j]);
    }
    ArrayMap(sin_theta, m) = ArrayMap(sin_theta, m).sqrt();
    for (std::size_t j = 0; j < m; ++j) {
      const T lx = sin_theta[j] * cos_phi[j], ly = sin_theta[j] * sin_phi[j], lz = cos_theta[j];
      const T wx = lx * fx0 + ly * fy0 + lz * fz0;
      const T wy = lx * fx1 + ly * fy1 + lz * fz1;
      const T wz = lx * fx2 + ly * fy2 + lz * fz2;
      ox[i0 + j] = wx;
      oy[i0 + j] = wy;
      oz[i0 + j] = wz;
      norm[j] = wx * wx + wy * wy + wz * wz;
    }
    ArrayMap(norm, m) = ArrayMap(norm, m).sqrt();
    // Renormalise like the scalar kernel (renormalized() of core.h); the norm is 1 up to rounding, never 0.
    for (std::size_t j = 0; j < m; ++j) {
      const T inv = T(1) / norm[j];
      ox[i0 + j] *= inv;
      oy[i0 + j] *= inv;
      oz[i0 + j] *= inv;
      op[i0 + j] = pdf;
    }
  }
  return NoSample::kNone;
}

// Any kernel with a per-light view and a scalar sample(view, u), batched by a plain loop (no vectorisation promised);
// a sample declined individually gets pdf 0 and direction 0.
template <class T, class View, class SampleFn> void sample_batch_scalar(const View& v, SampleFn&& sample, const T* u0,
                                                                        const T* u1, std::size_t n,
                                                                        DirectionBatch<T> out) {
  for (std::size_t i = 0; i < n; ++i) {
    const DirectionSample<T> s = sample(v, Vec2<T>(u0[i], u1[i]));
    out.x[i] = s.direction.x();
    out.y[i] = s.direction.y();
    out.z[i] = s.direction.z();
    out.pdf[i] = s.pdf;
  }
}

}  // namespace warpcheck
