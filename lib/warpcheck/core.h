// warpcheck/core.h: the types every kernel shares.
//
// Every kernel is templated on its scalar type T (float, double, long double), so that it can be checked against
// its own long double instantiation, and returns a DirectionSample<T>: a unit direction, its density per solid
// angle, or "no sample" with a reason. A kernel never returns NaN and never throws for bad geometry.
#pragma once

#include <bit>
#include <cstdint>
#include <cstring>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <numbers>
#include <type_traits>

// For the small helpers of every view, which GCC otherwise leaves as calls on the one-sample-per-light path.
#if defined(__GNUC__)
#define WARPCHECK_ALWAYS_INLINE [[gnu::always_inline]] inline
#else
#define WARPCHECK_ALWAYS_INLINE inline
#endif

namespace warpcheck {

template <class T> using Vec2 = Eigen::Matrix<T, 2, 1>;
template <class T> using Vec3 = Eigen::Matrix<T, 3, 1>;

// Why a kernel produced no sample (kNone: a sample exists).
enum class NoSample : std::uint8_t {
  kNone = 0,
  kNonFinite,        // NaN or Inf anywhere in the input
  kBadNormal,        // zero (or non-normalisable) shading normal
  kZeroSize,         // radius 0, zero-area polygon, ...
  kNegativeSize,     // negative radius
  kInsideLight,      // shading point inside the light or on its surface
  kBelowHorizon,     // the light is entirely behind the shading surface
  kEdgeOn,           // the light is seen exactly edge-on (zero solid angle)
  kTooSmall,         // the light subtends no representable solid angle in this precision
  kOnSilhouette,     // the sample landed where the density is infinite (a measure-zero set)
  kInvalidGeometry,  // non-convex, non-planar, too many vertices, singular transform, ...
};

constexpr const char* to_string(NoSample r) {
  switch (r) {
    case NoSample::kNone:
      return "sample";
    case NoSample::kNonFinite:
      return "non-finite input";
    case NoSample::kBadNormal:
      return "zero or non-finite shading normal";
    case NoSample::kZeroSize:
      return "light of zero size";
    case NoSample::kNegativeSize:
      return "light of negative size";
    case NoSample::kInsideLight:
      return "shading point inside or on the light";
    case NoSample::kBelowHorizon:
      return "light entirely below the horizon";
    case NoSample::kEdgeOn:
      return "light seen edge-on";
    case NoSample::kTooSmall:
      return "light subtends no representable solid angle";
    case NoSample::kOnSilhouette:
      return "sample on the silhouette (infinite density)";
    case NoSample::kInvalidGeometry:
      return "invalid geometry";
  }
  return "unknown";
}

// The one result type of every kernel.
template <class T> struct DirectionSample {
  Vec3<T> direction = Vec3<T>::Zero();  // unit, world space; zero when there is no sample
  T pdf = T(0);                         // density w.r.t. solid angle; 0 when there is no sample
  NoSample reason = NoSample::kNone;

  bool valid() const { return reason == NoSample::kNone; }
  static DirectionSample none(NoSample why) {
    DirectionSample s;
    s.reason = why;
    return s;
  }
};

// A point on a surface being shaded. The normal need not be unit length; kernels normalise it.
template <class T> struct ShadingPoint {
  Vec3<T> position = Vec3<T>::Zero();
  Vec3<T> normal = Vec3<T>(T(0), T(0), T(1));
};

// A spherical cap {w : angle(w, axis) <= half_angle}, stored as 1 - cos (tiny caps keep their precision).
template <class T> struct Cap {
  Vec3<T> axis = Vec3<T>(T(0), T(0), T(1));
  T one_minus_cos = T(2);  // 1 - cos(half_angle), in [0, 2]

  T cos_half_angle() const { return T(1) - one_minus_cos; }
  T solid_angle() const { return T(2) * std::numbers::pi_v<T> * one_minus_cos; }
  // By chord length: |w - axis|^2 = 2 (1 - w.axis) <= 2 (1 - cos(half_angle)).
  bool contains(const Vec3<T>& w, T slack = T(0)) const {
    return (w - axis).squaredNorm() <= T(2) * one_minus_cos * (T(1) + slack) + slack;
  }
};

template <class T> bool all_finite(const Vec3<T>& v) {
  return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z());
}

