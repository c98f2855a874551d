// warpcheck/batch.h: many samples of one light at once, written so that the compiler vectorises the loop.
//
// The per-light precomputation (a *View, Peters & Dachsbacher 2019 Sec. 3.7) is done once by the caller;
// sample_*_batch then maps n primary samples (u0[i], u1[i]) to n directions, stored as a structure of arrays
// (dx, dy, dz, pdf), so that each lane of a SIMD register holds one sample. The whole batch shares one
// NoSample reason: the per-light view decides whether a sample exists (for solid-angle sampling of a sphere
// every primary sample of a valid view gives a sample), and on "no sample" every output is zero.
//
// Why hand-rolled sine and cosine: std::sin / std::cos are calls into libm, which GCC and Clang vectorise
// only through glibc's libmvec, and glibc declares those SIMD variants only under -ffast-math, which this
// project forbids (IEEE semantics for NaN/Inf). No Debian SIMD library is needed for one sincos of an angle
// in [0, 2 pi): the quadrant reduction is exact (phi = 2 pi u1, u1 in [0, 1], reduced in u1, not in phi) and
// the remaining |a| <= pi/4 is covered by Taylor polynomials whose truncation error is below half an ulp of T
// (term counts chosen from std::numeric_limits<T>::digits below). The scalar kernel and the batch therefore
// agree to a few ulps, not bit for bit; validation/tests/test_batch.cpp measures the difference.
#pragma once

#include <cstddef>

#include "warpcheck/sphere.h"

namespace warpcheck {

namespace batch_detail {

// Number of Taylor terms of sin(a) = sum_k (-1)^k a^(2k+1) / (2k+1)! for |a| <= pi/4 whose first omitted term
// is below 2^-digits: float (24 bits) 6 terms (omitted term (pi/4)^13 / 13! = 7.8e-12), double (53 bits) 10
// terms ((pi/4)^21 / 21! = 1.2e-21), up to 113 bits 16 terms ((pi/4)^33 / 33! = 2.6e-41 < 2^-113 = 9.6e-35).
// cos uses the same count (its omitted term (pi/4)^(2k) / (2k)! is of the same order).
template <class T> constexpr int sincos_terms() {
  constexpr int d = std::numeric_limits<T>::digits;
  return d <= 24 ? 6 : d <= 53 ? 10 : d <= 64 ? 12 : 16;
}

// sin(a), cos(a) for |a| <= pi/4 by Horner's scheme in a^2 with coefficients 1/(2k+1)!, 1/(2k)! (constexpr).
template <class T> inline void sincos_quarter(T a, T& s, T& c) {
  constexpr int n = sincos_terms<T>();
  const T a2 = a * a;
  T ps = T(0), pc = T(0);
  // Horner from the highest term: p_k = 1/(2k+1)! - a^2 p_{k+1}, with 1/(2k+1)! = 1/(2k+3)! (2k+2)(2k+3).
  // The coefficients are computed as constants at compile time.
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

// sin(2 pi u), cos(2 pi u) for u in [0, 1]: quadrant q = nearest multiple of 1/4 (computed by truncation of
// 4u + 1/2, which vectorises on every x86-64, unlike rounding instructions before SSE4.1), r = u - q/4 in
// [-1/8, 1/8] exactly (Sterbenz), a = 2 pi r in [-pi/4, pi/4]; then rotate by q quarter turns.
template <class T> inline void sincos_2pi(T u, T& s, T& c) {
  // No selects: GCC 12 (under the default -ftrapping-math) would not if-convert them here ("control flow in
  // loop"). The quarter turn is applied arithmetically and exactly instead: w in {0, 1} blends
  // w ca + (1 - w) sa (one product is an exact 0, the other exact), and the signs are exact +-1 factors.
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

// Solid-angle sampling of a sphere (Shirley 1996 Sec. 3.2.2, as sample_sphere_solid_angle in sphere.h) for n
// primary samples (u0[i], u1[i]) in [0, 1]. Same formulas as the scalar kernel; the only differences are the
// polynomial sincos above and the clamping of u to [0, 1] (the scalar kernel trusts its caller). Returns the
// batch's reason: kNone (every output is a sample) or the view's reason (every output is zero).
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
  // Blocks of kBlock samples, in three loops without calls. The square roots go through Eigen's array
  // sqrt (SIMD sqrt instructions): std::sqrt in the loop body keeps GCC from vectorising under the default
  // -fmath-errno (it branches to libm to set errno for negative arguments; measured with -fopt-info-vec-missed:
  // "not vectorized: control flow in loop"). Our arguments are never negative.
  constexpr std::size_t kBlock = 128;
  using ArrayMap = Eigen::Map<Eigen::Array<T, Eigen::Dynamic, 1>>;
  // The clamps of u to [0, 1] are Eigen array expressions too: a ?: in the loop body (u > 0 ? u : 0) is not
  // if-converted by GCC 12 under the default -ftrapping-math (measured: the loop vectorises with
  // -fno-trapping-math only). Eigen 3.4's max(0) propagates a NaN u (std::max / maxps operand order), so the
  // lower clamp is a select on u >= 0, false for NaN: a NaN u gives 0, no NaN output (test_batch checks it).
  alignas(64) T ua[kBlock], ub[kBlock], sin_theta[kBlock], cos_theta[kBlock], sin_phi[kBlock], cos_phi[kBlock],
      norm[kBlock];
  using ConstMap = Eigen::Map<const Eigen::Array<T, Eigen::Dynamic, 1>>;
  for (std::size_t i0 = 0; i0 < n; i0 += kBlock) {
    const std::size_t m = n - i0 < kBlock ? n - i0 : kBlock;
    ArrayMap(ua, m) = (ConstMap(u0 + i0, m) >= T(0)).select(ConstMap(u0 + i0, m).min(T(1)), T(0));
    ArrayMap(ub, m) = (ConstMap(u1 + i0, m) >= T(0)).select(ConstMap(u1 + i0, m).min(T(1)), T(0));
    for (std::size_t j = 0; j < m; ++j) {
      // 1 - cos(theta) = u0 (1 - cos(theta_max)); sin^2 = (1 - cos)(1 + cos), as in sphere.h. With u0 in [0, 1]
      // and 1 - cos(theta_max) < 1 (a valid view has r < d), sin^2 >= 0 needs no clamp.
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

// Any kernel with a per-light view and a scalar sample(view, u) function, batched by a plain loop (no
// vectorisation promised: the polygon and projected-cap kernels branch per sample). Gives the same batch
// interface to every kernel; a sample declined individually gets pdf 0 and direction 0 in the output.
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
