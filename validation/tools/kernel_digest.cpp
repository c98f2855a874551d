// kernel_digest: a hash of every catalogue kernel's samples and densities on random geometries, per scalar type, to
// show that a change of lib/ left the kernels' results bit for bit as they were (scripts/digest_ab.sh compares the
// working tree with a revision).
//
// Per kernel and scalar type: 20000 geometries (4000 in long double) drawn with std::mt19937_64, the same for every
// kernel of a geometry type; half the polygon lights prepared (prepare_polygon_light). Per geometry: the view, 8
// samples (validity, direction, pdf, the pdf at the direction) and the pdf at 8 random directions, hashed by FNV-1a
// over their bytes (long double: its 10 significant bytes). Prints "KERNEL SCALAR HASH" per line. Uses only the
// catalogue's traits, so that it compiles against older trees too.
#include <cstdint>
#include <cstdio>
#include <list>
#include <random>

#include "warpcheck/catalogue.h"

namespace warpcheck {
namespace {

struct Digest {
  std::uint64_t hash = 1469598103934665603ull;
  template <class X> void add(const X& x) {
    const std::size_t n = std::is_same_v<X, long double> ? 10 : sizeof(X);  // x87: the padding is not the value
    const auto* p = reinterpret_cast<const unsigned char*>(&x);
    for (std::size_t i = 0; i < n; ++i) hash = (hash ^ p[i]) * 1099511628211ull;
  }
  template <class T> void add(const Vec3<T>& v) { add(v.x()), add(v.y()), add(v.z()); }
};

std::mt19937_64 rng;
double uniform(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); }
template <class T> Vec3<T> random_vector(double s) {
  return Vec3<T>(T(uniform(-s, s)), T(uniform(-s, s)), T(uniform(-s, s)));
}

// A shading point near the lights (or within 1e-3 of the origin), its normal +z or random (not unit).
template <class T> ShadingPoint<T> shading_point() {
  const Vec3<T> n = uniform(0, 1) < 0.5 ? Vec3<T>(0, 0, 1) : random_vector<T>(1);
  return {random_vector<T>(uniform(0, 1) < 0.3 ? 1e-3 : 2), n};
}

// A regular polygon (3 to 5 vertices) or a rectangle in a random plane, of size 1e-4 to 10.
template <class T> PolygonLight<T> polygon_light(bool rectangle) {
  PolygonLight<T> l;
  const double size = std::pow(10.0, uniform(-4, 1)), a0 = uniform(0, 2 * std::numbers::pi);
  const Vec3<T> c = random_vector<T>(4);
  const Frame<T> f = Frame<T>::from_z(random_vector<double>(1).normalized().cast<T>());
  l.count = rectangle ? 4 : (uniform(0, 1) < 0.5 ? 3 : (uniform(0, 1) < 0.5 ? 4 : 5));
  for (int k = 0; k < l.count; ++k) {
    const double a = a0 + 2 * std::numbers::pi * k / l.count, w = rectangle && k % 2 ? 0.7 : 1.0;
    l.vertices[k] = c + T(size * std::cos(a)) * f.x + T(size * w * std::sin(a)) * f.y;
  }
  return l;
}

template <class T> SphereLightGeometry<T> geometry(const SphereLightGeometry<T>*, bool) {
  return {shading_point<T>(), SphereLight<T>{random_vector<T>(4), T(std::pow(10.0, uniform(-5, 0.5)))}};
}
template <class T> PolygonLightGeometry<T> geometry(const PolygonLightGeometry<T>*, bool rectangle) {
  static std::list<PreparedPolygonLight<T>> prepared;
  PolygonLightGeometry<T> g{shading_point<T>(), polygon_light<T>(rectangle)};
  if (uniform(0, 1) < 0.5) g.prepared = &prepared.emplace_back(prepare_polygon_light(g.light));
  return g;
}
template <class T> SptdCapGeometry<T> geometry(const SptdCapGeometry<T>*, bool) {
  SptdCapGeometry<T> c;
  c.sptd.pivot = random_vector<T>(0.6);
  c.cap = make_sphere_view(geometry((const SphereLightGeometry<T>*)nullptr, false)).cap();
  return c;
}
template <class T> LtcPolygonGeometry<T> geometry(const LtcPolygonGeometry<T>*, bool) {
  Mat3<T> m;
  for (int i = 0; i < 9; ++i) m(i / 3, i % 3) = T(uniform(-1, 1));
  m(2, 2) = T(1);
  return LtcPolygonGeometry<T>{geometry((const PolygonLightGeometry<T>*)nullptr, false), m};
}

template <template <class> class K, class T> void digest(int geometries) {
  using G = typename K<T>::Geometry;
  rng.seed(11);
  Digest d;
  for (int i = 0; i < geometries; ++i) {
    const auto v = K<T>::view(geometry((const G*)nullptr, kernel_takes_only_rectangles<K<T>>()));
    for (int j = 0; j < 8; ++j) {
      const auto s = K<T>::sample(v, Vec2<T>(T(uniform(0, 1)), T(uniform(0, 1))));
      d.add(s.valid());
      if (s.valid()) d.add(s.direction), d.add(s.pdf), d.add(K<T>::pdf(v, s.direction));
      d.add(K<T>::pdf(v, random_vector<T>(1)));
    }
  }
  const char* scalar = std::is_same_v<T, float> ? "float" : std::is_same_v<T, double> ? "double" : "long-double";
  std::printf("%-40s %-12s %016llx\n", K<double>::name, scalar, static_cast<unsigned long long>(d.hash));
}

}  // namespace
}  // namespace warpcheck

int main() {
  warpcheck::AllKernels::for_each([]<template <class> class K>() {
    warpcheck::digest<K, float>(20000);
    warpcheck::digest<K, double>(20000);
    warpcheck::digest<K, long double>(4000);
  });
  return 0;
}
