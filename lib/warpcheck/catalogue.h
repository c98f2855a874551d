// warpcheck/catalogue.h: every kernel of lib/, by family.
//
// A kernel is one lib sample/pdf pair with its fixed options. Its header declares a trait K<T>, templated on the
// scalar T, that calls the lib functions; the battery, the worst-case searches, the benchmarks and the fuzz
// targets take their kernels, and the kernels' names, from the lists below.
//
// A trait has
//   name, description          the kernel's one name (everywhere) and a line on its method and source
//   Scalar, Geometry, View     T, the light as given, and the per-light precomputation
//   view(g)                    the precomputation; sample and pdf work on it
//   sample(v, u), pdf(v, w)    a DirectionSample for u in [0, 1)^2, and the density (per solid angle) at unit w
//   bounding_cap(g)            a cap containing every direction sample() returns
// and, where the kernel has them,
//   normaliser(v)              the measure the density is normalised by (solid angle, projected solid angle, area)
//   kinks_u0(g), kinks_u1(g)   u where the warp is only piecewise smooth (e.g. where u0 passes from one piece
//                              of the light to the next)
//   boundary_planes(g)         unit normals of the great circles on which the density may jump or kink
//   boundary_caps(g)           caps on whose edges (small circles) the density may jump or kink
//   invert(v, w, u)            the inverse warp: the u that sample() maps to w
//   rectangles_only            true if the kernel takes rectangles only
//
// Adding a kernel to a family: its trait in its header, its entry in the family's list below, and its
// configuration in validation/catalogue/<family>.cpp.
#pragma once

#include <array>
#include <cstddef>
#include <string_view>

#include "warpcheck/ltc.h"
#include "warpcheck/polygon_projected.h"
#include "warpcheck/polygon_solid_angle.h"
#include "warpcheck/projected_cap.h"
#include "warpcheck/sphere.h"
#include "warpcheck/spherical_rectangle.h"
#include "warpcheck/sptd.h"

namespace warpcheck {

// A list of kernel traits (templates over the scalar type).
template <template <class> class... K> struct KernelList {
  static constexpr std::size_t size = sizeof...(K);
  // f.template operator()<K>() for each kernel K, in order; f is e.g. []<template <class> class K>() { ... }.
  template <class F> static void for_each(F&& f) { (f.template operator()<K>(), ...); }
  static constexpr std::array<std::string_view, sizeof...(K)> names() { return {K<double>::name...}; }
  static constexpr bool contains(std::string_view name) {
    for (std::string_view n : names())
      if (n == name) return true;
    return false;
  }
};

template <class... Lists> struct JoinKernelLists;
template <template <class> class... K> struct JoinKernelLists<KernelList<K...>> { using type = KernelList<K...>; };
template <template <class> class... A, template <class> class... B, class... Rest>
struct JoinKernelLists<KernelList<A...>, KernelList<B...>, Rest...> {
  using type = typename JoinKernelLists<KernelList<A..., B...>, Rest...>::type;
};

// The families: one battery registrar each (validation/catalogue/<family>.cpp).
using SphereKernels = KernelList<SphereSolidAngle, SphereVisibleArea>;
using ProjectedCapKernels = KernelList<SphereProjectedCap, SphereProjectedCapExact, SphereProjectedCapPolar>;
using PolygonKernels =
    KernelList<PolygonProjectedSolidAngle, PolygonProjectedSolidAngleBiased, PolygonSolidAngle,
               PolygonSolidAngleClipped, BaselineArvoTriangle, BaselineTurkArea, BaselineUrenaRectangle>;
using SptdKernels = KernelList<SptdUniformCap, SptdCosineCap, PolygonLtc>;

using AllKernels = JoinKernelLists<SphereKernels, ProjectedCapKernels, PolygonKernels, SptdKernels>::type;

template <class K> constexpr bool kernel_takes_only_rectangles() {
  if constexpr (requires { K::rectangles_only; })
    return K::rectangles_only;
  else
    return false;
}

}  // namespace warpcheck