// An orthonormal frame whose z axis is a given unit vector, by the branch-free construction of Duff et al.,
// "Building an Orthonormal Basis, Revisited", JCGT 6(1), 2017 (their Listing 3, written from the formulas).
template <class T> struct Frame {
  Vec3<T> x, y, z;

  WARPCHECK_ALWAYS_INLINE static Frame from_z(const Vec3<T>& n) {
    const T sign = std::copysign(T(1), n.z());
    const T a = T(-1) / (sign + n.z());
    const T b = n.x() * n.y() * a;
    Frame f;
    f.x = Vec3<T>(T(1) + sign * n.x() * n.x() * a, sign * b, -sign * n.x());
    f.y = Vec3<T>(b, sign + n.y() * n.y() * a, -n.y());
    f.z = n;
    return f;
  }
  Vec3<T> to_world(const Vec3<T>& v) const { return v.x() * x + v.y() * y + v.z() * z; }
  Vec3<T> to_local(const Vec3<T>& v) const { return Vec3<T>(v.dot(x), v.dot(y), v.dot(z)); }
};

// Cube root for per-sample paths, inlinable (glibc's cbrt is a call): fdlibm's exponent-third guess (within ~3%),
// then Halley's iteration y <- y + y (x - y^3) / (2 y^3 + x): 3e-5, 3e-14, then rounding. Float takes two steps in
// double, double three (error: test CubeRoot.*). Outside [2^-600, 2^600] (y^3 could underflow), for long double
// and for 0, negatives, Inf, NaN: std::cbrt.
template <class T> T cube_root(T x) {
  if constexpr (std::is_same_v<T, float> || std::is_same_v<T, double>) {
    const double xd = double(x);
    if (xd >= 0x1p-600 && xd <= 0x1p600) {
      double y = std::bit_cast<double>(((std::bit_cast<std::uint64_t>(xd) >> 32) / 3 + 715094163ull) << 32);
      constexpr int iterations = std::is_same_v<T, float> ? 2 : 3;
      for (int i = 0; i < iterations; ++i) {
        const double y3 = y * y * y;
        y += y * (xd - y3) / (2 * y3 + xd);  // correction form: the rounding of y^3 enters y at a third
      }
      return T(y);
    }
  }
  return std::cbrt(x);
}

// x^(2/3) of a float without a division (the float projected-cap quintic's root). In double: r = x^(-1/3) from an
// exponent-third guess (K fitted: at most 3.42% off over [1, 8)), then one division-free step r <- r (1 + d P(d)),
// d = 1 - x r^3, P the series of (1 - d)^(-1/3) to d^7; |d| <= 0.106 leaves below 1.6e-9. x^(2/3) = x r, rounded
// once. Exact under x -> 8 x, so [1, 8) covers every float (exhaustive test: CubeRootSquaredForFloat.*).
// x = 0 gives 0; negative, Inf, NaN: std::cbrt.
inline float cube_root_squared_for_float(float x) {
  if (!(x > 0.0f) || !(x <= std::numeric_limits<float>::max())) {
    const float c = x == 0.0f ? 0.0f : std::cbrt(x);
    return c * c;
  }
  const double xd = double(x);  // subnormal floats are normal doubles
  const double r = std::bit_cast<double>(0x553ef0ff00000000ull - std::bit_cast<std::uint64_t>(xd) / 3);
  const double xr = xd * r;  // x^(2/3) to the guess's accuracy
  const double d = 1 - xr * (r * r);
  constexpr double c1 = 1.0 / 3, c2 = c1 * 4 / 6, c3 = c2 * 7 / 9, c4 = c3 * 10 / 12, c5 = c4 * 13 / 15,
                   c6 = c5 * 16 / 18, c7 = c6 * 19 / 21;
  const double d2 = d * d, d4 = d2 * d2;  // Estrin's scheme: a shorter dependency chain than Horner's
  const double p = (c1 + c2 * d) + d2 * (c3 + c4 * d) + d4 * ((c5 + c6 * d) + d2 * c7);
  return float(xr + (xr * d) * p);  // x (r + r d P(d))
}

