// Worst-case searches over whole kernels (searches.h): float and double against their own long double
// instantiation, and the returned pdf against the warp's area element.
//
//  precision-<kernel>-<float|double>-angle     angle (rad) between the T and the long double sample directions
//  precision-<kernel>-<float|double>-backward  backward error in primary sample space: the smallest |du|_inf
//                                              with warp_L(u + du) = direction_T(u), to first order
//  pdf-warp-<kernel>                           |pdf(u) * |dw/du0 x dw/du1| - 1| in long double
//
// Both compare the kernels on the *same* input: the geometry and u are rounded to T first, and the long double
// reference runs on exactly those rounded values, so input rounding (which no kernel can undo) is not
// counted. A point where either instantiation declines to sample is outside the search (NaN): declines are
// the battery's and the fuzzers' business, not an error of a returned sample. u stays 1e-6 away from 0 and 1:
// exactly there the warps reach measure-zero boundaries (zero-area sectors, silhouettes, the poles of polar
// maps) where float and long double may pick different but equally valid boundary points (up to ~1 rad apart).
//
// Derivatives: fourth-order central differences of the long double warp, (-f(+2h) + 8 f(+h) - 8 f(-h) +
// f(-2h)) / 12h. Hand-rolled because Boost.Math's autodiff would need every kernel (Eigen expressions,
// std::atan2, ...) instantiated on its fvar type, which they are not written for. Truncation is O(h^4), rounding
// O(eps_L / h) = 1e-19 / h. For the pdf search we also difference with 2h and call the point unresolved (NaN)
// when the two area elements differ by more than 1e-7 relative (the backward searches apply the same test to
// the whole Jacobian: where it is unresolved the linearised backward error means nothing): that happens where the
// stencil straddles a kink of the warp (a sector or fan-triangle boundary in u0) or approaches a singularity. So
// pdf-warp values below ~1e-7 are at the resolution of the measurement, not of the kernel.
#include <Eigen/Dense>
#include <cmath>
#include <string_view>

#include "searches/objective.h"
#include "warpcheck/catalogue.h"
#include "warpcheck/validation/searches.h"

