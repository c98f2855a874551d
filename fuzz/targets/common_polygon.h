// fuzz/targets/common_polygon.h: the invariant checks shared by the polygon families (not a family itself:
// files named common*.h are helpers). A polygon family decodes a geometry with decode_polygon /
// decode_polygon_shading and calls check_polygon_kernel with its sampler and density.
#pragma once

#include "common.h"

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

template <class T> bool polygon_input_finite(const PolygonLightGeometry<T>& g) {
  for (int i = 0; i < std::min(g.light.count, kMaxPolygonVertices); ++i)
    if (!all_finite(g.light.vertices[i])) return false;
  return all_finite(g.shading.position) && all_finite(g.shading.normal);
}

// The conditioning kappa of the header comment; for kernels clipped to the horizon also the clip points'
// (|p| + |q| + |V_j|_inf + |V_{j+1}|_inf + |x|_inf) / dist(x, line of the edge) for every edge that crosses
// the horizon: the clip point lies on that line, so its direction is known to eps_T times that ratio.
//
// The vertex term of common.h bounds the angular error of a boundary point P by delta / |P - x| with |P - x| >= the
// distance to the nearest vertex; but a boundary point may lie closer to x than every vertex: on an edge that
// passes near x. The same argument (a point of the moved polygon outside the exact cone lies within delta of the
// exact boundary) gives delta / dist(x, boundary), so every edge contributes
// (max(|V_j|_inf, |V_{j+1}|_inf) + |x|_inf + 16 min_T) / dist(x, segment V_j V_{j+1}) (found by
// fuzz_polygon_projected_double: an edge passing 4e-14 from x, whose great circle through x the coordinates
// do not determine, issue 7). The horizon arcs of a clipped polygon lie on the exactly known horizon.
// P: the geometry's type (T, or L for a light computed in long double, ltc.h); T: the kernel's precision.
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

