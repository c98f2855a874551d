// fuzz/checks/common.h: what every fuzz target shares: input decoding that leans towards degenerate geometry, an
// independent long double reference for "is this direction inside the light", and the invariant checks. A target
// fuzzes one kernel of the catalogue (lib/warpcheck/catalogue.h): the header fuzz/targets/<kernel name>.h
// specialises FuzzTarget for the kernel's trait with
//   template <class T> static void check(FuzzedDataProvider& in);
// which decodes one input and throws InvariantViolation when the kernel breaks an invariant. The libFuzzer entry
// (fuzz/entry.h) turns that into a crash report; the g++ replay driver (fuzz/replay.cpp) into a failed ctest. The
// checks of a family of kernels live in fuzz/checks/<family>.h. See fuzz/README.md for the targets, the campaign
// script and the triage of findings.
//
// Decoding (FuzzedDataProvider's ConsumeFloatingPoint never yields NaN, Inf or subnormals, so it is not used). Every
// scalar starts with a mode byte: a table of special values (signed zeros, 1 +- ulp, epsilon, the smallest
// normal and subnormal, the largest finite, Inf, NaN, ...), a small integer (exact coincidences: coplanar
// vertices, collinear points, zero-length edges), raw bits of T, or a moderate value. Geometry is then built
// from these by constructions that land on degenerate configurations exactly (the shading point on the light,
// in its plane, on an edge's line, a normal perpendicular to the light, an edge through the zenith, ...), with
// an optional tiny offset off the degeneracy.
//
// Order. Every value is decoded in its own statement (or in a declaration list, or a comma expression, which are
// sequenced): the order in which the operands of one expression or the arguments of one call are evaluated is
// unspecified, and g++ (right to left) and clang (left to right) differ, so an input that libFuzzer (clang) found
// would decode to another geometry in the g++ replay.
//
// Tolerances (the geometry's conditioning). A kernel in precision T first forms differences V - x of world
// coordinates; each carries an absolute rounding error of about eps_T (|V|_inf + |x|_inf), i.e. an angular
// error of eps_T (|V|_inf + |x|_inf) / |V - x| in the direction of V seen from x. A point of a polygon whose
// vertices are moved by at most delta lies within delta of the exact polygon (a convex combination of the
// moved vertices is the convex combination of the exact ones plus a combination of moves), and the sampling
// arithmetic itself adds a few tens of ulps. We therefore accept a direction as inside the light when its
// angular distance to the light's boundary (measured conservatively: the distance to every bounding great
// circle, resp. the ray's miss distance over d for a sphere) is at most
//     tol = kTolUlps * eps_T * kappa,   kappa = max(1, max_k (|V_k|_inf + |x|_inf + 16 min_T) / |V_k - x|)
// (for a sphere, V is the centre and |V - x| = d, kappa = max(1, (|c|_inf + |x|_inf) / d)), kTolUlps = 64.
// kappa grows without bound for a shading point close to a vertex relative to the coordinates' magnitude: that
// is exactly when the input coordinates themselves no longer determine the direction. The reference is
// computed in long double from the exact T inputs (exact conversion; the edge normals by Kahan's
// cancellation-free cross products of V_j - x and V_{j+1} - V_j).
#pragma once

// g++ builds (the replay driver) name the header's installed path in WARPCHECK_FDP_HEADER rather than putting
// clang's resource include directory on the path (its stddef.h breaks GCC).
#ifdef WARPCHECK_FDP_HEADER
#include WARPCHECK_FDP_HEADER
#else
#include <fuzzer/FuzzedDataProvider.h>
#endif

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>

#include "warpcheck/catalogue.h"
#include "warpcheck/core.h"
#include "warpcheck/polygon.h"