namespace warpcheck::validation {

namespace {

// ---- Geometry families: parameters -> long double geometry, and rounding to T ---------------------------

// A unit sphere whose centre is at distance d (d / r log-uniform in [1.0001, 1e4]) and elevation e above the
// shading horizon, seen from the origin with normal +z.
struct SphereFamily {
  template <class T> using Geometry = SphereLightGeometry<T>;
  static constexpr const char* what = "sphere lights";
  static std::vector<SearchParameter> parameters() {
    return {{"log10_distance_over_radius", std::log10(1.0001L), 4, "log10(d / r), unit radius"},
            {"elevation_deg", -90, 90, "elevation of the centre above the shading horizon (degrees)"}};
  }
  static Geometry<L> make(std::span<const L> p) {
    const L d = std::pow(L(10), p[0]), e = p[1] * kDeg;
    return {ShadingPoint<L>{Vec3<L>::Zero(), Vec3<L>(0, 0, 1)},
            SphereLight<L>{Vec3<L>(d * std::cos(e), 0, d * std::sin(e)), 1}};
  }
  template <class U, class T> static Geometry<U> cast(const Geometry<T>& g) {
    return {ShadingPoint<U>{g.shading.position.template cast<U>(), g.shading.normal.template cast<U>()},
            SphereLight<U>{g.light.center.template cast<U>(), U(g.light.radius)}};
  }
};

// A w x h rectangle centred at distance D and elevation e, its normal tilted by `tilt` from facing the shading
// point (about an axis at `tilt_azimuth`), spun by `spin` in its plane. Origin, normal +z.
struct RectangleFamily {
  template <class T> using Geometry = PolygonLightGeometry<T>;
  static constexpr const char* what = "rectangles";
  static std::vector<SearchParameter> parameters() {
    return {{"log10_distance", -1, 2, "log10 of the distance to the centre"},
            {"elevation_deg", -30, 90, "elevation of the centre above the shading horizon (degrees)"},
            {"log10_width", -2, 1, "log10 of the width"},
            {"log10_height", -2, 1, "log10 of the height"},
            {"tilt_deg", 0, 89, "angle between the light's normal and the direction to the shading point (degrees)"},
            {"tilt_azimuth_deg", -180, 180, "azimuth of the tilt axis (degrees)"},
            {"spin_deg", 0, 180, "rotation of the rectangle in its plane (degrees)"}};
  }
  static Geometry<L> make(std::span<const L> p) {
    const L D = std::pow(L(10), p[0]), e = p[1] * kDeg, w = std::pow(L(10), p[2]), h = std::pow(L(10), p[3]);
    const Vec3<L> c(D * std::cos(e), 0, D * std::sin(e));
    const Vec3<L> m0 = -c / D;
    const Frame<L> f0 = Frame<L>::from_z(m0);
    const Vec3<L> axis = std::cos(p[5] * kDeg) * f0.x + std::sin(p[5] * kDeg) * f0.y;
    const Vec3<L> m = Eigen::AngleAxis<L>(p[4] * kDeg, axis) * m0;
    const Frame<L> f = Frame<L>::from_z(m.normalized());
    const Vec3<L> a = std::cos(p[6] * kDeg) * f.x + std::sin(p[6] * kDeg) * f.y, b = f.z.cross(a);
    Geometry<L> g;
    g.shading = ShadingPoint<L>{Vec3<L>::Zero(), Vec3<L>(0, 0, 1)};
    g.light = PolygonLight<L>{c - w / 2 * a - h / 2 * b, c + w / 2 * a - h / 2 * b, c + w / 2 * a + h / 2 * b,
                              c - w / 2 * a + h / 2 * b};
    return g;
  }
  template <class U, class T> static Geometry<U> cast(const Geometry<T>& g) { return g.template cast<U>(); }
};

// An SPTD cap (Dupuy et al. 2017, lib/warpcheck/sptd.h): its pivot |r_p| <= 0.95 in any direction, and a cap of
// half-angle alpha about any axis (the base density is the kernel's). (The cap invariance of the transform itself
// is the search sptd-cap-invariance in caps.cpp.)
struct SptdCapFamily {
  template <class T> using Geometry = SptdCapGeometry<T>;
  static constexpr const char* what = "caps";
  static std::vector<SearchParameter> parameters() {
    const L pi = std::numbers::pi_v<L>;
    return {{"pivot_radius", 0, 0.95L, "|r_p|"},
            {"pivot_polar", 0, pi, "polar angle of r_p (rad)"},
            {"pivot_azimuth", -pi, pi, "azimuth of r_p (rad)"},
            {"cap_polar", 0, pi, "polar angle of the cap axis (rad)"},
            {"cap_azimuth", -pi, pi, "azimuth of the cap axis (rad)"},
            {"cap_half_angle", 1e-2L, pi - 1e-2L, "half-angle alpha of the cap (rad)"}};
  }
  static Geometry<L> make(std::span<const L> p) {
    auto dir = [](L polar, L az) {
      return Vec3<L>(std::sin(polar) * std::cos(az), std::sin(polar) * std::sin(az), std::cos(polar));
    };
    Geometry<L> g;
    g.sptd.pivot = p[0] * dir(p[1], p[2]);
    g.cap = Cap<L>{dir(p[3], p[4]), 2 * std::sin(p[5] / 2) * std::sin(p[5] / 2)};  // 1 - cos without cancellation
    return g;
  }
  template <class U, class T> static Geometry<U> cast(const Geometry<T>& g) { return g.template cast<U>(); }
};

// A rectangle (RectangleFamily) seen through an LTC (Heitz et al. 2016, lib/warpcheck/ltc.h) of their fitted
// form M = [[a, 0, b], [0, c, 0], [d, 0, 1]] (the shape of their tables), a, c log-uniform in [10^-2.5, 1].
struct LtcRectangleFamily {
  template <class T> using Geometry = LtcPolygonGeometry<T>;
  static constexpr const char* what = "rectangles through an LTC";
  static std::vector<SearchParameter> parameters();
  static Geometry<L> make(std::span<const L> p);
  template <class U, class T> static Geometry<U> cast(const Geometry<T>& g) { return g.template cast<U>(); }
};

// ---- Kernels ---------------------------------------------------------------------------------------------

std::vector<SearchParameter> LtcRectangleFamily::parameters() {
  std::vector<SearchParameter> v = RectangleFamily::parameters();
  v.push_back({"log10_ltc_a", -2.5L, 0, "LTC matrix entry a (log10)"});
  v.push_back({"log10_ltc_c", -2.5L, 0, "LTC matrix entry c (log10)"});
  v.push_back({"ltc_b", -1, 1, "LTC matrix entry b"});
  v.push_back({"ltc_d", -1, 1, "LTC matrix entry d"});
  return v;
}
LtcRectangleFamily::Geometry<L> LtcRectangleFamily::make(std::span<const L> p) {
  const std::size_t n = RectangleFamily::parameters().size();
  Geometry<L> g;
  g.polygon = RectangleFamily::make(p.first(n));
  g.m << std::pow(L(10), p[n]), 0, p[n + 2], 0, std::pow(L(10), p[n + 1]), 0, p[n + 3], 0, 1;
  return g;
}

// The geometry family each kernel's searches draw from, by the kernel's geometry type.
template <class G> struct FamilyOf;
template <> struct FamilyOf<SphereLightGeometry<L>> { using type = SphereFamily; };
template <> struct FamilyOf<PolygonLightGeometry<L>> { using type = RectangleFamily; };
template <> struct FamilyOf<SptdCapGeometry<L>> { using type = SptdCapFamily; };
template <> struct FamilyOf<LtcPolygonGeometry<L>> { using type = LtcRectangleFamily; };

// Catalogue kernels without searches (yet); each would add its five.
constexpr std::string_view kNotSearched[] = {"sphere-projected-cap-exact", "sphere-projected-cap-polar",
                                             "polygon-projected-solid-angle-biased", "polygon-solid-angle-clipped",
                                             "sptd-cosine-cap"};

// ---- Measures ----------------------------------------------------------------------------------------------

template <class T> T unit_below_one(L u) {
  const T v = T(u);
  return v < T(1) ? v : std::nextafter(T(1), T(0));
}

// Fourth-order central difference of the long double warp in both u; nullopt if any stencil sample declines.
template <class Warp> std::optional<Eigen::Matrix<L, 3, 2>> warp_jacobian(const Warp& warp, L u0, L u1, L h) {
  Eigen::Matrix<L, 3, 2> J;
  for (int k = 0; k < 2; ++k) {
    Vec3<L> d[4];
    const L off[4] = {2 * h, h, -h, -2 * h};
    for (int i = 0; i < 4; ++i) {
      const DirectionSample<L> s = k == 0 ? warp(u0 + off[i], u1) : warp(u0, u1 + off[i]);
      if (!s.valid()) return std::nullopt;
      d[i] = s.direction;
    }
    J.col(k) = (-d[0] + L(8) * d[1] - L(8) * d[2] + d[3]) / (L(12) * h);
  }
  return J;
}

enum class Metric { kAngle, kBackward };

constexpr L kBackwardStep =
    1e-6L;                      // with 2h the stencil reaches 4e-6: the backward searches keep u in [1e-5, 1 - 1e-5]
constexpr L kResolved = 1e-7L;  // differences with h and 2h must agree to this (relative) to count

template <class Family, template <class> class K, class T> L precision_error(std::span<const L> p, Metric metric) {
  const std::size_t n = Family::parameters().size();
  using GL = typename Family::template Geometry<L>;
  const auto gT = Family::template cast<T>(Family::make(p.first(n)));
  const GL gL = Family::template cast<L>(gT);
  const T u0 = unit_below_one<T>(p[n]), u1 = unit_below_one<T>(p[n + 1]);
  const auto vL = K<L>::view(gL);
  const DirectionSample<T> sT = K<T>::sample(K<T>::view(gT), Vec2<T>(u0, u1));
  const DirectionSample<L> sL = K<L>::sample(vL, Vec2<L>(L(u0), L(u1)));
  if (!sT.valid() || !sL.valid()) return kNaN;
  if (!all_finite(sT.direction) || !std::isfinite(sT.pdf)) return kInf;
  const Vec3<L> a = sT.direction.template cast<L>().normalized(), b = sL.direction.normalized();
  if (metric == Metric::kAngle) return std::atan2(a.cross(b).norm(), a.dot(b));
  auto warp = [&](L v0, L v1) { return K<L>::sample(vL, Vec2<L>(v0, v1)); };
  const auto J = warp_jacobian(warp, L(u0), L(u1), kBackwardStep);
  const auto J2 = warp_jacobian(warp, L(u0), L(u1), 2 * kBackwardStep);
  if (!J || !J2 || !((*J - *J2).norm() <= kResolved * J->norm())) return kNaN;  // unresolved (see the top)
  // Least squares in the tangent plane: du = (J^T J)^-1 J^T (a - b).
  const Eigen::Matrix<L, 2, 2> JtJ = J->transpose() * *J;
  if (!(std::abs(JtJ.determinant()) > 0)) return kNaN;
  const Vec2<L> du = JtJ.inverse() * (J->transpose() * (a - b));
  return du.cwiseAbs().maxCoeff();
}

constexpr L kPdfStep = 1e-5L;  // with 2h, the stencil reaches 4e-5: u in [1e-4, 1 - 1e-4]

template <class Family, template <class> class K> L pdf_warp_error(std::span<const L> p) {
  const std::size_t n = Family::parameters().size();
  const auto v = K<L>::view(Family::make(p.first(n)));
  const L u0 = p[n], u1 = p[n + 1];
  const DirectionSample<L> s = K<L>::sample(v, Vec2<L>(u0, u1));
  if (!s.valid()) return kNaN;
  if (!all_finite(s.direction) || !std::isfinite(s.pdf)) return kInf;
  auto warp = [&](L v0, L v1) { return K<L>::sample(v, Vec2<L>(v0, v1)); };
  const auto J1 = warp_jacobian(warp, u0, u1, kPdfStep), J2 = warp_jacobian(warp, u0, u1, 2 * kPdfStep);
  if (!J1 || !J2) return kNaN;
  const L area1 = J1->col(0).cross(J1->col(1)).norm(), area2 = J2->col(0).cross(J2->col(1)).norm();
  if (!(area1 > 0) || !(std::abs(area1 - area2) <= kResolved * area1)) return kNaN;  // unresolved (see the top)
  return std::abs(s.pdf * area1 - 1);
}

std::vector<SearchParameter> with_u(std::vector<SearchParameter> v, L margin) {
  v.push_back({"u0", margin, 1 - margin, "first primary sample"});
  v.push_back({"u1", margin, 1 - margin, "second primary sample"});
  return v;
}

template <template <class> class K> void add_kernel(std::vector<Search>& v) {
  using Family = typename FamilyOf<typename K<L>::Geometry>::type;
  const std::string kernel = K<L>::name, what = std::string(K<L>::description) + "; " + Family::what;
  auto precision = [&]<class T>(Metric metric) {
    Search s;
    const std::string scalar = std::is_same_v<T, float> ? "float" : "double";
    s.name = "precision-" + kernel + "-" + scalar + (metric == Metric::kAngle ? "-angle" : "-backward");
    s.description = metric == Metric::kAngle
                        ? kernel + " (" + what + ") in " + scalar +
                              ": angle (rad) between its sample direction and the long double "
                              "instantiation's on the same rounded input"
                        : kernel + " (" + what + ") in " + scalar +
                              ": backward error max(|du0|, |du1|) explaining its sample "
                              "direction by the long double warp (first order, 4th-order differences with h = 1e-6)";
    s.paper = "";
    s.resolution_depends_on_cpu = metric == Metric::kBackward;
    s.parameters = with_u(Family::parameters(), metric == Metric::kAngle ? L(1e-6L) : L(1e-5L));
    s.objective = [metric](std::span<const L> p) { return precision_error<Family, K, T>(p, metric); };
    v.push_back(std::move(s));
  };
  precision.template operator()<float>(Metric::kAngle);
  precision.template operator()<float>(Metric::kBackward);
  precision.template operator()<double>(Metric::kAngle);
  precision.template operator()<double>(Metric::kBackward);
  Search s;
  s.name = "pdf-warp-" + kernel;
  s.description = kernel + " (" + what +
                  ") in long double: |returned pdf * area element of the warp - 1|, the area "
                  "element |dw/du0 x dw/du1| by 4th-order differences (h = 1e-5; points where h and 2h disagree by "
                  "> 1e-7 are skipped as kinks)";
  s.paper = "";
  s.resolution_depends_on_cpu = true;
  s.parameters = with_u(Family::parameters(), 1e-4L);
  s.objective = [](std::span<const L> p) { return pdf_warp_error<Family, K>(p); };
  v.push_back(std::move(s));
}

}  // namespace

void append_kernel_searches(std::vector<Search>& v) {
  AllKernels::for_each([&]<template <class> class K>() {
    for (std::string_view skip : kNotSearched)
      if (skip == K<L>::name) return;
    add_kernel<K>(v);
  });
}

}  // namespace warpcheck::validation