// ---- Arctangents ----

// atan2 evaluated in double for the float kernels, inline: glibc 2.36's atan2f is a call into atanf (about 16 ns here)
// and misrounds about one argument in seven (docs/measurements.md). Octants reduce to t = lo / hi in [0, 1]; above
// tan(pi/8), atan t = pi/4 + atan((lo - hi) / (lo + hi)); then atan t = t P(t^2), P of degree 10 with relative error
// 3.5e-17 (scripts/fit_arctangent.py), by Estrin's scheme. Within 4 ulps of double, so rounded to float it is the
// correctly rounded float but within 2^-50 of a midpoint (test: Atan2InDouble.*). Subnormal t is still one
// rounding (of lo / hi, then t P). Where hi is 0, Inf, NaN or above 2^1000 (lo + hi could overflow): std::atan2.
inline double atan2_in_double(double y, double x) {
  const double ax = std::abs(x), ay = std::abs(y);
  const bool steep = ax < ay;
  const double hi = steep ? ay : ax, lo = steep ? ax : ay;
  if (!(hi > 0 && hi <= 0x1p1000)) return std::atan2(y, x);  // a NaN lo gives NaN below
  const bool upper = lo > 0.41421356237309504880 * hi;       // t > tan(pi/8)
  const double t = upper ? (lo - hi) / (lo + hi) : lo / hi;
  constexpr double c0 = 0.99999999999999996532, c1 = -0.33333333333328438572, c2 = 0.19999999998855110134,
                   c3 = -0.14285714180976466830, c4 = 0.11111106180455945220, c5 = -0.090907730748084137897,
                   c6 = 0.076899534963068577563, c7 = -0.066402339304294085887, c8 = 0.056883492268090104794,
                   c9 = -0.043480522157164624777, c10 = 0.021135373157693245206;
  const double s = t * t, s2 = s * s, s4 = s2 * s2, s8 = s4 * s4;
  const double p =
      (c0 + c1 * s) + s2 * (c2 + c3 * s) + s4 * ((c4 + c5 * s) + s2 * (c6 + c7 * s)) + s8 * ((c8 + c9 * s) + s2 * c10);
  double r = t * p + (upper ? std::numbers::pi / 4 : 0.0);
  if (steep) r = std::numbers::pi / 2 - r;
  if (x < 0) r = std::numbers::pi - r;
  return std::copysign(r, y);
}

// The kernels' atan2 in scalar A for a kernel of scalar T (A = T, or double where a float kernel computes in double):
// a float kernel's by atan2_in_double, rounded once to A; double's and long double's by std::atan2.
template <class A, class T = A> A kernel_atan2(A y, A x) {
  if constexpr (std::is_same_v<T, float>)
    return A(atan2_in_double(y, x));
  else
    return std::atan2(y, x);
}

// ---- a b + c rounded once ----
// std::fma everywhere except x87 long double, which has no FMA instruction: there glibc's fmal saves and restores
// the floating-point environment (~200 ns a call). fused_multiply_add gives the same bits from Dekker's exact
// product (Veltkamp halves of 32 bits) and Boldo & Melquiond's FMA emulation (IEEE TC 2008, Sec. 5: c + a b as
// three exact terms, the low parts summed rounded to odd, then one rounding to nearest). Both steps are exact
// only without overflow and underflow, so operands or a product outside [2^-8000, 2^8000], Inf and NaN take
// std::fma; a zero factor makes the product an exact signed zero (test: FusedMultiplyAdd.*).
inline constexpr bool kX87LongDouble =
#if defined(__x86_64__) || defined(__i386__)
    std::numeric_limits<long double>::digits == 64;
#else
    false;
#endif

