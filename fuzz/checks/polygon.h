// fuzz/checks/polygon.h: the invariant checks shared by the polygon kernels. A polygon target decodes a geometry
// with decode_polygon_geometry (common.h's decode_polygon and decode_polygon_shading) and calls check_polygon_kernel
// with its sampler and density.
#pragma once

#include "common.h"
#include "warpcheck/polygon_projected.h"
#include "warpcheck/polygon_solid_angle.h"

namespace warpcheck::fuzz {

enum class PolygonDensity {
  kConstant,  // 1 / Omega: the sample's pdf and pdf(direction) are the same number
  kCosine,    // cos(theta) / A_Sigma: both from the same cosine; relative rounding 8 eps / cos(theta)
  kArea,      // h^2 / (|N.w|^3 Area): both from the same formula; relative rounding 8 eps * 3 / |N.w|
};

template <class T> std::string describe(const PolygonLightGeometry<T>& g, const Vec2<T>& u, const char* kernel) {
  std::ostringstream os;
  os.precision(std::numeric_limits<T>::max_digits10);
  os << kernel << " <" << (sizeof(T) == 4 ? "float" : "double") << ">: " << g.light.count << " vertices";
  for (int i = 0; i < std::min(g.light.count, kMaxPolygonVertices); ++i) os << " " << show(g.light.vertices[i]);
  os << " x " << show(g.shading.position) << " n " << show(g.shading.normal) << " u (" << u[0] << ", " << u[1] << ")\n";
  return os.str();
}

template <class T>
PolygonLightGeometry<T> decode_polygon_geometry(FuzzedDataProvider& in, bool rectangle_bias = false) {
  PolygonLightGeometry<T> g;
  g.light = decode_polygon<T>(in, rectangle_bias);
  g.shading = decode_polygon_shading<T>(in, g.light);
  return g;
}

template <class T> bool polygon_input_finite(const PolygonLightGeometry<T>& g) {
  for (int i = 0; i < std::min(g.light.count, kMaxPolygonVertices); ++i)
    if (!all_finite(g.light.vertices[i])) return false;
  return all_finite(g.shading.position) && all_finite(g.shading.normal);
}

// Distance from x to the segment from a to a + e (e != 0), without cancellation in its interior: |p x e| / |e|.
inline L segment_distance(const Vec3<L>& a, const Vec3<L>& e, const Vec3<L>& x) {
  const Vec3<L> p = a - x;
  const L ee = e.squaredNorm();
  const L t = -p.dot(e) / ee;
  return t <= 0 ? p.norm() : (t >= 1 ? Vec3<L>(p + e).norm() : kahan_cross<L>(p, e).norm() / std::sqrt(ee));
}

// The light's plane as the kernels flatten onto it (make_polygon_view, polygon.h): the unit area vector nh (0 for
// zero area) and each vertex's signed distance d[k] from the plane through the centroid, in long double.
struct PolygonLifts {
  Vec3<L> nh = Vec3<L>::Zero();
  L area2 = 0;                  // |area vector| = 2 area
  Vec3<L> c = Vec3<L>::Zero();  // the centroid
  std::array<L, kMaxPolygonVertices> d{};
};
template <class P> PolygonLifts polygon_lifts(const PolygonLight<P>& p) {
  PolygonLifts r;
  const int n = p.count;
  Vec3<L> area = Vec3<L>::Zero(), &c = r.c;
  const Vec3<L> v0 = p.vertices[0].template cast<L>();
  for (int i = 1; i + 1 < n; ++i)
    area += kahan_cross<L>(Vec3<L>(p.vertices[i].template cast<L>() - v0),
                           Vec3<L>(p.vertices[i + 1].template cast<L>() - v0));
  for (int i = 0; i < n; ++i) c += p.vertices[i].template cast<L>() / L(n);
  r.area2 = area.norm();
  if (!(r.area2 > 0) || n < 3) return r;
  r.nh = area / r.area2;
  for (int i = 0; i < n; ++i) r.d[i] = r.nh.dot(Vec3<L>(p.vertices[i].template cast<L>() - c));
  return r;
}

// The conditioning kappa of common.h's header, plus two terms. (1) A boundary point may lie closer to x than every
// vertex, on an edge that passes near x; a point of the moved polygon outside the exact cone lies within delta of
// the exact boundary, so each edge contributes (max(|V_j|_inf, |V_{j+1}|_inf) + |x|_inf + 16 min_T) / dist(x,
// segment V_j V_{j+1}). (2) For kernels clipped to the horizon, each clip point lies on the line of an edge that
// crosses the horizon, so its direction is known to eps_T (|p| + |q| + |V_j|_inf + |V_{j+1}|_inf + |x|_inf) /
// dist(x, line of the edge). The horizon arcs lie on the exactly known horizon.
// P: the geometry's type (T, or L for a light computed in long double, ltc.h); T: the kernel's precision.
template <class P, class T = P> L polygon_kappa(const PolygonLightGeometry<P>& g, bool clipped) {
  const int n = g.light.count;
  L k = kappa_of<P, T>(g.light.vertices.data(), n, g.shading.position);
  const Vec3<L> x = g.shading.position.template cast<L>(), nl = g.shading.normal.template cast<L>();
  for (int j = 0; j < n; ++j) {
    const Vec3<L> vj = g.light.vertices[j].template cast<L>(), vj1 = g.light.vertices[(j + 1) % n].template cast<L>();
    const Vec3<L> e = vj1 - vj;
    if (!(e.squaredNorm() > 0)) continue;  // a repeated vertex: covered by the vertex term
    const L seg_dist = segment_distance(vj, e, x);
    const L mag = std::max(vj.cwiseAbs().maxCoeff(), vj1.cwiseAbs().maxCoeff()) + x.cwiseAbs().maxCoeff() +
                  kSubnormalUlps * L(std::numeric_limits<T>::min());
    k = std::max(k, seg_dist > 0 ? mag / seg_dist : std::numeric_limits<L>::infinity());
  }
  if (!clipped) return k;
  for (int j = 0; j < n; ++j) {
    const Vec3<L> vj = g.light.vertices[j].template cast<L>(), vj1 = g.light.vertices[(j + 1) % n].template cast<L>();
    const Vec3<L> p = vj - x, q = vj1 - x, e = vj1 - vj;
    if (!(nl.dot(p) * nl.dot(q) < 0)) continue;
    const L line_dist = kahan_cross<L>(p, e).norm() / e.norm();
    const L mag = p.norm() + q.norm() + vj.cwiseAbs().maxCoeff() + vj1.cwiseAbs().maxCoeff() + x.cwiseAbs().maxCoeff();
    k = std::max(k, line_dist > 0 ? mag / line_dist : std::numeric_limits<L>::infinity());
  }
  return k;
}

// max_k |V_k|_inf in long double.
template <class T> L max_abs_coordinate(const PolygonLight<T>& p) {
  L mag = 0;
  for (int i = 0; i < p.count; ++i) mag = std::max(mag, L(p.vertices[i].template cast<L>().cwiseAbs().maxCoeff()));
  return mag;
}

// delta = kTolUlps eps_T (max_k |V_k|_inf + |x|_inf + 16 min_T): the vertex displacement the tolerance accepts
// (common.h). Every light within delta / 2 of the light as given is an "accepted displacement" of it.
template <class T> L displacement_budget(L mag, const Vec3<T>& x) {
  return L(kTolUlps) * eps<T>() *
         (mag + L(x.template cast<L>().cwiseAbs().maxCoeff()) + kSubnormalUlps * L(std::numeric_limits<T>::min()));
}

// The light with every vertex dropped that lies within delta / 2 of its predecessor: an accepted displacement. An
// edge that short has a direction the coordinates do not determine: the polygon can be reflex at it (an edge of
// subnormal length pointing out of the light's plane), and its great circle then cuts through the light.
template <class T> PolygonLight<T> merge_short_edges(const PolygonLight<T>& p, const Vec3<T>& x) {
  const int n = p.count;
  const L delta = displacement_budget(max_abs_coordinate(p), x);
  PolygonLight<T> m;
  for (int i = 0; i < n; ++i) {
    const Vec3<L> vi = p.vertices[i].template cast<L>();
    if (m.count > 0 && (vi - m.vertices[m.count - 1].template cast<L>()).norm() <= delta / 2) continue;
    m.vertices[m.count++] = p.vertices[i];
  }
  while (m.count > 1 &&
         (m.vertices[m.count - 1].template cast<L>() - m.vertices[0].template cast<L>()).norm() <= delta / 2)
    --m.count;
  return m;
}

// Angular distance of the direction w from the arc of directions from x to the segment a b.
template <class T> L arc_distance(const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& x, const Vec3<T>& w) {
  const Vec3<L> xl = x.template cast<L>(), wl = w.template cast<L>().normalized();
  const Vec3<L> ua = (a.template cast<L>() - xl).normalized(), ub = (b.template cast<L>() - xl).normalized();
  auto angle = [](const Vec3<L>& p, const Vec3<L>& q) { return std::atan2(p.cross(q).norm(), p.dot(q)); };
  L d = std::min(angle(wl, ua), angle(wl, ub));
  const Vec3<L> nab = ua.cross(ub);
  const L nn = nab.norm();
  if (nn > 0 && ua.cross(wl).dot(nab) >= 0 && wl.cross(ub).dot(nab) >= 0)
    d = std::min(d, std::abs(std::asin(std::clamp(nab.dot(wl) / nn, L(-1), L(1)))));
  return d;
}

// The light's two farthest vertices and their distance.
struct PolygonDiameter {
  int a = 0, b = 0;
  L length = 0;
};
template <class T> PolygonDiameter polygon_diameter(const PolygonLight<T>& p) {
  PolygonDiameter r;
  for (int i = 0; i < p.count; ++i)
    for (int j = i + 1; j < p.count; ++j) {
      const L d = (p.vertices[i].template cast<L>() - p.vertices[j].template cast<L>()).norm();
      if (d > r.length) r.length = d, r.a = i, r.b = j;
    }
  return r;
}

// The flat light (vertices `flat`, exact edges fe_i = flat_{i+1} - flat_i) with the vertices not `kept` dropped:
// a dropped vertex's outgoing edge joins the last kept vertex's, so the merged edges are sums of exact edges.
struct FlatMerge {
  PolygonLight<L> light;
  std::array<Vec3<L>, kMaxPolygonVertices> edges;
};
inline FlatMerge merge_flat_vertices(const PolygonLight<L>& flat, const std::array<Vec3<L>, kMaxPolygonVertices>& fe,
                                     const std::array<bool, kMaxPolygonVertices>& kept) {
  FlatMerge r;
  const int n = flat.count;
  int first = 0;
  while (first < n && !kept[first]) ++first;
  for (int k = 0; k < n && first < n; ++k) {
    const int i = (first + k) % n;
    if (kept[i]) r.light.vertices[r.light.count] = flat.vertices[i], r.edges[r.light.count++] = Vec3<L>::Zero();
    r.edges[r.light.count - 1] += fe[i];
  }
  return r;
}

// The light moved onto its plane (polygon_lifts): flat_k = V_k - d_k nh, off = max_k |d_k|. Its edges fe_k = e_k -
// (nh.e_k) nh come from the exact differences e_k = V_{k+1} - V_k: the difference of the rounded flat vertices
// would tilt a short edge out of the plane by eps_L |V| / |e_k|, and seen from close to the plane that edge's
// plane through x would cut the light.
struct FlatLight {
  PolygonLifts lifts;
  PolygonLight<L> light;
  std::array<Vec3<L>, kMaxPolygonVertices> edges;
  L off = 0;
};
template <class T> FlatLight flatten_light(const PolygonLight<T>& p, const PolygonLifts& lifts) {
  FlatLight f;
  const int n = p.count;
  f.lifts = lifts;
  f.light.count = n;
  for (int i = 0; i < n; ++i) {
    const L d = lifts.d[i];
    f.off = std::max(f.off, std::abs(d));
    f.light.vertices[i] = p.vertices[i].template cast<L>() - d * lifts.nh;
  }
  for (int i = 0; i < n; ++i) {
    const Vec3<L> ei = p.vertices[(i + 1) % n].template cast<L>() - p.vertices[i].template cast<L>();
    f.edges[i] = ei - lifts.nh.dot(ei) * lifts.nh;
  }
  return f;
}

// The margins under construction: m against the light as given, mm the largest against its accepted
// displacements, lo the smallest against the displacements that only `inner` takes.
struct MarginCandidates {
  L m, mm, lo;
};

// A light off its plane by at most delta / 2: the flat light is an accepted displacement, and so is the flat light
// with the vertices within r = delta / 2 - off of the last kept one dropped (a dropped vertex moves onto that
// vertex's flat position, by at most r + off = delta / 2). Seen from a height h above the plane, an edge whose
// direction leaves the plane by the coordinates' rounding has a plane through x tilted by about (nh.e / |e|)
// dist / h, which flattening removes; an edge shorter still has a direction in the plane of rounding noise and
// can be reflex, which merging removes. Distances are measured between the vertices as given or between their
// flat positions: flattening can shorten an edge along the normal below r.
template <class T> void near_flat_candidates(const PolygonLight<T>& p, const FlatLight& f, const Vec3<L>& xl,
                                             const Vec3<L>& wl, L delta, MarginCandidates& c) {
  const int n = p.count;
  c.mm = std::max(c.mm, polygon_cone_margin<L, T>(f.light, xl, wl, f.edges.data()));
  const L r = delta / 2 - f.off;
  auto within_r = [&](int i, int j) {  // vertices i and j, j before i going around, within r
    Vec3<L> e = Vec3<L>::Zero();
    for (int k = j; k != i; k = (k + 1) % n) e += f.edges[k];
    return (p.vertices[i].template cast<L>() - p.vertices[j].template cast<L>()).norm() <= r || e.norm() <= r;
  };
  std::array<bool, kMaxPolygonVertices> kept{};
  int last = 0;
  kept[0] = true;
  for (int i = 1; i < n; ++i) {
    kept[i] = !within_r(i, last);
    if (kept[i]) last = i;
  }
  for (int i = n - 1; i > 0 && within_r(0, i); --i) kept[i] = false;  // the wrapped-around tail, of vertex 0
  const FlatMerge fm = merge_flat_vertices(f.light, f.edges, kept);
  if (fm.light.count >= 3 && fm.light.count < n)
    c.mm = std::max(c.mm, polygon_cone_margin<L, T>(fm.light, xl, wl, fm.edges.data()));
}

// A light farther off its plane than delta / 2 but within check_polygon's planarity tolerance is accepted as the
// planar light it is near (every kernel takes its side and edge-on test from the area vector and flattens it), and
// its directions are known only up to the angle `moved` by which flattening moves a point of it as seen from x:
// off / dist, dist being x's distance from the flat light (from its plane where x's foot lies inside it, else from
// its nearest edge: a clip point or an edge can be much closer to x than any vertex). Flattened edges no longer than
// off have a direction that is what is left of the cross product, possibly reflex: they are merged into the next
// one (edges summed, exact), which moves the light by the merged lengths more: moved = (off + merged) / (dist -
// merged). outer may take the flat light's margin plus `moved`; inner comes down to its margin less `moved` (the
// kernels' own samples on the flat light's boundary get pdf() 0 by rounding) and to its margin without credit.
template <class T>
void far_flat_candidates(const FlatLight& f, const Vec3<L>& xl, const Vec3<L>& wl, MarginCandidates& c) {
  const int n = f.light.count;
  const Vec3<L>& nh = f.lifts.nh;
  c.lo = std::min(c.lo, polygon_cone_margin<L, T>(f.light, xl, wl, f.edges.data()));
  std::array<bool, kMaxPolygonVertices> kept{};
  L merged = 0;
  for (int i = 0; i < n; ++i) {
    const L incoming = f.edges[(i + n - 1) % n].norm();
    kept[i] = incoming > f.off;
    if (!kept[i]) merged += incoming;
  }
  const FlatMerge fm = merge_flat_vertices(f.light, f.edges, kept);
  const bool use_merged = fm.light.count >= 3 && fm.light.count < n;
  const PolygonLight<L>& fl = use_merged ? fm.light : f.light;
  const Vec3<L>* fle = use_merged ? fm.edges.data() : f.edges.data();
  if (!use_merged) merged = 0;
  const L height = nh.dot(Vec3<L>(xl - f.lifts.c));
  const Vec3<L> foot = xl - height * nh;
  bool inside = true;
  L dist = std::numeric_limits<L>::infinity();
  for (int i = 0; i < fl.count; ++i) {
    const Vec3<L> a = fl.vertices[i], e = fle[i];
    inside = inside && nh.dot(kahan_cross<L>(e, Vec3<L>(foot - a))) >= 0;
    dist = std::min(dist, e.squaredNorm() > 0 ? segment_distance(a, e, xl) : Vec3<L>(a - xl).norm());
  }
  if (inside) dist = std::abs(height);
  dist -= merged;
  const L moved = dist > 0 ? (f.off + merged) / dist : std::numeric_limits<L>::infinity();
  const L fl_margin = polygon_cone_margin<L, T>(fl, xl, wl, fle);
  c.mm = std::max(c.mm, fl_margin + moved);
  c.lo = std::min(c.lo, fl_margin - moved);
}

// Signed angular margins of w inside the light (clipped: also above the shading horizon). `outer` is the largest
// over the light as given and its accepted displacements: the light with its short edges merged; a light within
// delta / 2 of its diameter segment (a sliver) measured against that segment's arc; a light within delta / 2 of
// its plane against its flattening (near_flat_candidates); a light within check_polygon's planarity tolerance
// against its flattening with a credit (far_flat_candidates). A sample must lie inside some accepted displacement
// (outer >= -tol). `inner` is the smallest of the light as given, the displacements' largest, and the flat
// light's margins that far_flat_candidates gives it: a density of 0 needs w near the boundary of some accepted
// displacement (inner <= tol).
struct PolygonMargins {
  L inner, outer;
};
template <class T> PolygonMargins polygon_margins(const PolygonLightGeometry<T>& g, const Vec3<T>& w, bool clipped) {
  const PolygonLight<T>& light = g.light;
  const Vec3<T>& x = g.shading.position;
  const int n = light.count;
  MarginCandidates c;
  c.m = polygon_cone_margin(light, x, w);
  c.mm = c.m;
  c.lo = std::numeric_limits<L>::infinity();
  const PolygonLight<T> merged = merge_short_edges(light, x);
  if (merged.count >= 3 && merged.count < n) c.mm = polygon_cone_margin(merged, x, w);
  if (merged.count == 1 || merged.count == 2)  // merged down to a segment or a point: the light is within delta of it
    c.mm = -arc_distance(merged.vertices[0], merged.vertices[merged.count - 1], x, w);
  const Vec3<L> xl = x.template cast<L>();
  const L mag = max_abs_coordinate(light), delta = displacement_budget(mag, x);
  const PolygonDiameter diam = polygon_diameter(light);
  if (diam.length > 0) {  // a sliver: every vertex within delta / 2 of the line through its two farthest ones
    const Vec3<L> a = light.vertices[diam.a].template cast<L>(), e = light.vertices[diam.b].template cast<L>() - a;
    L width = 0;
    for (int i = 0; i < n; ++i)
      width =
          std::max(width, kahan_cross<L>(Vec3<L>(light.vertices[i].template cast<L>() - a), e).norm() / diam.length);
    if (width <= delta / 2) c.mm = std::max(c.mm, -arc_distance(light.vertices[diam.a], light.vertices[diam.b], x, w));
  }
  const PolygonLifts lifts = polygon_lifts(light);
  if (lifts.area2 > 0 && n >= 3) {
    const FlatLight f = flatten_light(light, lifts);
    const Vec3<L> wl = w.template cast<L>();
    const L planarity =
        diam.length > 0 ? L(polygon_planarity_tolerance<T>(T(lifts.area2 / diam.length), T(mag))) : L(0);
    if (f.off > 0 && f.off <= delta / 2) near_flat_candidates(light, f, xl, wl, delta, c);
    if (f.off > delta / 2 && f.off <= planarity) far_flat_candidates<T>(f, xl, wl, c);
  }
  if (clipped) {
    const L h = g.shading.normal.template cast<L>().normalized().dot(w.template cast<L>().normalized());
    c.m = std::min(c.m, h), c.mm = std::min(c.mm, h);  // inner <= m <= h already: lo needs no clamp
  }
  return {std::min({c.m, c.mm, c.lo}), std::max(c.m, c.mm)};
}

template <class T, class Sample, class Pdf>
void check_polygon_kernel(FuzzedDataProvider& in, const PolygonLightGeometry<T>& g, const char* name, bool clipped,
                          PolygonDensity density, Sample&& sample, Pdf&& pdf) {
  const bool finite_input = polygon_input_finite(g);
  const bool valid_polygon = check_polygon(g.light) == NoSample::kNone;
  const L tol = finite_input && valid_polygon ? L(kTolUlps) * eps<T>() * polygon_kappa(g, clipped) : L(0);
  const int samples = in.ConsumeIntegralInRange<int>(1, 3);
  for (int k = 0; k < samples; ++k) {
    const Vec2<T> u = unit_square<T>(in);
    const DirectionSample<T> s = sample(u);
    const std::string geo = describe(g, u, name);
    check_sample_shape(s, geo);
    if (!finite_input) WARPCHECK_FUZZ_REQUIRE(!s.valid(), "a sample from non-finite input", geo);
    if (!s.valid()) continue;
    WARPCHECK_FUZZ_REQUIRE(valid_polygon, "a sample from a polygon that check_polygon rejects", geo);
    const PolygonMargins margins = polygon_margins(g, s.direction, clipped);
    WARPCHECK_FUZZ_REQUIRE(
        margins.outer >= -tol, "direction outside the polygon",
        geo << "direction " << show(s.direction) << " margin " << margins.outer << " tol " << tol << "\n");
    L rel = 8 * eps<T>();
    if (density == PolygonDensity::kCosine || density == PolygonDensity::kArea) {
      // The cosine both densities are computed from (shading normal resp. light normal, in T).
      const Vec3<T> axis =
          density == PolygonDensity::kCosine ? Vec3<T>(g.shading.normal) : polygon_area_vector(g.light);
      const L c = std::abs(axis.template cast<L>().normalized().dot(s.direction.template cast<L>()));
      rel = c > 0 ? rel * (density == PolygonDensity::kArea ? 3 : 1) / c : L(1);
    }
    check_pdf_consistency<T>(s.pdf, pdf(s.direction), rel, margins.inner, tol, geo);
  }
  // The density at an arbitrary unit direction: finite, >= 0, zero for invalid geometry and well outside.
  const Vec3<T> w = safe_normalized(
      in.ConsumeBool() ? vec3<T>(in) : Vec3<T>(polygon_centroid(g.light) - g.shading.position + vec3<T>(in)));
  const T p = pdf(w);
  const std::string geo = describe(g, Vec2<T>(Vec2<T>::Zero()), name) + "pdf at w " + show(w) + "\n";
  WARPCHECK_FUZZ_REQUIRE(std::isfinite(p) && p >= T(0), "pdf not finite and >= 0", geo << "pdf " << p << "\n");
  if (!finite_input || !valid_polygon) {
    WARPCHECK_FUZZ_REQUIRE(p == T(0), "pdf > 0 for invalid geometry", geo << "pdf " << p << "\n");
  } else if (!w.isZero()) {
    const L margin = polygon_margins(g, w, clipped).outer;
    if (margin < -tol)
      WARPCHECK_FUZZ_REQUIRE(p == T(0), "pdf > 0 outside the polygon",
                             geo << "pdf " << p << " margin " << margin << " tol " << tol << "\n");
  }
}

// Projected-solid-angle sampling, Peters 2021 Sec. 3 (0 to 4 tangent-line iterations; the catalogue's
// configuration has 2) or its biased variant of Sec. 6.4; samples lie in the polygon clipped to the shading
// horizon. The byte after the geometry chose the variant when one target checked both: it is read and ignored, so
// that the stored inputs decode as they did.
template <class T, bool kBiased> void check_polygon_projected(FuzzedDataProvider& in) {
  const PolygonLightGeometry<T> g = decode_polygon_geometry<T>(in);
  (void)in.ConsumeIntegralInRange<int>(0, 3);
  int iterations = 0;
  if (!kBiased) iterations = in.ConsumeIntegralInRange<int>(0, 4);
  const PolygonProjectedView<T> v = make_polygon_projected_view<T, kBiased>(g);
  check_polygon_kernel<T>(
      in, g, PolygonProjectedSolidAngleKernel<T, kBiased>::name, true, PolygonDensity::kCosine,
      [&](const Vec2<T>& u) { return sample_polygon_projected_solid_angle<T, kBiased>(v, u, iterations); },
      [&](const Vec3<T>& w) {
        return kBiased ? pdf_polygon_projected_solid_angle(v, w) : pdf_polygon_projected_solid_angle(g, w);
      });
}

// Solid-angle sampling, Peters 2021 Sec. 5, of the whole polygon or clipped to the shading horizon. The byte after
// the geometry chose whether to clip when one target checked both: it is read and ignored, so that the stored
// inputs decode as they did.
template <class T, bool kClipped> void check_polygon_solid_angle(FuzzedDataProvider& in) {
  const PolygonLightGeometry<T> g = decode_polygon_geometry<T>(in);
  (void)in.ConsumeBool();
  const PolygonSolidAngleView<T> v = make_polygon_solid_angle_view(g, kClipped);
  check_polygon_kernel<T>(
      in, g, PolygonSolidAngleKernel<T, kClipped>::name, kClipped, PolygonDensity::kConstant,
      [&](const Vec2<T>& u) { return sample_polygon_solid_angle(v, u); },
      [&](const Vec3<T>& w) { return pdf_polygon_solid_angle(g, w, kClipped); });
}

}  // namespace warpcheck::fuzz