namespace warpcheck::fuzz {

inline constexpr double kTolUlps = 64;

// The fuzz target of the catalogue kernel K (a trait of lib/warpcheck/catalogue.h), specialised in
// fuzz/targets/<K's name>.h. Its name, fuzz_<K's name>_<T>, comes from the trait.
template <template <class> class K> struct FuzzTarget;

// Asserts that the target header fuzz/targets/<file_name>.h is named after its kernel: the trait (found from the
// file's name in CamelCase, fuzz/CMakeLists.txt) carries that name, and the catalogue lists it.
#define WARPCHECK_FUZZ_ASSERT_NAMED(file_name, Trait)                                                                  \
  static_assert(                                                                                                       \
      std::string_view(::warpcheck::Trait<double>::name) == file_name && ::warpcheck::AllKernels::contains(file_name), \
      "fuzz/targets/" file_name ".h must be named after a kernel of lib/warpcheck/catalogue.h")

struct InvariantViolation : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Formats the message and throws. `what` names the invariant; the stream gets the geometry.
#define WARPCHECK_FUZZ_REQUIRE(cond, what, details)                                                                   \
  do {                                                                                                                \
    if (!(cond)) {                                                                                                    \
      std::ostringstream warpcheck_fuzz_os;                                                                           \
      warpcheck_fuzz_os.precision(21);                                                                                \
      warpcheck_fuzz_os << "warpcheck invariant violated: " << (what) << " [" << __FILE__ << ":" << __LINE__ << "]\n" \
                        << details;                                                                                   \
      throw ::warpcheck::fuzz::InvariantViolation(warpcheck_fuzz_os.str());                                           \
    }                                                                                                                 \
  } while (0)

template <class T> std::string show(const Vec3<T>& v) {
  std::ostringstream os;
  os.precision(std::numeric_limits<T>::max_digits10);
  os << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
  return os.str();
}

// ---- Decoding --------------------------------------------------------------------------------------------

template <class T> T from_bits(FuzzedDataProvider& in) {
  T t;
  if constexpr (sizeof(T) == 4) {
    const auto b = in.ConsumeIntegral<std::uint32_t>();
    std::memcpy(&t, &b, 4);
  } else {
    const auto b = in.ConsumeIntegral<std::uint64_t>();
    std::memcpy(&t, &b, 8);
  }
  return t;
}

// Whether NaN and Inf may be produced. Off in the FE_INVALID trapping build: comparisons with NaN raise
// FE_INVALID themselves, so that build hunts NaNs born inside the kernels from finite input.
#ifdef WARPCHECK_FUZZ_TRAP_FP
inline constexpr bool kAllowNonFinite = false;
#else
inline constexpr bool kAllowNonFinite = true;
#endif

template <class T> T finite_or_zero(T t) { return kAllowNonFinite || std::isfinite(t) ? t : T(0); }

template <class T> T special_value(std::uint8_t i) {
  using L = std::numeric_limits<T>;
  const T table[] = {T(0),
                     -T(0),
                     T(1),
                     T(-1),
                     T(0.5),
                     T(2),
                     T(-2),
                     L::epsilon(),
                     -L::epsilon(),
                     T(1) + L::epsilon(),
                     T(1) - L::epsilon() / 2,
                     L::min(),
                     -L::min(),
                     L::denorm_min(),
                     -L::denorm_min(),
                     L::max(),
                     L::lowest(),
                     std::sqrt(L::max()),
                     std::sqrt(L::min()),
                     T(1e-30f),
                     T(1e30f),
                     L::infinity(),
                     -L::infinity(),
                     L::quiet_NaN(),
                     -L::quiet_NaN()};
  return finite_or_zero(table[i % (sizeof(table) / sizeof(table[0]))]);
}

// A scalar of roughly `scale`, leaning towards special values and exact small integers.
template <class T> T scalar(FuzzedDataProvider& in, T scale = T(1)) {
  const std::uint8_t mode = in.ConsumeIntegral<std::uint8_t>();
  if (mode < 24) return special_value<T>(in.ConsumeIntegral<std::uint8_t>());
  if (mode < 96) return scale * T(in.ConsumeIntegralInRange<int>(-4, 4));
  if (mode < 120) return finite_or_zero(from_bits<T>(in));
  if (mode < 136) {
    const T mantissa = T(in.ConsumeIntegralInRange<int>(-8, 8));  // before the exponent (see "Order" above)
    return scale * std::ldexp(mantissa, in.ConsumeIntegralInRange<int>(-160, 160));
  }
  // Moderate: 16 bits spread over [-4, 4] scale.
  return scale * (T(in.ConsumeIntegral<std::uint16_t>()) / T(8192) - T(4));
}

template <class T> Vec3<T> vec3(FuzzedDataProvider& in, T scale = T(1)) {
  const T x = scalar<T>(in, scale), y = scalar<T>(in, scale), z = scalar<T>(in, scale);
  return Vec3<T>(x, y, z);
}

// A tiny signed offset (possibly exactly zero), relative to `scale`: moves a construction just off (or keeps
// it exactly on) its degeneracy.
template <class T> T tiny(FuzzedDataProvider& in, T scale) {
  const std::uint8_t mode = in.ConsumeIntegral<std::uint8_t>();
  if (mode < 64) return T(0);
  const T sign = (mode & 1) ? T(1) : T(-1);
  const int e = in.ConsumeIntegralInRange<int>(-std::numeric_limits<T>::digits - 8, 0);
  return finite_or_zero(sign * std::ldexp(scale, e));
}

// A random number in [0, 1), leaning towards 0, the smallest positive values and 1 - ulp.
template <class T> T unit_random(FuzzedDataProvider& in) {
  const std::uint8_t mode = in.ConsumeIntegral<std::uint8_t>();
  const int digits = std::numeric_limits<T>::digits;
  switch (mode % 8) {
    case 0:
      return T(0);
    case 1:
      return T(1) - std::numeric_limits<T>::epsilon() / 2;  // the largest value below 1
    case 2:
      return std::ldexp(T(1), -in.ConsumeIntegralInRange<int>(1, digits + 100));
    case 3:
      return T(1) - std::ldexp(T(1), -in.ConsumeIntegralInRange<int>(1, digits));
    default: {
      const std::uint64_t b = in.ConsumeIntegral<std::uint64_t>() >> (64 - digits);
      return std::ldexp(T(b), -digits);
    }
  }
}

template <class T> Vec2<T> unit_square(FuzzedDataProvider& in) {
  const T a = unit_random<T>(in), b = unit_random<T>(in);
  return Vec2<T>(a, b);
}

// A unit-ish vector orthogonal to n (any, if n is zero), rotated by a decoded angle.
template <class T> Vec3<T> perpendicular(FuzzedDataProvider& in, const Vec3<T>& n) {
  const Vec3<T> nn = safe_normalized(n);
  if (nn.isZero()) return Vec3<T>(T(1), T(0), T(0));
  const Frame<T> f = Frame<T>::from_z(nn);
  const T phi = kTwoPi<T> * unit_random<T>(in);
  return std::cos(phi) * f.x + std::sin(phi) * f.y;
}

// A point near p: p + v t, with v a decoded vector (unit scale) and t a tiny offset relative to `scale`, decoded
// in that order.
template <class T> Vec3<T> near(FuzzedDataProvider& in, const Vec3<T>& p, T scale = T(1)) {
  const Vec3<T> v = vec3<T>(in, T(1));
  return p + v * tiny<T>(in, scale);
}

// ---- Polygons leaning towards degeneracy -------------------------------------------------------------------

// A polygon: raw vertices (often invalid), a convex polygon from sorted angles on an ellipse (coincident
// angles give zero-length edges, close ones nearly collinear vertices), or a rectangle.
template <class T> PolygonLight<T> decode_polygon(FuzzedDataProvider& in, bool rectangle_bias = false) {
  PolygonLight<T> p;
  const std::uint8_t mode = in.ConsumeIntegral<std::uint8_t>();
  const T scale = scalar<T>(in);
  const T s = std::isfinite(scale) && scale != T(0) ? std::abs(scale) : T(1);
  if (mode < 32 && !rectangle_bias) {  // raw vertices
    p.count = in.ConsumeIntegralInRange<int>(0, kMaxPolygonVertices + 1);
    for (int i = 0; i < std::min(p.count, kMaxPolygonVertices); ++i) p.vertices[i] = vec3<T>(in, s);
    return p;
  }
  const Vec3<T> c = vec3<T>(in, s);
  Vec3<T> a = vec3<T>(in, s), b = vec3<T>(in, s);
  if (rectangle_bias || mode < 96) {  // rectangle: b made orthogonal to a
    const T aa = a.squaredNorm();
    if (aa > T(0) && std::isfinite(aa)) b = b - (b.dot(a) / aa) * a;
    p.count = 4;
    p.vertices[0] = c;
    p.vertices[1] = c + a;
    p.vertices[2] = c + a + b;
    p.vertices[3] = c + b;
    return p;
  }
  // Convex polygon on the ellipse c + cos(t) a + sin(t) b, angles sorted.
  const int n = in.ConsumeIntegralInRange<int>(3, kMaxPolygonVertices);
  T t[kMaxPolygonVertices];
  const bool regular = in.ConsumeBool();
  T acc = 0;
  for (int i = 0; i < n; ++i) {
    T step = T(1);
    if (!regular) {
      const T whole = T(in.ConsumeIntegralInRange<int>(0, 255));
      step = whole + tiny<T>(in, T(1));
    }
    t[i] = acc;
    acc += std::max(T(0), step);
  }
  const T total = acc > T(0) ? acc : T(1);
  for (int i = 0; i < n; ++i) {
    const T angle = kTwoPi<T> * t[i] / total;
    p.vertices[i] = c + std::cos(angle) * a + std::sin(angle) * b;
  }
  p.count = n;
  return p;
}

template <class T> Vec3<T> polygon_centroid(const PolygonLight<T>& p) {
  Vec3<T> c = Vec3<T>::Zero();
  const int n = std::clamp(p.count, 1, kMaxPolygonVertices);
  for (int i = 0; i < n; ++i) c += p.vertices[i] / T(n);
  return c;
}

// A shading point and normal for a polygon, leaning towards: on the light, in its plane, on an edge's line,
// at a vertex, far away; normals raw, equal to the light's normal, perpendicular to the direction to the
// light, putting a vertex on the horizon, or making an edge pass through the zenith.
template <class T> ShadingPoint<T> decode_polygon_shading(FuzzedDataProvider& in, const PolygonLight<T>& p) {
  ShadingPoint<T> sp;
  const int n = std::clamp(p.count, 1, kMaxPolygonVertices);
  const int j = in.ConsumeIntegralInRange<int>(0, n - 1), j1 = (j + 1) % n;
  const Vec3<T> area = p.count >= 3 && p.count <= kMaxPolygonVertices ? polygon_area_vector(p) : Vec3<T>::Zero();
  const Vec3<T> nhat = safe_normalized(area);
  const T size = (p.vertices[j1] - p.vertices[j]).norm();
  const T sz = std::isfinite(size) && size > T(0) ? size : T(1);
  switch (in.ConsumeIntegralInRange<int>(0, 7)) {
    case 0:
      sp.position = vec3<T>(in, sz);
      break;
    case 1: {  // on the light (a convex combination), possibly just off its plane
      const T w = unit_random<T>(in);
      sp.position = polygon_centroid(p) * (T(1) - w) + p.vertices[j] * w + nhat * tiny<T>(in, sz);
      break;
    }
    case 2: {  // on the line of edge j, possibly just off it
      const T t = scalar<T>(in);
      const T off_plane = tiny<T>(in, sz);
      const Vec3<T> side = perpendicular(in, nhat);
      sp.position = p.vertices[j] + t * (p.vertices[j1] - p.vertices[j]) + nhat * off_plane + side * tiny<T>(in, sz);
      break;
    }
    case 3:
      sp.position = near(in, p.vertices[j], sz);
      break;  // at a vertex
    case 4:
      sp.position = polygon_centroid(p) + nhat * scalar<T>(in, sz);
      break;  // on the axis
    case 5: {
      const Vec3<T> d = vec3<T>(in, sz);
      sp.position = polygon_centroid(p) + d * std::ldexp(T(1), in.ConsumeIntegralInRange<int>(0, 120));
      break;
    }
    default:
      sp.position = polygon_centroid(p) + vec3<T>(in, sz);
      break;
  }
  const Vec3<T> to_light = polygon_centroid(p) - sp.position;
  switch (in.ConsumeIntegralInRange<int>(0, 6)) {
    case 0:
      sp.normal = vec3<T>(in);
      break;
    case 1:
      sp.normal = nhat * scalar<T>(in);
      break;
    case 2:
      sp.normal = perpendicular(in, to_light);
      break;
    case 3:
      sp.normal = perpendicular(in, Vec3<T>(p.vertices[j] - sp.position));
      break;   // vertex j on the horizon
    case 4: {  // the great circle of edge j passes through the zenith
      const T a = scalar<T>(in), b = scalar<T>(in);
      sp.normal = a * (p.vertices[j] - sp.position) + b * (p.vertices[j1] - sp.position);
      break;
    }
    case 5:
      sp.normal = perpendicular(in, nhat);
      break;  // the light's plane contains the normal
    default:
      sp.normal = near(in, safe_normalized(to_light));
      break;
  }
  return sp;
}

// ---- Reference geometry in long double ----------------------------------------------------------------------

using L = long double;

inline bool any_nonfinite(std::initializer_list<L> xs) {
  for (L x : xs)
    if (!std::isfinite(x)) return true;
  return false;
}

template <class T> L eps() { return L(std::numeric_limits<T>::epsilon()); }

// Below the smallest normal number min_T, rounding is absolute: every subnormal intermediate carries an error
// of up to denorm_min / 2 = eps_T min_T / 2. We allow kSubnormalUlps of them per coordinate, i.e. we add
// kSubnormalUlps min_T to the magnitudes in kappa.
inline constexpr long double kSubnormalUlps = 16;

// kappa = max(1, max_k (|V_k|_inf + |x|_inf + kSubnormalUlps min_T) / |V_k - x|) over the given points (see the
// header comment). P: the points' type (T, or L for points computed in long double); T: the kernel's precision.
// subnormal_ulps: kSubnormalUlps, or 0 for a kernel that rescales V - x by a power of two before any other
// arithmetic (no subnormal intermediate from the coordinates' magnitude; the caller derives it).
template <class P, class T = P>
L kappa_of(const Vec3<P>* v, int n, const Vec3<P>& x, L subnormal_ulps = kSubnormalUlps) {
  L k = 1;
  const Vec3<L> xl = x.template cast<L>();
  for (int i = 0; i < n; ++i) {
    const Vec3<L> vl = v[i].template cast<L>();
    const L dist = (vl - xl).norm();
    const L mag =
        vl.cwiseAbs().maxCoeff() + xl.cwiseAbs().maxCoeff() + subnormal_ulps * L(std::numeric_limits<T>::min());
    k = std::max(k, dist > 0 ? mag / dist : std::numeric_limits<L>::infinity());
  }
  return k;
}

// Signed angular distances of a unit direction w from the great circles bounding the cone of a convex polygon
// seen from x (positive inside), in long double; returns the minimum. Also the side of the light's plane.
// (The polygon's own edges: for a sliver accepted by check_polygon but reflex at the rounding level this is
// not the cone of its convex hull; a hull in the noise plane of such a sliver is not meaningful either, see
// fuzz/README.md, "Known limits".)
// P: the vertices' type (T, or L for a displaced light computed in long double); T: the kernel's precision.
// edges: the edge vectors V_{j+1} - V_j if the caller has them more accurately than the vertices' difference (a
// displaced light whose vertices are rounded, polygon.h); null: the difference.
template <class P, class T = P>
L polygon_cone_margin(const PolygonLight<P>& p, const Vec3<P>& x, const Vec3<P>& w, const Vec3<L>* edges = nullptr) {
  const int n = p.count;
  const Vec3<L> xl = x.template cast<L>(), wl = w.template cast<L>().normalized();
  Vec3<L> area = Vec3<L>::Zero();
  const Vec3<L> v0 = p.vertices[0].template cast<L>();
  for (int i = 1; i + 1 < n; ++i)
    area += kahan_cross<L>(Vec3<L>(p.vertices[i].template cast<L>() - v0),
                           Vec3<L>(p.vertices[i + 1].template cast<L>() - v0));
  const L h = area.dot(Vec3<L>(v0 - xl));
  auto margin_for = [&](L orient) {
    L margin = std::numeric_limits<L>::infinity();
    for (int j = 0; j < n; ++j) {
      const Vec3<L> pj = p.vertices[j].template cast<L>() - xl;
      const Vec3<L> ej =
          edges ? edges[j] : Vec3<L>(p.vertices[(j + 1) % n].template cast<L>() - p.vertices[j].template cast<L>());
      const Vec3<L> m = kahan_cross<L>(pj, ej);  // = p_j x p_{j+1}
      const L mn = m.norm();
      if (!(mn > 0)) continue;  // x on the edge's line: that bound is undetermined
      margin = std::min(margin, orient * m.dot(wl) / mn);
    }
    // The cone test alone accepts -w for a polygon seen nearly edge-on; w must also point towards the plane.
    const L an = area.norm();
    if (an > 0) margin = std::min(margin, orient * area.dot(wl) / an);
    return margin;
  };
  // Which side of the light x is on is undetermined by T's arithmetic when the plane distance is below the
  // rounding of the coordinates, kTolUlps eps_T (max_k |V_k|_inf + |x|_inf): the light then faces either way
  // (from a point on the light it covers a whole hemisphere, and which one flips with a rounding error), so
  // either orientation is accepted.
  L mag = xl.cwiseAbs().maxCoeff();
  for (int j = 0; j < n; ++j)
    mag = std::max(mag, L(p.vertices[j].template cast<L>().cwiseAbs().maxCoeff()) + xl.cwiseAbs().maxCoeff());
  const L an = area.norm();
  if (an > 0 && std::abs(h) / an <= L(kTolUlps) * eps<T>() * (mag + kSubnormalUlps * L(std::numeric_limits<T>::min())))
    return std::max(margin_for(L(1)), margin_for(L(-1)));
  return margin_for(h >= 0 ? L(1) : L(-1));
}

// ---- The invariants ------------------------------------------------------------------------------------------

// A valid sample: finite unit direction and finite positive pdf; an invalid one: zero direction and pdf.
template <class T> void check_sample_shape(const DirectionSample<T>& s, const std::string& geometry) {
  if (!s.valid()) {
    WARPCHECK_FUZZ_REQUIRE(s.pdf == T(0) && s.direction.isZero(), "no-sample carries a direction or pdf",
                           geometry << "reason " << to_string(s.reason) << " pdf " << s.pdf << "\n");
    return;
  }
  WARPCHECK_FUZZ_REQUIRE(all_finite(s.direction), "non-finite direction",
                         geometry << "direction " << show(s.direction) << "\n");
  const L len = s.direction.template cast<L>().norm();
  WARPCHECK_FUZZ_REQUIRE(std::abs(len - 1) <= 16 * eps<T>(), "direction not unit",
                         geometry << "direction " << show(s.direction) << " |w| - 1 = " << (len - 1) << "\n");
  WARPCHECK_FUZZ_REQUIRE(std::isfinite(s.pdf) && s.pdf > T(0), "pdf not finite and positive",
                         geometry << "pdf " << s.pdf << "\n");
}

// pdf(direction) of the kernel, compared with the sample's pdf to relative tolerance `rel`, or 0 when the
// direction is within `tol` of the boundary (margin: the reference's signed angular distance, > 0 inside).
template <class T>
void check_pdf_consistency(T sample_pdf, T eval_pdf, L rel, L margin, L tol, const std::string& geometry) {
  WARPCHECK_FUZZ_REQUIRE(std::isfinite(eval_pdf) && eval_pdf >= T(0), "pdf(direction) not finite and >= 0",
                         geometry << "pdf(direction) " << eval_pdf << "\n");
  if (eval_pdf == T(0)) {
    // 0 is allowed near the boundary, and where the conditioning allows a relative error of 100 %.
    WARPCHECK_FUZZ_REQUIRE(margin <= tol || rel >= 1, "pdf(direction) is 0 for a direction well inside the light",
                           geometry << "sample pdf " << sample_pdf << " margin " << margin << " tol " << tol << "\n");
    return;
  }
  if (rel >= L(0.5)) return;  // the comparison carries no information at this conditioning
  const L ratio = L(eval_pdf) / L(sample_pdf);
  WARPCHECK_FUZZ_REQUIRE(std::abs(ratio - 1) <= rel, "pdf(direction) disagrees with the sample's pdf",
                         geometry << "sample pdf " << sample_pdf << " pdf(direction) " << eval_pdf << " ratio - 1 "
                                  << (ratio - 1) << " allowed " << rel << "\n");
}

// pdf(direction) of a kernel whose density is only piecewise smooth (pieces of a warp meeting along seams,
// folds where two branches reach a direction, the support's boundary), against the sample's pdf. The kernel
// evaluates its density at a direction that rounding has moved by up to a backward error `delta` (an angle,
// derived by the caller) from the one its sampler meant, so the two values agree only up to the density's
// variation within delta: a cosine near the horizon varies by delta / cos, and within delta of a jump the
// variation is the jump itself. We measure that variation: pdf at w and at four probes at angle delta from w
// (+- two orthogonal tangents), V = max_k |pdf(probe_k) / pdf(w) - 1|. Over the disk of radius delta a linear
// density varies by at most sqrt(2) times what the four probes show; the sample's pdf must agree with pdf(w) to
// 2 V plus the relative rounding `rel` of the density formulas. A density off by 1 % fails wherever it varies by
// less than 0.5 % within delta, i.e. everywhere except within delta of a jump. pdf(w) = 0: allowed within tol of
// the light's boundary (margin <= tol, as in check_pdf_consistency) or when a probe is not 0 (within delta of
// the support's edge). With delta >= 1/2 rad the comparison carries no information.
template <class T, class Pdf> void check_pdf_consistency_probed(T sample_pdf, const Vec3<T>& w, Pdf&& pdf, L delta,
                                                                L rel, L margin, L tol, const std::string& geometry) {
  const T p0 = pdf(w);
  WARPCHECK_FUZZ_REQUIRE(std::isfinite(p0) && p0 >= T(0), "pdf(direction) not finite and >= 0",
                         geometry << "pdf(direction) " << p0 << "\n");
  if (!(delta < L(0.5))) return;
  const Vec3<L> wl = w.template cast<L>().normalized();
  const Frame<L> f = Frame<L>::from_z(wl);
  T probes[4];
  L hi = 0, variation = 0;
  for (int k = 0; k < 4; ++k) {
    const Vec3<L> t = (k % 2 == 0 ? f.x : f.y) * (k < 2 ? delta : -delta);
    const Vec3<T> wk = Vec3<L>((wl + t).normalized()).template cast<T>();
    probes[k] = pdf(wk);
    WARPCHECK_FUZZ_REQUIRE(std::isfinite(probes[k]) && probes[k] >= T(0), "pdf(direction) not finite and >= 0",
                           geometry << "pdf at probe " << show(wk) << ": " << probes[k] << "\n");
    hi = std::max(hi, L(probes[k]));
    if (p0 > T(0)) variation = std::max(variation, std::abs(L(probes[k]) / L(p0) - 1));
  }
  if (p0 == T(0)) {
    WARPCHECK_FUZZ_REQUIRE(margin <= tol || hi > 0, "pdf(direction) is 0 around a direction well inside the light",
                           geometry << "sample pdf " << sample_pdf << " margin " << margin << " tol " << tol
                                    << " probe radius " << delta << "\n");
    return;
  }
  const L allowed = 2 * variation + rel;
  if (allowed >= L(0.5)) return;
  const L ratio = L(sample_pdf) / L(p0);
  WARPCHECK_FUZZ_REQUIRE(std::abs(ratio - 1) <= allowed, "pdf(direction) disagrees with the sample's pdf",
                         geometry << "sample pdf " << sample_pdf << " pdf(direction) " << p0 << " ratio - 1 "
                                  << (ratio - 1) << " allowed " << allowed << " (probes " << probes[0] << " "
                                  << probes[1] << " " << probes[2] << " " << probes[3] << " at radius " << delta
                                  << ")\n");
}

// ---- Negative controls ---------------------------------------------------------------------------------------

// A deliberately broken kernel, for the negative controls (fuzz/tests/test_fuzz_checks.cpp): the families that
// take a Mutation apply it to every sample the kernel returns and to every pdf(direction) value before the
// checks see them, and to the normalising constants their view-level checks compare with a reference. The
// libFuzzer targets and the replay use the default, kNone.
struct Mutation {
  enum Kind {
    kNone,
    kSamplePdfTimes1_01,
    kSampleDirectionNegated,
    kPdfTimes1_01,
    kNormaliserTimes1_01,
    kTransformedVertexTurned  // LTC only: every vertex of the kernel's M^-1 P turned by 1e-3 rad
  } kind = kNone;
  template <class T> DirectionSample<T> sample(DirectionSample<T> s) const {
    if (!s.valid()) return s;
    if (kind == kSamplePdfTimes1_01) s.pdf *= T(1.01);
    if (kind == kSampleDirectionNegated) s.direction = -s.direction;
    return s;
  }
  template <class T> T pdf(T p) const { return kind == kPdfTimes1_01 ? p * T(1.01) : p; }
  // A light's normalising constant as a family's view-level check sees it (e.g. the projected solid angle).
  template <class T> T normaliser(T x) const { return kind == kNormaliserTimes1_01 ? x * T(1.01) : x; }
  // A vertex of a light the kernel transformed (the LTC's M^-1 P), as the family's vertex check sees it: turned
  // by 1e-3 rad about the origin, towards the coordinate axis least aligned with it.
  template <class T> Vec3<T> transformed_vertex(const Vec3<T>& v) const {
    if (kind != kTransformedVertexTurned || !(v.norm() > 0)) return v;
    Vec3<T> axis = Vec3<T>::Zero();
    int k = 0;
    v.cwiseAbs().minCoeff(&k);
    axis[k] = 1;
    const Vec3<T> t = (axis - axis.dot(v) / v.squaredNorm() * v).normalized();
    return v + T(1e-3) * v.norm() * t;
  }
};

}  // namespace warpcheck::fuzz