namespace detail {
// s + e == a + b exactly (Knuth's TwoSum; no condition on the magnitudes).
inline void two_sum(long double a, long double b, long double& s, long double& e) {
  s = a + b;
  const long double bb = s - a;
  e = (a - (s - bb)) + (b - bb);
}

// a + b rounded to odd: exact, or else the neighbour of a + b whose last significand bit is 1.
inline long double sum_rounded_to_odd(long double a, long double b) {
  long double s, e;
  two_sum(a, b, s, e);
  std::uint64_t significand;
  std::memcpy(&significand, &s, sizeof significand);  // x87: bytes 0-7 hold the 64-bit significand
  if (e == 0 || (significand & 1u)) return s;
  // The neighbour towards a + b, by the significand's last bit (0 here, so +-1 neither carries nor borrows),
  // except below a power of two, where the binade changes.
  if ((e > 0) == (s > 0))
    significand |= 1u;
  else if (significand != (std::uint64_t(1) << 63))
    significand -= 1u;
  else
    return std::nextafter(
        s, e > 0 ? std::numeric_limits<long double>::infinity() : -std::numeric_limits<long double>::infinity());
  std::memcpy(&s, &significand, sizeof significand);
  return s;
}

// p + error == a b exactly, p = fl(a b) (Dekker 1971 with Veltkamp's split into halves of 32 bits).
inline long double exact_product_error(long double a, long double b, long double p) {
  constexpr long double kSplit = 0x1p32L + 1;
  const long double ta = kSplit * a, tb = kSplit * b;
  const long double ah = ta - (ta - a), al = a - ah, bh = tb - (tb - b), bl = b - bh;
  return al * bl - (((p - ah * bh) - al * bh) - ah * bl);
}

// The range where the steps above are exact: magnitudes in (2^-8000, 2^8000) (NaN is outside).
inline bool within_exact_range(long double x) {
  const long double ax = std::abs(x);
  return ax > 0x1p-8000L && ax < 0x1p8000L;
}
inline bool below_exact_bound(long double a, long double b) {
  return std::abs(a) < 0x1p8000L && std::abs(b) < 0x1p8000L;
}
// A finite product with a zero factor: exactly a signed zero.
inline bool exact_zero_product(long double a, long double b) {
  return (a == 0 || b == 0) && std::isfinite(a) && std::isfinite(b);
}
}  // namespace detail

// c - a b where c = fl(a b): the product's rounding error, negated, as fused_multiply_add(-a, b, c) gives it.
template <class T> T negated_product_error(T a, T b, T c) {
  if constexpr (std::is_same_v<T, long double> && kX87LongDouble) {
    // c = fl(a b) is a zero, and -a b the zero of the other sign: their sum is +0.
    if (detail::exact_zero_product(a, b)) return 0.0L;
    if (detail::within_exact_range(c) && detail::below_exact_bound(a, b)) {
      const long double e = detail::exact_product_error(a, b, c);
      return e == 0 ? 0.0L : -e;  // an exact zero sum is +0 when rounding to nearest
    }
  }
  return std::fma(-a, b, c);
}

template <class T> T fused_multiply_add(T a, T b, T c) {
  if constexpr (std::is_same_v<T, long double> && kX87LongDouble) {
    const long double p = a * b;
    if (detail::exact_zero_product(a, b)) return c + p;
    if (detail::within_exact_range(p) && detail::below_exact_bound(a, b) && (c == 0 || detail::within_exact_range(c))) {
      long double th, tl;
      detail::two_sum(c, p, th, tl);
      return th + detail::sum_rounded_to_odd(tl, detail::exact_product_error(a, b, p));
    }
  }
  return std::fma(a, b, c);
}

