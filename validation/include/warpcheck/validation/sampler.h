// warpcheck/validation/sampler.h: what the battery tests.
//
// The battery runs on a SamplerUnderTest: one sampler bound to one geometry, seen through long double. Two
// ways to get one:
//
//  1. Your own sampler (any precision, any geometry type): fill in the fields by hand with lambdas.
//     `sample` (or `sample_u`, for a sampler of more than two uniform numbers) and `pdf` are required, and so is
//     `bounding_cap`, a spherical cap that contains every direction the sampler can return: the chi-square grid
//     and the KS coordinates are laid over it, so make it tight; a sampler without a tight cap (a BSDF) takes
//     hemisphere(n) or whole_sphere(). README.md, "Validate your own sampler", says which field matters when.
//
//  2. A kernel trait satisfying the `Kernel` concept below, as lib/warpcheck/catalogue.h's kernels do (name,
//     Scalar, Geometry, View, static view / sample / pdf / bounding_cap): `bind_kernel<K>(config, geometry)`
//     builds the SamplerUnderTest, and `bind_kernel<K, KRef>` also wires KRef (the same kernel in long double)
//     as the reference warp for the Jacobian check. A kernel without a per-light precomputation takes
//     `using View = Geometry;` and a `view` that returns the geometry.
//
// Conventions: directions are unit world-space vectors; densities are with respect to solid angle; a sample
// with valid == false means the sampler declined (allowed only where the sampler also reports pdf == 0
// everywhere, i.e. "no sample" geometry; the battery counts declined samples and fails on any).
#pragma once

#include <array>
#include <cmath>
#include <concepts>
#include <functional>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "warpcheck/core.h"

namespace warpcheck::validation {

// The kernels' geometry types and constants, by their names in this namespace too.
using warpcheck::Cap;
using warpcheck::Frame;
using warpcheck::kPi;
using warpcheck::kTwoPi;
using warpcheck::Vec3;

using Real = long double;
using Vec3L = Vec3<long double>;

struct Sample {
  Vec3L direction = Vec3L::Zero();
  Real pdf = 0;
  bool valid = false;
  // Optional: the sampler's weight, the estimate f(direction) / pdf it returns to the renderer (a BSDF sampler's
  // f cos / pdf). With SamplerUnderTest::eval the battery checks it (the test "weight").
  std::optional<Real> weight = std::nullopt;
};

// Bounding caps for samplers without a tight one: the hemisphere around the unit normal n, and the whole sphere
// (1 - cos of the half-angle = 1 and 2). The chi-square grid keeps its equal-area rings and columns on them.
inline Cap<Real> hemisphere(const Vec3L& n) { return Cap<Real>{n.normalized(), 1}; }
inline Cap<Real> whole_sphere() { return Cap<Real>{Vec3L(0, 0, 1), 2}; }

// An independently computed measure that the sampler's normalisation must equal (e.g. the cap's solid angle
// for a uniform cone sampler, the projected solid angle for a projected-solid-angle sampler).
struct Normalization {
  std::string what;              // e.g. "solid angle of the cap"
  std::function<Real()> kernel;  // the value the kernel's own code uses (e.g. 1 / pdf)
  Real reference = 0;            // computed independently of the kernel's code
};

// A block of samples in double, as arrays: sample i is the direction (x[i], y[i], z[i]) with density pdf[i], declined
// where valid[i] is false (as Sample).
struct DoubleSamples {
  std::span<double> x, y, z, pdf;
  std::span<bool> valid;
};

struct SamplerUnderTest {
  std::string kernel;  // kernel name, e.g. "sphere-solid-angle"
  std::string scalar;  // "float", "double", "long double" or whatever the sampler computes in
  std::string config;  // configuration name, e.g. "near"

  std::function<Sample(double u0, double u1)> sample;  // required (or sample_u)
  std::function<Real(const Vec3L&)> pdf;               // required: density of a unit direction
  Cap<Real> bounding_cap;                              // required: contains the support

  // A sampler of more than two uniform numbers (a lobe, a triangle or a light chosen by the third): `uniforms`
  // numbers per sample, passed in u (u.size() == uniforms), instead of `sample`. The chi-square grid and the KS
  // tests are on the direction as always; pdf-consistency compares the returned pdf with pdf(direction) only (the
  // warp's area element is that of one branch, not the mixture's density).
  int uniforms = 2;
  std::function<Sample(std::span<const double> u)> sample_u;
  // Optional: the integrand f of the sampler's weight (a BSDF times the cosine). Every drawn sample with pdf > 0
  // must then carry weight == eval(direction) / pdf to `tolerance` (the test "weight").
  std::function<Real(const Vec3L&)> eval;

