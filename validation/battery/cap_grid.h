// The grid quadrature of a sampler's pdf over its bounding cap (internal to the battery): the chi-square bin
// masses and the KS marginal CDFs from one pass, checked by a second pass that integrates in the other order.
// docs/derivations/battery-quadrature.md derives the accuracy each result needs.
#pragma once

#include <vector>

#include "warpcheck/validation/battery.h"

namespace warpcheck::validation::battery {

struct CapGridSpec {
  int radial_bins = 16, azimuth_bins = 32;  // the chi-square grid: rings equal in t, columns equal in phi
  std::vector<Real> xr, xa;                 // KS nodes: t, and phi / (2 pi), each from 0 to 1
  Real rel_tol = 1e-8L;                     // relative tolerance of each 1D piece's Gauss-Kronrod rule
  Real resolution = 0;                      // slabs are not halved below this width in t or phi (the sampler's
                                            // scalar cannot tell directions closer than that apart), and rings
                                            // with t > 1 - resolution, where a rounded pdf's edge lies, are
                                            // integrated by a dense midpoint rule in phi (cap_grid.cpp)
  Real bend = 1e-2L;                        // a slab is halved where its second difference exceeds this
  int max_depth = 8;                        // ... up to this many times
  bool beside_bends = true;                 // ... and so is a slab beside one that bends (cap_grid.cpp)
  int threads = 1;
};

struct CapGrid {
  std::vector<Real> bins;        // mass of each chi-square bin, row-major [ring][column], from the radial lines
  std::vector<Real> bins_check;  // the same from the rings: an independent estimate of the same numbers
  std::vector<Real> Fr, Fa;      // KS CDFs at the nodes xr (from the rings) and xa (from the lines)
  long pdf_calls = 0;
};

// Radial lines: at the 3 Gauss-Legendre azimuths of every slab between consecutive KS azimuth nodes, column
// edges and azimuth cuts (corners of the boundary, crossings of boundary circles with ring edges), each line
// integrated ring by ring with a 15-point Gauss-Kronrod rule, split where it crosses a boundary circle (circles.h).
// Rings: the same with t and phi exchanged (KS radial nodes, ring edges, tangencies and corners of the boundary;
// each ring integrated column by column). Between its cuts each slab's integrand is smooth, which is what the
// fixed 3-point rule needs; a 1D piece whose Kronrod error estimate exceeds rel_tol is refined adaptively.
CapGrid integrate_cap_grid(const SamplerUnderTest& s, const CapGridSpec& spec);

}  // namespace warpcheck::validation::battery