// ---- sin and cos in radians ----
// std::sin and std::cos, except x87 long double with pi/4 < |x| < 2^12: glibc reduces every such argument by the
// Payne-Hanek method (~250 ns a call). There x - k pi/2 is taken by Cody & Waite with pi/2 = P1 + P2 + P3: k P1 and
// k P2 are exact (P1 and P2 hold 50 bits, k < 2^12), x - k P1 is exact (Sterbenz), and P3's truncation leaves
// 2^-170 k; then sin or cos of |r| <= pi/4 on glibc's fast path. Within 1.5 ulps of a 50-digit reference, as
// sinl and cosl are, not always their bits (test: SineCosine.*).
namespace detail {
inline long double quarter_turns(long double x, long long& k) {
  constexpr long double two_over_pi = 0xa2f9836e4e44152ap-64L;
  constexpr long double p1 = 0xc90fdaa22168c000p-63L, p2 = 0x8d313198a2e04000p-117L, p3 = -0x8f8cbb5bf6c7ddd6p-169L;
  k = std::llrint(x * two_over_pi);
  const long double kk = static_cast<long double>(k);
  return ((x - kk * p1) - kk * p2) - kk * p3;
}
inline bool reduce_for_sine_cosine(long double x) {
  const long double ax = std::abs(x);
  return ax > 0.78539816339744830962L && ax < 0x1p12L;
}

// sin(x + shift pi/2): shift 0 gives sin x, shift 1 cos x.
template <class T> T sine_shifted(T x, int shift) {
  if constexpr (std::is_same_v<T, long double> && kX87LongDouble) {
    if (detail::reduce_for_sine_cosine(x)) {
      long long k;
      const long double r = detail::quarter_turns(x, k);
      switch ((k + shift) & 3) {
        case 0:
          return std::sin(r);
        case 1:
          return std::cos(r);
        case 2:
          return -std::sin(r);
        default:
          return -std::cos(r);
      }
    }
  }
  return shift ? std::cos(x) : std::sin(x);
}
}  // namespace detail

template <class T> T sine(T x) { return detail::sine_shifted(x, 0); }
template <class T> T cosine(T x) { return detail::sine_shifted(x, 1); }

// sin x and cos x together: sine and cosine in float and double; in x87 long double with |x| < 2^12, the argument
// reduced as in sine and one FSINCOS instruction on |r| <= pi/4, where it reduces nothing itself and is within 0.54
// ulp (26 ns for both against 83 for sinl and cosl; test: SineCosine.*).
namespace detail {
inline void x87_sine_cosine(long double r, long double& s, long double& c) {
#if (defined(__x86_64__) || defined(__i386__)) && defined(__GNUC__)
  asm("fsincos" : "=t"(c), "=u"(s) : "0"(r));
#else
  s = std::sin(r), c = std::cos(r);
#endif
}
}  // namespace detail

template <class T> void sine_cosine(T x, T& s, T& c) {
  if constexpr (std::is_same_v<T, long double> && kX87LongDouble) {
    if (std::abs(x) < 0x1p12L) {
      long long k = 0;
      const long double r = detail::reduce_for_sine_cosine(x) ? detail::quarter_turns(x, k) : x;
      long double sr, cr;
      detail::x87_sine_cosine(r, sr, cr);
      switch (k & 3) {  // x = k pi/2 + r
        case 0:
          s = sr, c = cr;
          return;
        case 1:
          s = cr, c = -sr;
          return;
        case 2:
          s = -sr, c = -cr;
          return;
        default:
          s = -cr, c = sr;
          return;
      }
    }
  }
  s = sine(x), c = cosine(x);
}

// 2^e when it is a normal float or double (built from its bits, no library call), else 0.
template <class T> T normal_power_of_two(int e) {
  if (e < std::numeric_limits<T>::min_exponent - 1 || e > std::numeric_limits<T>::max_exponent - 1) return T(0);
  if constexpr (std::is_same_v<T, float>)
    return std::bit_cast<float>(std::uint32_t(e + 127) << 23);
  else if constexpr (std::is_same_v<T, double>)
    return std::bit_cast<double>(std::uint64_t(e + 1023) << 52);
  else
    return T(0);
}

// x * 2^e as std::ldexp gives it: for a normal 2^e one product, whose single rounding (exact unless the result
// over- or underflows) is ldexp's.
template <class T> T scale_by_power_of_two(T x, int e) {
  const T p = normal_power_of_two<T>(e);
  return p != T(0) ? x * p : std::ldexp(x, e);
}

// v * 2^e, exact componentwise (std::ldexp) unless a component over- or underflows.
template <class T> Vec3<T> ldexp(const Vec3<T>& v, int e) {
  const T p = normal_power_of_two<T>(e);
  if (p != T(0)) return v * p;
  return Vec3<T>(std::ldexp(v.x(), e), std::ldexp(v.y(), e), std::ldexp(v.z(), e));
}