// The light with every vertex dropped that lies within delta / 2 of its predecessor, delta = kTolUlps eps_T
// (max_k |V_k|_inf + |x|_inf + 16 min_T) being the vertex displacement that the tolerance accepts (common.h).
// An edge that short has a direction the coordinates do not determine: the polygon can be reflex at it (an
// edge of subnormal length pointing out of the light's plane) and its great circle then cuts through the light.
// The merged polygon is one of the accepted displacements of the light (found by
// fuzz_polygon_solid_angle_double: edges of length 5e-324, 9e-308 and 3e-15, issue 7).
template <class T> PolygonLight<T> merge_short_edges(const PolygonLight<T>& p, const Vec3<T>& x) {
  const int n = p.count;
  L mag = 0;
  for (int i = 0; i < n; ++i) mag = std::max(mag, L(p.vertices[i].template cast<L>().cwiseAbs().maxCoeff()));
  const L delta =
      L(kTolUlps) * eps<T>() *
      (mag + L(x.template cast<L>().cwiseAbs().maxCoeff()) + kSubnormalUlps * L(std::numeric_limits<T>::min()));
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

// The flat light (vertices `flat`, exact edges fe_i = flat_{i+1} - flat_i) with the vertices not `kept` dropped:
// a dropped vertex's outgoing edge joins the last kept vertex's, so the merged edges are sums of exact edges.
// Used by both merges of the flattened light in polygon_margins, which differ only in which vertices they keep.
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

// Signed angular margins of w inside the light (clipped: also above the shading horizon): `outer` the largest over
// the light as given and its accepted displacements (merge_short_edges(light), a sliver's arc, the flat light, the
// flat light merged, the flattened light with its credit; below), `inner` the smallest over the light as given, the
// largest of the displacements' margins, and, off the plane beyond delta / 2, the flat light's own margin without
// credit (80cce1ce below), and the flattened light's margin less its credit (e9b7708c below). A sample must lie inside
// some accepted displacement of the light (outer >= -tol); a density of 0 needs w near the boundary of some accepted
// displacement (inner <= tol).
struct PolygonMargins {
  L inner, outer;
};
template <class T> PolygonMargins polygon_margins(const PolygonLightGeometry<T>& g, const Vec3<T>& w, bool clipped) {
  L m = polygon_cone_margin(g.light, g.shading.position, w);
  const PolygonLight<T> merged = merge_short_edges(g.light, g.shading.position);
  L mm = m;
  // The smallest margin against an accepted displacement that only `inner` takes: the flat light's without credit
  // (80cce1ce) and with its credit subtracted (e9b7708c), below.
  L lo = std::numeric_limits<L>::infinity();
  if (merged.count >= 3 && merged.count < g.light.count) mm = polygon_cone_margin(merged, g.shading.position, w);
  // Merged down to a segment or a point: the light is within delta of it, so the accepted displacements' cones
  // are within the tolerance of its arc (a polygon of width 6 and length 1e30: a sliver).
  if (merged.count == 1 || merged.count == 2)
    mm = -arc_distance(merged.vertices[0], merged.vertices[merged.count - 1], g.shading.position, w);
  // Other accepted displacements: a light within delta / 2 of a segment (a sliver: its width, the largest
  // distance of a vertex from the line through its two farthest vertices, is at most delta / 2) is measured
  // against that segment's arc; a light within delta / 2 of its plane against its vertices moved onto the
  // plane (long double). A light non-planar below its coordinates' rounding, seen from x much closer to its
  // plane than its shortest edge is long, is reflex at that edge (found by fuzz_polygon_projected_double: x
  // 1.9e-26 from a light of size 1.5e-15, an edge 2.4e-26 long, off-plane residues 5e-32, issue 7).
  {
    const int n = g.light.count;
    const Vec3<L> xl = g.shading.position.template cast<L>();
    L mag = 0;
    for (int i = 0; i < n; ++i) mag = std::max(mag, L(g.light.vertices[i].template cast<L>().cwiseAbs().maxCoeff()));
    const L delta =
        L(kTolUlps) * eps<T>() * (mag + xl.cwiseAbs().maxCoeff() + kSubnormalUlps * L(std::numeric_limits<T>::min()));
    int ia = 0, ib = 0;
    L diam = 0;
    for (int i = 0; i < n; ++i)
      for (int j = i + 1; j < n; ++j) {
        const L d = (g.light.vertices[i].template cast<L>() - g.light.vertices[j].template cast<L>()).norm();
        if (d > diam) diam = d, ia = i, ib = j;
      }
    if (diam > 0) {
      const Vec3<L> a = g.light.vertices[ia].template cast<L>(), e = g.light.vertices[ib].template cast<L>() - a;
      L width = 0;
      for (int i = 0; i < n; ++i)
        width = std::max(width, kahan_cross<L>(Vec3<L>(g.light.vertices[i].template cast<L>() - a), e).norm() / diam);
      if (width <= delta / 2)
        mm = std::max(mm, -arc_distance(g.light.vertices[ia], g.light.vertices[ib], g.shading.position, w));
    }
    const PolygonLifts lifts = polygon_lifts(g.light);
    const L an = lifts.area2;
    if (an > 0 && n >= 3) {
      const Vec3<L> nh = lifts.nh;
      PolygonLight<L> flat;
      flat.count = n;
      L off = 0;
      for (int i = 0; i < n; ++i) {
        const L d = lifts.d[i];
        off = std::max(off, std::abs(d));
        flat.vertices[i] = g.light.vertices[i].template cast<L>() - d * nh;
      }
      // The flat light's edges flat_{j+1} - flat_j = e_j - (nh.e_j) nh, e_j = V_{j+1} - V_j (the d_j differ by
      // nh.e_j), from the exact differences e_j: the difference of the rounded flat vertices leaves a short edge
      // tilted out of the plane by eps_L |V| / |e_j|, and seen from x close to the plane its edge plane then
      // cuts through the light (found by fuzz_ltc_double with M = I, 9e426f21: an edge of 2.2e-13 at |V| ~ 3,
      // tilt 1.5e-6, x 1e-13 from the plane, a sample at -8.1e-10 against that plane; issue 7).
      std::array<Vec3<L>, kMaxPolygonVertices> fe;
      for (int i = 0; i < n; ++i) {
        const Vec3<L> ei = g.light.vertices[(i + 1) % n].template cast<L>() - g.light.vertices[i].template cast<L>();
        fe[i] = ei - nh.dot(ei) * nh;
      }
      const Vec3<L> wl = w.template cast<L>();
      // The flat light itself, without credit, beyond delta / 2 off the plane: there every kernel flattens (delta / 2
      // = 32 eps (|V|_inf + |x|_inf) exceeds make_polygon_view's 8 eps reach) and its density tests w against the
      // flat light's planes (polygon_inward_planes), so a density of 0 is expected within tol of that boundary, which
      // can lie up to off / dist inside the light as given. The flat light is an accepted displacement, so its margin
      // is one of `inner`'s candidates (the returned minimum); only `outer` credits the move (below). This excuses a
      // density of 0 at a sample inside the light as given but more than tol outside the flat one, which outer,
      // accepting both, does not flag either: a sampler that strays from its own flattened light by less than the
      // credit is not detected here. (Found by fuzz_ltc_double 80cce1ce with M = I: a quad with two vertices at
      // 4.4e12, non-planar by 0.31 (check_polygon's planarity tolerance, 8 sqrt(eps) of its width 3.1e12, is 3.7e5),
      // x 0.31 off its plane, 1.9e5 from its near vertices and 1.3e5 from its edges V0 V1 and V2 V3: the kernel
      // flattened it, and its own sample lay 1e-10 rad outside the flat light's plane of edge V0 V1 (within the
      // kernel's rounding, tol 1.4e-6), pdf 0 there and at the probes, 2.3e-6 rad inside the light as given;
      // flattening turns that edge's plane by up to 0.31 / 1.3e5 = 2.4e-6 rad. issue 7.) Below delta / 2 the flat
      // light is within the budget of the light as given and enters outer only.
      const L planarity = diam > 0 ? L(polygon_planarity_tolerance<T>(T(an / diam), T(mag))) : L(0);
      if (off > delta / 2 && off <= planarity) lo = std::min(lo, polygon_cone_margin<L, T>(flat, xl, wl, fe.data()));
      if (off > 0 && off <= delta / 2) {
        mm = std::max(mm, polygon_cone_margin<L, T>(flat, xl, wl, fe.data()));
        // The flat light with its short edges merged. Seen from x at a height h above the plane, an edge e whose
        // direction leaves the plane by the coordinates' rounding (nh.e / |e|, up to eps |V| / |e|) has a plane
        // through x tilted against the flat edge's by about (nh.e / |e|) dist / h, which can cut the light, and
        // flattening removes that; an edge shorter still has a direction in the plane of rounding noise too and can
        // be reflex, and merging removes that: each of the two displacements repairs one of them, and neither alone
        // the light (found by fuzz_ltc_double 026c1719 with M = I: an octagon non-planar by 4.2e-16, x 2.5e-7 off its
        // plane; its edge V0 V1 of 1.7e-10 leaves the plane by 3.8e-17, so its plane through x cut 4.4e-8 rad into
        // the light at V3, and the sample on the edge V3 V4 lay 4.9e-8 rad behind it; the flat light has V7, 3.1e-15
        // from V0, reflex by 2.7 rad, and that edge's plane lay 1.7e-7 rad behind the sample; the flat light with V7
        // merged into V0 contains it, margin +8.7e-17; issue 7). A vertex within r = delta / 2 - off of the last kept
        // one (the wrapped-around tail: of vertex 0, as merge_short_edges) is dropped, i.e. moved onto that vertex's
        // flat position, by at most r + off = delta / 2, the budget of each displacement above; a kept vertex moves
        // by its |d_k| <= off. The merged edges are sums of the exact flat edges fe.
        const L r = delta / 2 - off;
        // Measured between the vertices as given or between their flat positions (flat_i - flat_last, the sum of
        // the exact flat edges between them): either bounds the move by r + off. The flat distance catches an edge
        // longer than r that flattening shortens below it (found by fuzz_polygon_solid_angle_double 4a059601: an
        // edge V2 V3 of 1.2e-10 along the normal of a light non-planar by 2.9e-11, r 1e-11, flattened to ~7e-21
        // and reflex; x 7700 away; the flat light's plane of that edge cut 1.6e-6 rad into the light, and the
        // sample, on the edge V0 V1, lay behind it; with V3 merged into V2 it is inside by 8e-15 rad; issue 7).
        auto within_r = [&](int i, int j) {  // vertices i and j, j before i going around, within r
          Vec3<L> f = Vec3<L>::Zero();
          for (int k = j; k != i; k = (k + 1) % n) f += fe[k];
          return (g.light.vertices[i].template cast<L>() - g.light.vertices[j].template cast<L>()).norm() <= r ||
                 f.norm() <= r;
        };
        std::array<bool, kMaxPolygonVertices> kept{};
        int last = 0;
        kept[0] = true;
        for (int i = 1; i < n; ++i) {
          kept[i] = !within_r(i, last);
          if (kept[i]) last = i;
        }
        for (int i = n - 1; i > 0 && within_r(0, i); --i) kept[i] = false;
        const FlatMerge fm = merge_flat_vertices(flat, fe, kept);
        if (fm.light.count >= 3 && fm.light.count < n)
          mm = std::max(mm, polygon_cone_margin<L, T>(fm.light, xl, wl, fm.edges.data()));
      }
      // A light farther off its plane than that, but within check_polygon's planarity tolerance, is accepted as
      // the planar light it is near (polygon_planarity_tolerance, polygon.h; every kernel takes its side and its
      // edge-on test from the area vector), and its directions are known only up to its non-planarity: the angle
      // by which flattening moves a point of it as seen from x. Its flattening, within that angle, is an accepted
      // displacement too. Where x sees an edge of the unflattened light end-on, that
      // edge's plane through x is set by the non-planarity alone and can cut the light's cone down to a plane
      // (found by fuzz_polygon_solid_angle_double 56a30637: a vertex 4.2e-11 off the plane of a light of width
      // 15, x on the line of its 5.8e-11 long edge up to a subnormal z; a sample on the edge V2 V3, 1.2e-10 rad
      // on the far side of the end-on edge's plane, and 8.7e-12 rad outside the flattened light, whose vertices
      // moved by up to 3.1e-11 rad; issue 7).
      // The angle is off / dist over the light, not only at its vertices: a clip point or the nearest point of the
      // light can be much closer to x than any vertex (a5fc8f53: the same light seen from 0.009 off its plane, a
      // sample at a horizon clip point 1.5 from x with the vertices ~5.6 away, 6.6e-12 rad outside the flattened
      // light). So dist is x's distance from the flattened polygon: from its plane where x's foot lies inside it,
      // else from its nearest edge.
      // An edge of the light that is (nearly) along nh flattens to a remnant no longer than the non-planarity,
      // whose direction in the plane is what is left of the cross product: the flattening can be reflex there,
      // and that edge's plane through x then cuts the flat light's cone (found by
      // fuzz_polygon_solid_angle_double bedd9183: an edge of 2.9e-11 along the normal of a light non-planar by
      // 1.5e-11, flattened to 1.7e-21; x 4.4e-11 off the plane; the sample, at a vertex of the light, 1.1e-11 rad
      // behind that remnant's plane). So flattened edges no longer than off are merged into the next one (the
      // vertex they end at dropped, the edge vectors summed, so they stay exact), which moves the flat light by
      // at most the merged lengths more: the credit is (off + merged) / dist, dist less the merged lengths.
      if (off > delta / 2 && off <= planarity) {
        std::array<bool, kMaxPolygonVertices> kept{};
        L merged = 0;
        for (int i = 0; i < n; ++i) {
          const L incoming = fe[(i + n - 1) % n].norm();
          kept[i] = incoming > off;
          if (!kept[i]) merged += incoming;
        }
        const FlatMerge fm = merge_flat_vertices(flat, fe, kept);
        const bool use_merged = fm.light.count >= 3 && fm.light.count < n;
        const PolygonLight<L>& fl = use_merged ? fm.light : flat;
        const Vec3<L>* fle = use_merged ? fm.edges.data() : fe.data();
        if (!use_merged) merged = 0;
        const L height = nh.dot(Vec3<L>(xl - lifts.c));
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
        const L moved = dist > 0 ? (off + merged) / dist : std::numeric_limits<L>::infinity();
        const L fl_margin = polygon_cone_margin<L, T>(fl, xl, Vec3<L>(w.template cast<L>()), fle);
        mm = std::max(mm, fl_margin + moved);
        // The same accepted displacements bound `inner` from below: a density of 0 is allowed near the boundary of
        // any of them, and the credit above takes them as the cones whose great circles lie within `moved` of the
        // flat light's, so inner may come down to fl_margin - moved (the outer credit, from the other side). The
        // kernels sample and test the flattened light (make_polygon_view), and their samples on its boundary (a
        // fan vertex at u = (0, 0)) get pdf() 0 from the planes through that vertex by rounding; measured against
        // the light as given, such a sample is inside by up to the angle flattening moved it (found by
        // fuzz_polygon_solid_angle_double e9b7708c: vertex 0 1.5e-11 off the plane y = 0 of the others, lifts
        // +-3.7e-12, x 1 above the plane; the sample at the flattened vertex V3, 7.3e-13 rad inside the light as
        // given (tol 1.4e-13), -1e-16 against the flat light's planes through V3, moved 3.7e-12; issue 7).
        lo = std::min(lo, fl_margin - moved);
      }
    }
  }
  if (clipped) {
    const L h = g.shading.normal.template cast<L>().normalized().dot(w.template cast<L>().normalized());
    m = std::min(m, h), mm = std::min(mm, h);  // inner <= m <= h already: lo needs no clamp
  }
  return {std::min({m, mm, lo}), std::max(m, mm)};
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

}  // namespace warpcheck::fuzz