  // Optional: the inverse warp, for a sampler of two uniform numbers: the primary sample (u0, u1) in [0, 1)^2 that
  // `sample` maps to the unit direction w, or nullopt where w is outside the support. (A sampler of more uniform
  // numbers picks a branch with the others; its inverse is not defined here.) With it the battery runs the
  // deterministic test "round-trip": inverse(sample(u)) == u on a grid of u, and sample(inverse(w)) == w on a grid
  // of directions over the bounding cap, both to inverse_tolerance. It catches an inversion in `sample` that stops
  // early, which the statistical tests at 10^7 samples may not see.
  std::function<std::optional<std::array<Real, 2>>(const Vec3L& w)> inverse;
  // The round trip's tolerance in units of u: max |inverse(sample(u)) - u| over both coordinates; a direction's
  // error sample(inverse(w)) - w is taken to u as the distance from inverse(w) to w's nearest preimage under
  // `sample`, found by Gauss-Newton steps with the warp's Jacobian dw/du (least squares).
  Real inverse_tolerance = 1e-6L;
  // Optional: membership in the support, used to flag samples outside the light. Default: pdf(w) > 0.
  std::function<bool(const Vec3L&)> in_support;
  // Optional: the same warp evaluated in higher precision, for the Jacobian check. Default: `sample`.
  std::function<Sample(Real u0, Real u1)> reference_sample;
  // Documented kinks of the warp in primary sample space: the Jacobian check skips points whose
  // finite-difference stencil would straddle one. Periodic seams (u = 0 or 1) need not be listed.
  std::vector<Real> kinks_u0, kinks_u1;
  // Optional independent normalisation checks.
  std::vector<Normalization> normalizations;
  // Relative tolerance of the deterministic checks (pdf consistency, integral, normalisation): 1e-6 for double
  // and long double; a float sampler states its own, measured, tolerance.
  Real tolerance = 1e-6L;
  // Why the tolerance differs from 1e-6, if it does (printed in the JSON results).
  std::string tolerance_note;
  // Optional: great circles (unit normals m of planes through the shading point) on which the pdf may jump or
  // kink, e.g. a polygon's edges and the horizon. The battery's quadrature splits each radial line where it
  // crosses one, so that parts of the support thinner than its nodes' spacing (an acute corner's tip) keep
  // their mass. Without them a polygon seen 0.3 deg from its plane lost 0.25% of its mass.
  std::vector<Vec3L> boundary_planes;
  // Optional: caps on whose edges (small circles) the pdf may jump or kink, e.g. where a pivot transform maps a
  // clamped cosine's horizon. The grid quadrature splits at them as at boundary_planes.
  std::vector<Cap<Real>> boundary_caps;
  // Optional block forms of sample and pdf, for speed: out[i] = sample(u0[i], u1[i]) and out[i] = pdf(w[i]), bit
  // for bit, with the per-light work and the call paid once per block. bind_kernel fills both; sample_many and
  // pdf_many below fall back to the single forms.
  std::function<void(std::span<const double> u0, std::span<const double> u1, std::span<Sample> out)> sample_block;
  std::function<void(std::span<const Vec3L> w, std::span<Real> out)> pdf_block;
  // Optional, for a sampler that computes in float or double (both exact in double): sample_block with its output in
  // double, which the battery bins without converting each sample to long double and back. bind_kernel fills it
  // for float and double kernels.
  std::function<void(std::span<const double> u0, std::span<const double> u1, DoubleSamples out)> sample_block_double;
  // Geometry for which the sampler must decline every sample (e.g. a light entirely below the horizon):
  // the battery then checks only that every sample is declined and the pdf is zero everywhere.
  bool expect_no_sample = false;
};

// One sample from the primary sample u (u.size() == s.uniforms), through sample_u or sample.
inline Sample sample_at(const SamplerUnderTest& s, std::span<const double> u) {
  return s.sample_u ? s.sample_u(u) : s.sample(u[0], u[1]);
}

// The sampler's samples (pdfs) of a block of primary samples (directions), through the block form when it has one.
inline void sample_many(const SamplerUnderTest& s, std::span<const double> u0, std::span<const double> u1,
                        std::span<Sample> out) {
  if (s.sample_block) return s.sample_block(u0, u1, out);
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = s.sample(u0[i], u1[i]);
}
inline void pdf_many(const SamplerUnderTest& s, std::span<const Vec3L> w, std::span<Real> out) {
  if (s.pdf_block) return s.pdf_block(w, out);
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = s.pdf(w[i]);
}

// ---- Kernel concept: for samplers written as warpcheck-style kernels ---------------------------------------

template <class K>
concept Kernel = requires(const typename K::Geometry& g, const typename K::View& v, const Vec2<typename K::Scalar>& u,
                          const Vec3<typename K::Scalar>& w) {
  { K::name } -> std::convertible_to<std::string>;
  { K::view(g) } -> std::convertible_to<typename K::View>;
  { K::sample(v, u) } -> std::convertible_to<DirectionSample<typename K::Scalar>>;
  { K::pdf(v, w) } -> std::convertible_to<typename K::Scalar>;
  { K::bounding_cap(g) } -> std::convertible_to<Cap<typename K::Scalar>>;
};

// A kernel's documented kinks in u0 and u1 (catalogue.h), empty if it declares none.
template <Kernel K> std::vector<Real> kernel_kinks(const typename K::Geometry& g, int axis) {
  std::vector<typename K::Scalar> k;
  if constexpr (requires { K::kinks_u0(g); })
    if (axis == 0) k = K::kinks_u0(g);
  if constexpr (requires { K::kinks_u1(g); })
    if (axis == 1) k = K::kinks_u1(g);
  return std::vector<Real>(k.begin(), k.end());
}

template <class T> Vec3L to_long(const Vec3<T>& v) { return v.template cast<Real>(); }

// A kernel's inverse warp (catalogue.h's invert(v, w, u)) on view v, as SamplerUnderTest::inverse; empty if K has
// none. The tolerance is K::inverse_tolerance where K states one, else 1e-6 (double and long double); a float
// kernel with an inverse must state its own.
template <Kernel K> void bind_inverse(SamplerUnderTest& s, const typename K::View& v) {
  using T = typename K::Scalar;
  if constexpr (requires(const Vec3<T>& w, Vec2<T>& u) {
                  { K::invert(v, w, u) } -> std::convertible_to<bool>;
                }) {
    s.inverse = [v](const Vec3L& w) -> std::optional<std::array<Real, 2>> {
      Vec2<T> u(T(0), T(0));
      if (!K::invert(v, w.template cast<T>(), u)) return std::nullopt;
      return std::array<Real, 2>{Real(u[0]), Real(u[1])};
    };
    if constexpr (requires { K::inverse_tolerance; }) s.inverse_tolerance = Real(K::inverse_tolerance);
  }
}

template <class T> constexpr const char* scalar_name() {
  if constexpr (std::is_same_v<T, float>)
    return "float";
  else if constexpr (std::is_same_v<T, double>)
    return "double";
  else if constexpr (std::is_same_v<T, long double>)
    return "long double";
  else
    return "custom";
}

// How far, in radians, rounding in scalar type T may put a sampler's direction beyond its support's edge: 64
// machine epsilons of T (3.8e-6 rad for float, 1.4e-14 for double). The battery counts samples about that far beyond
// the bounding cap in its outermost ring, and integrates the pdf there as well. A pdf that tests its edge exactly is
// rounded as its samples are; one that accepts directions this far outside adds that band's mass to its integral
// (2e-13 of a 0.4 rad cone in double, 1.7e-4 of a 0.3 rad cone in float, where pdf-integral sees 5.9e-5 of it).
template <class T> constexpr Real support_slack() { return 64 * Real(std::numeric_limits<T>::epsilon()); }

// A uniform number in [0, 1) as T: rounding to float can turn 1 - 2^-53 into 1, which some warps map onto a
// measure-zero set of infinite density (a silhouette); keep it below 1.
template <class T> T to_unit(double u) {
  const T v = T(u);
  return v < T(1) ? v : std::nextafter(T(1), T(0));
}

template <class T> Sample to_sample(const DirectionSample<T>& s) {
  return Sample{to_long(s.direction), Real(s.pdf), s.valid()};
}

// A kernel's boundary planes (catalogue.h), empty if it declares none.
template <Kernel K> std::vector<Vec3L> kernel_boundary_planes(const typename K::Geometry& g) {
  std::vector<Vec3L> planes;
  if constexpr (requires { K::boundary_planes(g); })
    for (const auto& m : K::boundary_planes(g)) planes.push_back(to_long(m));
  return planes;
}

// A kernel's boundary caps (catalogue.h), empty if it declares none.
template <Kernel K> std::vector<Cap<Real>> kernel_boundary_caps(const typename K::Geometry& g) {
  std::vector<Cap<Real>> caps;
  if constexpr (requires { K::boundary_caps(g); })
    for (const auto& c : K::boundary_caps(g)) caps.push_back(Cap<Real>{to_long(c.axis), Real(c.one_minus_cos)});
  return caps;
}

// Binds kernel K to geometry g (in K's scalar type; the caller converts it): sample and pdf on one view of g,
// K's bounding cap, kinks, boundary planes and caps, and its inverse where it has one.
template <Kernel K> SamplerUnderTest bind_kernel(std::string config, const typename K::Geometry& g) {
  using T = typename K::Scalar;
  SamplerUnderTest s;
  s.kernel = K::name;
  s.config = std::move(config);
  s.scalar = scalar_name<T>();
  // K's sample at a uniform pair in double, the form every entry point below draws through.
  static constexpr auto draw = [](const typename K::View& v, double u0, double u1) {
    return K::sample(v, Vec2<T>(to_unit<T>(u0), to_unit<T>(u1)));
  };
  s.sample = [v = K::view(g)](double u0, double u1) { return to_sample(draw(v, u0, u1)); };
  s.pdf = [v = K::view(g)](const Vec3L& w) { return Real(K::pdf(v, w.template cast<T>())); };
  s.sample_block = [v = K::view(g)](std::span<const double> u0, std::span<const double> u1, std::span<Sample> out) {
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = to_sample(draw(v, u0[i], u1[i]));
  };
  s.pdf_block = [v = K::view(g)](std::span<const Vec3L> w, std::span<Real> out) {
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = Real(K::pdf(v, w[i].template cast<T>()));
  };
  if constexpr (std::is_same_v<T, float> || std::is_same_v<T, double>)
    s.sample_block_double = [v = K::view(g)](std::span<const double> u0, std::span<const double> u1,
                                             DoubleSamples out) {
      for (std::size_t i = 0; i < out.x.size(); ++i) {
        const DirectionSample<T> x = draw(v, u0[i], u1[i]);
        out.x[i] = x.direction.x(), out.y[i] = x.direction.y(), out.z[i] = x.direction.z();
        out.pdf[i] = x.pdf, out.valid[i] = x.valid();
      }
    };
  const Cap<T> cap = K::bounding_cap(g);
  s.bounding_cap = Cap<Real>{to_long(cap.axis).normalized(), Real(cap.one_minus_cos)};
  s.kinks_u0 = kernel_kinks<K>(g, 0);
  s.kinks_u1 = kernel_kinks<K>(g, 1);
  s.boundary_planes = kernel_boundary_planes<K>(g);
  s.boundary_caps = kernel_boundary_caps<K>(g);
  bind_inverse<K>(s, K::view(g));
  return s;
}

// As above, with KRef (the same kernel in long double, on the same geometry converted) as the reference warp;
// the bounding cap and the kinks come from KRef. The boundary planes and caps, where the pdf jumps, are KRef's on
// K's own geometry (g, exactly converted, where the geometry converts): a float polygon's edges are those of its
// rounded vertices, up to 1e-7 rad off the exact ones, and a quadrature split at the exact edges integrates across
// the rounded ones.
template <Kernel K, Kernel KRef>
SamplerUnderTest bind_kernel(std::string config, const typename K::Geometry& g, const typename KRef::Geometry& g_ref) {
  SamplerUnderTest s = bind_kernel<K>(std::move(config), g);
  using R = typename KRef::Scalar;
  s.reference_sample = [v = KRef::view(g_ref)](Real u0, Real u1) {
    return to_sample(KRef::sample(v, Vec2<R>(R(u0), R(u1))));
  };
  // The bounding cap from the long double geometry is tighter for tiny lights in float.
  const auto cap = KRef::bounding_cap(g_ref);
  s.bounding_cap = Cap<Real>{to_long(cap.axis).normalized(), Real(cap.one_minus_cos)};
  s.kinks_u0 = kernel_kinks<KRef>(g_ref, 0);
  s.kinks_u1 = kernel_kinks<KRef>(g_ref, 1);
  const typename KRef::Geometry* own = &g_ref;
  typename KRef::Geometry converted;
  if constexpr (requires { g.template cast<R>(); }) own = &(converted = g.template cast<R>());
  s.boundary_planes = kernel_boundary_planes<KRef>(*own);
  s.boundary_caps = kernel_boundary_caps<KRef>(*own);
  return s;
}

}  // namespace warpcheck::validation