// std::max(a, b), a < b ? b : a, returned by value: GCC keeps the temporaries of a nested std::max in memory (it
// returns a reference) and selects among their addresses, a chain of stores and reloads.
template <class T> WARPCHECK_ALWAYS_INLINE T larger(T a, T b) { return a < b ? b : a; }

// Whether 1 / x is finite, for x >= 0 or NaN, without the division: 1 / x rounds to Inf exactly for x <= t =
// 2^-max_exponent (min / 4 in every IEEE format). Near t the numbers are subnormal and more than t 2^-(digits + 1)
// apart, so none lies between t and the overflow threshold t / (1 - 2^-(digits + 1)).
template <class T> bool has_finite_reciprocal(T x) {
  static_assert(std::numeric_limits<T>::is_iec559);
  return x > std::numeric_limits<T>::min() / T(4);
}

// max_i |v_i|: Eigen's cwiseAbs().maxCoeff() in its order, max(|x|, max(|y|, |z|)), so the same value (NaN
// included), but inline where GCC leaves Eigen's reduction as a call.
template <class T> WARPCHECK_ALWAYS_INLINE T max_abs(const Vec3<T>& v) {
  return larger(std::abs(v.x()), larger(std::abs(v.y()), std::abs(v.z())));
}

// |v| without overflow or underflow: m sqrt((x s)^2 + (y s)^2 + (z s)^2), m = max |v_i|, s = 1 / m (Eigen's
// stableNorm of a vector taken as one block, its special cases included). Eigen's own stableNorm splits a 3-vector
// into blocks by its address (alignment), which changes the rounding; this one does not depend on where v lies.
template <class T> WARPCHECK_ALWAYS_INLINE T stable_norm(const Vec3<T>& v) {
  const T m = larger(larger(std::abs(v.x()), std::abs(v.y())), std::abs(v.z()));
  if (m == T(0)) return T(0);
  T inv = T(1) / m, scale = m;
  if (inv > std::numeric_limits<T>::max())  // a subnormal m whose reciprocal overflows
    inv = std::numeric_limits<T>::max(), scale = T(1) / inv;
  else if (m > std::numeric_limits<T>::max())  // an infinite entry: Inf (or NaN)
    inv = T(1);
  const T a = v.x() * inv, b = v.y() * inv, c = v.z() * inv;
  return scale * std::sqrt(a * a + b * b + c * c);
}

// Renormalises a direction that is a unit vector up to rounding (a sampler's output): one division and three
// products instead of normalized()'s three divisions. Not for vectors that may be 0 or huge.
template <class T> Vec3<T> renormalized(const Vec3<T>& v) { return v * (T(1) / v.norm()); }

// The factor that renormalises a vector of squared length n2 near 1 without a square root or division: one Newton
// step of 1 / sqrt at 1, (3 - n2) / 2, error 3/8 (n2 - 1)^2 (< 2.2e-8 for |n2 - 1| <= 2^-12); else 1 / sqrt(n2).
template <class T> T near_unit_renormalization_factor(T n2) {
  if (!(std::abs(n2 - T(1)) <= T(0x1p-12))) return T(1) / std::sqrt(n2);
  return (T(3) - n2) * T(0.5);
}

// Normalises a shading normal; returns false for zero, subnormal-length or non-finite normals.
template <class T> WARPCHECK_ALWAYS_INLINE bool normalize_normal(const Vec3<T>& n, Vec3<T>& out) {
  if (!all_finite(n)) return false;
  const T len = stable_norm(n);
  if (!(len > std::numeric_limits<T>::min()) || !std::isfinite(len)) return false;
  out = n / len;
  return std::isfinite(out.x()) && std::isfinite(out.y()) && std::isfinite(out.z());
}

template <class T> constexpr T kPi = std::numbers::pi_v<T>;
template <class T> constexpr T kTwoPi = T(2) * std::numbers::pi_v<T>;

}  // namespace warpcheck
