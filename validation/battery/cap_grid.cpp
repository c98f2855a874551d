// The grid quadrature of the battery (cap_grid.h).
#include "battery/cap_grid.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <boost/math/quadrature/gauss.hpp>
#include <boost/math/quadrature/gauss_kronrod.hpp>
#include <cmath>
#include <mutex>

#include "battery/circles.h"
#include "battery/drawing.h"

namespace warpcheck::validation::battery {
namespace {

// Gauss-Kronrod 15 (Kronrod weights wk, Gauss 7 weights wg, zero off the Gauss nodes) on [0, 1], from Boost's
// nodes and weights on [0, 1] of the symmetric rule on [-1, 1].
struct Rule15 {
  std::array<Real, 15> v, wk, wg;
  Rule15() {
    using GK = boost::math::quadrature::gauss_kronrod<Real, 15>;
    using G = boost::math::quadrature::gauss<Real, 7>;
    for (int i = 0; i < 8; ++i) {
      const Real x = GK::abscissa()[i], k = GK::weights()[i] / 2, g = i % 2 == 0 ? G::weights()[i / 2] / 2 : 0;
      v[7 + i] = (1 + x) / 2, wk[7 + i] = k, wg[7 + i] = g;
      v[7 - i] = (1 - x) / 2, wk[7 - i] = k, wg[7 - i] = g;
    }
  }
};
const Rule15 kRule15;

// Gauss-Legendre 3 on [0, 1].
constexpr int kSlabNodes = 3;
const Real kG3v[3] = {(1 - std::sqrt(Real(0.6))) / 2, Real(0.5), (1 + std::sqrt(Real(0.6))) / 2};
const Real kG3w[3] = {Real(5) / 18, Real(8) / 18, Real(5) / 18};

// The cubic substitution x = a + (b - a)(3 v^2 - 2 v^3): dx/dv = 6 (b - a) v (1 - v) vanishes at both ends, which
// turns an inverse-square-root singularity at an end (the visible-area pdf at the cap's edge) into a bounded
// integrand and a square-root kink (a ring tangent to a boundary circle) into a smooth one.
Real cubic_x(Real a, Real b, Real v) { return a + (b - a) * v * v * (3 - 2 * v); }
Real cubic_dx(Real a, Real b, Real v) { return 6 * (b - a) * v * (1 - v); }

// A 1D interval of a line or ring, integrated on its own and added to slot `slot` of the result.
struct Piece {
  Real a, b;
  int slot;
  bool whole;  // the whole ring (column) `slot`: its nodes come from a table shared by every line (ring)
};

// The cap's frame, and directions by (t, phi): 1 - cos(theta) = t omc.
struct CapFrame {
  Frame<Real> fr;
  Real omc;
  explicit CapFrame(const Cap<Real>& cap) : fr(Frame<Real>::from_z(cap.axis)), omc(cap.one_minus_cos) {}
  Vec3L dir(Real t, Real c, Real s) const {
    const Real o = t * omc, sin_t = std::sqrt(std::max<Real>(0, o * (2 - o)));
    return fr.to_world(Vec3L(sin_t * c, sin_t * s, 1 - o));
  }
};

// The 15 Kronrod nodes of a piece: directions and the weight of the parameter's change of variables.
struct PieceNodes {
  std::array<Vec3L, 15> w;
  std::array<Real, 15> jac;
};

// Integrates pieces of one 1D path with Gauss-Kronrod 15, through one block call of the pdf (nodes(p, out) gives
// piece p's nodes; direction(p, v) one direction for the adaptive rule), and adds each piece to out[slot]. A
// piece whose |K15 - G7| exceeds rel_tol times max(|piece|, 1e-3 |path|) is integrated again adaptively.
template <class Nodes, class Direction>
void integrate_pieces(const SamplerUnderTest& s, const std::vector<Piece>& pieces, Real rel_tol, const Nodes& nodes,
                      const Direction& direction, std::vector<Real>& out, long& calls) {
  const std::size_t n = pieces.size() * 15;
  std::vector<Vec3L> w(n);
  std::vector<Real> f(n), jac(n);
  PieceNodes pn;
  for (std::size_t p = 0; p < pieces.size(); ++p) {
    nodes(pieces[p], pn);
    std::copy(pn.w.begin(), pn.w.end(), w.begin() + std::ptrdiff_t(15 * p));
    std::copy(pn.jac.begin(), pn.jac.end(), jac.begin() + std::ptrdiff_t(15 * p));
  }
  pdf_many(s, w, f);
  calls += long(n);
  std::vector<Real> k(pieces.size(), 0), e(pieces.size(), 0);
  Real total = 0;
  for (std::size_t p = 0; p < pieces.size(); ++p) {
    Real g = 0;
    for (int i = 0; i < 15; ++i) {
      const Real y = std::isfinite(f[15 * p + i]) ? f[15 * p + i] * jac[15 * p + i] : Real(0);
      k[p] += kRule15.wk[i] * y, g += kRule15.wg[i] * y;
    }
    e[p] = std::abs(k[p] - g), total += std::abs(k[p]);
  }
  for (std::size_t p = 0; p < pieces.size(); ++p) {
    if (e[p] > rel_tol * std::max(std::abs(k[p]), Real(1e-3) * total)) {
      auto g = [&](Real v) {
        Real j;
        const Real y = s.pdf(direction(pieces[p], v, j));
        ++calls;
        return std::isfinite(y) ? y * j : Real(0);
      };
      k[p] = integrate_adaptive(g, 0, 1, rel_tol, rel_tol * Real(1e-3) * total, 16).value;
    }
    out[std::size_t(pieces[p].slot)] += k[p];
  }
}

// t of a polar angle theta in [0, pi]: 1 - cos(theta) = 2 sin^2(theta / 2) keeps its precision near the axis.
Real t_of_polar(Real theta, Real omc) {
  const Real sh = sine(theta / 2);
  return 2 * sh * sh / omc;
}
void push_t(Real theta, Real omc, std::vector<Real>& t) {
  const Real x = t_of_polar(theta, omc);
  if (x > 0 && x < 1) t.push_back(x);
}

// t where the radial line at azimuth (c, s) crosses each circle.
void line_crossings(const std::vector<Circle>& m, Real omc, Real c, Real s, std::vector<Real>& t) {
  std::vector<Real> theta;
  line_crossing_angles(m, c, s, theta);
  for (Real x : theta) push_t(x, omc, t);
}

// Corners of the boundary inside the cap: (t, phi) where two circles meet.
std::vector<std::pair<Real, Real>> corners(const std::vector<Circle>& m, Real omc) {
  std::vector<std::pair<Real, Real>> out;
  for (std::size_t i = 0; i < m.size(); ++i)
    for (std::size_t j = i + 1; j < m.size(); ++j)
      for (const Vec3L& q : circle_intersections(m[i], m[j])) {
        const Real t = (q - Vec3L(0, 0, 1)).squaredNorm() / 2 / omc;
        Real phi = std::atan2(q.y(), q.x());
        if (phi < 0) phi += kTwoPi<Real>;
        if (t > 0 && t < 1) out.emplace_back(t, phi);
      }
  return out;
}

// Sorted, unique edges in [lo, hi] from a list (ends included).
std::vector<Real> edges_of(std::vector<Real> e, Real lo, Real hi) {
  e.push_back(lo), e.push_back(hi);
  std::erase_if(e, [&](Real x) { return !(x >= lo && x <= hi); });
  std::sort(e.begin(), e.end());
  e.erase(std::unique(e.begin(), e.end()), e.end());
  return e;
}

// A slab [a, b] of the outer variable (phi for lines, t for rings), integrated with Gauss-Legendre 3. With
// `edge_singular` the rule runs in y = sqrt(1 - x) (x = (1 - y)(1 + y), dx = 2 y dy), which makes an
// inverse-square-root singularity at x = 1 (the visible-area pdf at the cap's edge, integrated over rings) smooth
// in every slab. An end at a tangency of the boundary (bit 1: a, bit 2: b) has a square-root kink: there the rule
// runs in the quadratic substitution y = a + (b - a) v^2, which makes every power (y - a)^(k/2) a polynomial in v
// (the cubic 3 v^2 - 2 v^3 where both ends are kinks).
struct Slab {
  Real a, b;
  int kinked_ends;
  int depth = 0;
  std::array<Real, 3> x{}, weight{};
  std::array<std::vector<Real>, 3> value;  // the line's (ring's) integral per ring (column) at each node
  long calls = 0;
  std::vector<Real> parent;  // a kinked slab's parent's rule per component, when it was halved from one
  int sibling = 0;           // then the offset of the other half in its batch
};

// The slab's rule per component.
std::vector<Real> rule(const Slab& sl) {
  std::vector<Real> r(sl.value[0].size(), 0);
  for (int i = 0; i < kSlabNodes; ++i)
    for (std::size_t j = 0; j < r.size(); ++j) r[j] += sl.weight[i] * sl.value[i][j];
  return r;
}

// y(v) on [a, b] and dy/dv for the kinked ends (Slab).
void substitute(Real a, Real b, int kinked_ends, Real v, Real& y, Real& dy) {
  const Real h = b - a;
  switch (kinked_ends) {
    case 0:
      y = a + h * v, dy = h;
      return;
    case 1:
      y = a + h * v * v, dy = 2 * h * v;
      return;
    case 2:
      y = b - h * (1 - v) * (1 - v), dy = 2 * h * (1 - v);
      return;
    default:
      y = cubic_x(a, b, v), dy = cubic_dx(a, b, v);
  }
}

void place_nodes(Slab& sl, bool edge_singular) {
  const Real a = edge_singular ? std::sqrt(1 - sl.b) : sl.a, b = edge_singular ? std::sqrt(1 - sl.a) : sl.b;
  // y = sqrt(1 - x) reverses the slab: x's end a is y's end b.
  const int kinked = edge_singular ? ((sl.kinked_ends & 1) << 1) | ((sl.kinked_ends & 2) >> 1) : sl.kinked_ends;
  for (int i = 0; i < kSlabNodes; ++i) {
    Real y, dy;
    substitute(a, b, kinked, kG3v[i], y, dy);
    dy *= kG3w[i];
    sl.x[i] = edge_singular ? (1 - y) * (1 + y) : y, sl.weight[i] = edge_singular ? 2 * y * dy : dy;
  }
}

// Whether a slab's three values bend more than a 3-point rule resolves: the second difference of any component
// beyond `threshold` (CapGridSpec::bend, 1e-2) of that component (or of 1e-3 of the total, for the small ones). A
// smooth integrand varying on a scale s has a relative second difference d of about 0.15 (h / s)^2 and the rule a
// relative error of about (h / s)^6 / 2e6 = (d / 0.15)^3 / 2e6: 1.5e-10 at the threshold.
bool bends(const Slab& sl, Real threshold) {
  const std::vector<Real>&l = sl.value[0], &c = sl.value[1], &r = sl.value[2];
  Real total = 0;
  for (Real v : c) total += std::abs(v);
  for (std::size_t j = 0; j < c.size(); ++j)
    if (std::abs(l[j] - 2 * c[j] + r[j]) > threshold * std::max(std::abs(c[j]), Real(1e-3) * total)) return true;
  return false;
}

// Whether the two halves of a kinked slab agree with their parent's rule to `tol` of each component (or of 1e-3 of
// the total): the kink's higher terms (y - a)^(k/2), k >= 5, escape the 3-point rule in proportion to the slab's
// width against the boundary's size, which the second difference does not see.
bool halving_agrees(const Slab& half, const Slab& other, Real tol) {
  const std::vector<Real> a = rule(half), b = rule(other);
  Real total = 0;
  for (Real v : half.parent) total += std::abs(v);
  for (std::size_t j = 0; j < a.size(); ++j)
    if (std::abs(a[j] + b[j] - half.parent[j]) > tol * std::max(std::abs(a[j] + b[j]), Real(1e-3) * total))
      return false;
  return true;
}

// Integrates the slabs (eval(x, values, calls) gives the vector of one line or ring), halving a slab that bends
// or, at a kink, until halving agrees with the whole (up to max_depth times, 8: to 1/256 of its width, and not
// below `resolution`), and returns the leaf slabs in order.
template <class Eval>
std::vector<Slab> integrate_slabs(std::vector<Slab> todo, bool edge_singular, const CapGridSpec& sp, const Eval& eval) {
  const int threads = sp.threads;
  std::vector<Slab> done;
  while (!todo.empty()) {
    for (Slab& sl : todo) place_nodes(sl, edge_singular);
    parallel_for(todo.size() * kSlabNodes, threads, [&](std::size_t k) {
      Slab& sl = todo[k / kSlabNodes];
      long calls = 0;
      eval(sl.x[k % kSlabNodes], sl.value[k % kSlabNodes], calls);
      std::atomic_ref<long>(sl.calls).fetch_add(calls);
    });
    // Decided before any slab moves (a half's test reads its sibling). A slab beside one that bends is halved too:
    // at an inflection point (a peak's flank) the second difference vanishes, the rule's error does not.
    // todo is sorted (children replace their parent in order), so neighbours are adjacent entries.
    const std::size_t n = todo.size();
    std::vector<char> bent(n), halve(n);
    for (std::size_t k = 0; k < n; ++k) bent[k] = bends(todo[k], sp.bend);
    for (std::size_t k = 0; k < n; ++k) {
      const Slab& sl = todo[k];
      const bool beside_bent = sp.beside_bends && ((k > 0 && todo[k - 1].b == sl.a && bent[k - 1]) ||
                                                   (k + 1 < n && sl.b == todo[k + 1].a && bent[k + 1]));
      halve[k] = sl.depth < sp.max_depth && sl.b - sl.a > 2 * sp.resolution &&
                 (sl.kinked_ends == 0 ? bent[k] || beside_bent
                                      : sl.parent.empty() || !halving_agrees(sl, todo[k + sl.sibling], sp.rel_tol));
    }
    std::vector<Slab> next;
    for (std::size_t k = 0; k < n; ++k) {
      Slab& sl = todo[k];
      if (halve[k]) {
        const Real mid = (sl.a + sl.b) / 2;
        done.push_back(Slab{sl.a, sl.b, 0, -1, {}, {}, {}, sl.calls, {}, 0});  // keeps the count of calls only
        Slab left{sl.a, mid, sl.kinked_ends & 1, sl.depth + 1, {}, {}, {}, 0, {}, 0};
        Slab right{mid, sl.b, sl.kinked_ends & 2, sl.depth + 1, {}, {}, {}, 0, {}, 0};
        if (sl.kinked_ends != 0) left.parent = right.parent = rule(sl), left.sibling = 1, right.sibling = -1;
        next.push_back(std::move(left));
        next.push_back(std::move(right));
      } else {
        done.push_back(std::move(sl));
      }
    }
    todo = std::move(next);
  }
  std::sort(done.begin(), done.end(),
            [](const Slab& p, const Slab& q) { return p.a < q.a || (p.a == q.a && p.b < q.b); });
  return done;
}

// The initial slabs between sorted edges, with their ends at an edge listed in `kinks_at` marked (Slab).
std::vector<Slab> slabs_between(const std::vector<Real>& e, const std::vector<Real>& kinks_at) {
  std::vector<Slab> out;
  auto listed = [&](Real x) { return std::find(kinks_at.begin(), kinks_at.end(), x) != kinks_at.end(); };
  for (std::size_t k = 0; k + 1 < e.size(); ++k)
    if (e[k + 1] > e[k])
      out.push_back(Slab{e[k], e[k + 1], int(listed(e[k])) | int(listed(e[k + 1])) << 1, 0, {}, {}, {}, 0, {}, 0});
  return out;
}

// Index of the interval [nodes[i], nodes[i + 1]) holding x.
std::size_t interval_of(const std::vector<Real>& nodes, Real x) {
  const auto it = std::upper_bound(nodes.begin(), nodes.end(), x);
  return std::size_t(std::clamp<std::ptrdiff_t>(it - nodes.begin() - 1, 0, std::ptrdiff_t(nodes.size()) - 2));
}

// The lines: bins (per ring, from lines at each column's slabs) and the azimuth CDF.
void integrate_lines(const SamplerUnderTest& s, const CapGridSpec& sp, const CapFrame& cf, const std::vector<Circle>& m,
                     CapGrid& out) {
  const int R = sp.radial_bins, A = sp.azimuth_bins;
  std::vector<Real> phi_edges;
  for (Real x : sp.xa) phi_edges.push_back(kTwoPi<Real> * x);
  for (int c = 0; c <= A; ++c) phi_edges.push_back(kTwoPi<Real> * c / A);
  for (const auto& [t, phi] : corners(m, cf.omc)) phi_edges.push_back(phi);
  const std::vector<Real> tangencies = azimuth_tangencies(m);
  phi_edges.insert(phi_edges.end(), tangencies.begin(), tangencies.end());
  for (int j = 1; j <= R; ++j) {
    const Real o = Real(j) / R * cf.omc;
    ring_crossing_azimuths(m, 1 - o, std::sqrt(std::max<Real>(0, o * (2 - o))), phi_edges);
  }
  const std::vector<Real> e = edges_of(phi_edges, 0, kTwoPi<Real>);
  // (sin theta, cos theta, dt/dv) at the nodes of each whole ring, in the cubic substitution.
  std::vector<std::array<Real, 3>> table(std::size_t(R) * 15);
  for (int j = 0; j < R; ++j)
    for (int i = 0; i < 15; ++i) {
      const Real a = Real(j) / R, b = Real(j + 1) / R, o = cubic_x(a, b, kRule15.v[i]) * cf.omc;
      table[std::size_t(j) * 15 + i] = {std::sqrt(std::max<Real>(0, o * (2 - o))), 1 - o, cubic_dx(a, b, kRule15.v[i])};
    }
  auto line_at = [&](Real phi, std::vector<Real>& line, long& calls) {
    line.assign(std::size_t(R), 0);
    const Real c = cosine(phi), sn = sine(phi);
    const Vec3L u = cf.fr.to_world(Vec3L(c, sn, 0)), axis = cf.fr.to_world(Vec3L(0, 0, 1));
    std::vector<Real> t_edges;
    for (int j = 0; j <= R; ++j) t_edges.push_back(Real(j) / R);
    line_crossings(m, cf.omc, c, sn, t_edges);
    const std::vector<Real> te = edges_of(t_edges, 0, 1);
    std::vector<Piece> pieces;
    for (std::size_t i = 0; i + 1 < te.size(); ++i) {
      if (!(te[i + 1] > te[i])) continue;
      const int j = std::min(R - 1, int((te[i] + te[i + 1]) / 2 * R));
      pieces.push_back({te[i], te[i + 1], j, te[i] == Real(j) / R && te[i + 1] == Real(j + 1) / R});
    }
    auto direction = [&](const Piece& p, Real v, Real& jac) {
      jac = cubic_dx(p.a, p.b, v);
      return cf.dir(cubic_x(p.a, p.b, v), c, sn);
    };
    auto piece_nodes = [&](const Piece& p, PieceNodes& pn) {
      for (int i = 0; i < 15; ++i) {
        if (!p.whole) {
          pn.w[i] = direction(p, kRule15.v[i], pn.jac[i]);
          continue;
        }
        const auto& [sin_t, cos_t, dt] = table[std::size_t(p.slot) * 15 + i];
        pn.w[i] = sin_t * u + cos_t * axis, pn.jac[i] = dt;
      }
    };
    integrate_pieces(s, pieces, sp.rel_tol, piece_nodes, direction, line, calls);
  };
  std::vector<Real> xa_rad;
  for (Real x : sp.xa) xa_rad.push_back(kTwoPi<Real> * x);
  std::vector<Real> slab_mass(sp.xa.size() - 1, 0);
  out.bins.assign(std::size_t(R) * A, 0);
  for (const Slab& sl : integrate_slabs(slabs_between(e, tangencies), false, sp, line_at)) {
    out.pdf_calls += sl.calls;
    if (sl.depth < 0) continue;
    const Real mid = (sl.a + sl.b) / 2;
    const int col = std::min(A - 1, int(mid / kTwoPi<Real> * A));
    Real sum = 0;
    for (int i = 0; i < kSlabNodes; ++i)
      for (int j = 0; j < R; ++j) {
        const Real v = cf.omc * sl.weight[i] * sl.value[i][std::size_t(j)];
        out.bins[std::size_t(j) * A + col] += v, sum += v;
      }
    slab_mass[interval_of(xa_rad, mid)] += sum;
  }
  out.Fa.assign(sp.xa.size(), 0);
  for (std::size_t k = 0; k + 1 < sp.xa.size(); ++k) out.Fa[k + 1] = out.Fa[k] + slab_mass[k];
}

// A ring within the edge band (t > 1 - CapGridSpec::resolution): the midpoint rule on kEdgeBandNodes equally spaced
// azimuths per column, whose (cos, sin) the caller computes once. There a rounded pdf is 0 or not by its
// directions' rounding, a pattern far finer than any rule's nodes, so the ring's integral is an average over that
// pattern: the Gauss-Kronrod pieces' 480 nodes leave about 2% of a float ring's zero fraction to chance
// (sqrt(f (1 - f) / 480)), these 16384 about 0.4%.
constexpr int kEdgeBandNodes = 512;
std::vector<std::array<Real, 2>> edge_band_azimuths(int columns) {
  const std::size_t n = std::size_t(columns) * kEdgeBandNodes;
  std::vector<std::array<Real, 2>> cs(n);
  const Real h = kTwoPi<Real> / Real(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Real phi = h * (Real(i) + Real(0.5));
    cs[i] = {cosine(phi), sine(phi)};
  }
  return cs;
}
void edge_band_ring(const SamplerUnderTest& s, const std::vector<std::array<Real, 2>>& azimuths, const Vec3L& centre,
                    const Vec3L& ex, const Vec3L& ey, std::vector<Real>& ring, long& calls) {
  const std::size_t n = azimuths.size();
  const Real h = kTwoPi<Real> / Real(n);
  std::vector<Vec3L> w(n);
  std::vector<Real> f(n);
  for (std::size_t i = 0; i < n; ++i) w[i] = centre + azimuths[i][0] * ex + azimuths[i][1] * ey;
  pdf_many(s, w, f);
  calls += long(n);
  for (std::size_t i = 0; i < n; ++i)
    if (std::isfinite(f[i])) ring[i / kEdgeBandNodes] += f[i] * h;
}

// The rings: bins again (the check) and the radial CDF. Slabs in t end at the KS nodes, the ring edges, and where
// each column's integrand kinks: tangencies of boundary circles with the rings, corners, and crossings of the
// boundary with the columns' edges.
void integrate_rings(const SamplerUnderTest& s, const CapGridSpec& sp, const CapFrame& cf, const std::vector<Circle>& m,
                     CapGrid& out) {
  const int R = sp.radial_bins, A = sp.azimuth_bins;
  std::vector<Real> t_edges(sp.xr.begin(), sp.xr.end()), cuts{1};
  for (int j = 0; j <= R; ++j) t_edges.push_back(Real(j) / R);
  std::vector<Real> tangencies;  // kept at the cap's ends too, where they mark the end slabs as kinked
  for (Real theta : polar_tangencies(m)) tangencies.push_back(t_of_polar(theta, cf.omc));
  for (const auto& [t, phi] : corners(m, cf.omc)) cuts.push_back(t);
  for (int c = 0; c < A; ++c)  // where the boundary crosses a column's edge, a column's integrand kinks
    line_crossings(m, cf.omc, cosine(kTwoPi<Real> * c / A), sine(kTwoPi<Real> * c / A), cuts);
  t_edges.insert(t_edges.end(), cuts.begin(), cuts.end());
  t_edges.insert(t_edges.end(), tangencies.begin(), tangencies.end());
  const std::vector<Real> e = edges_of(t_edges, 0, 1);
  // (cos phi, sin phi) at the nodes of each whole column.
  std::vector<Real> phi_edges_whole;
  for (int c = 0; c <= A; ++c) phi_edges_whole.push_back(kTwoPi<Real> * c / A);
  std::vector<std::array<Real, 2>> table(std::size_t(A) * 15);
  for (int c = 0; c < A; ++c)
    for (int i = 0; i < 15; ++i) {
      const Real a = phi_edges_whole[c], phi = a + (phi_edges_whole[c + 1] - a) * kRule15.v[i];
      table[std::size_t(c) * 15 + i] = {cosine(phi), sine(phi)};
    }
  const Vec3L ex = cf.fr.to_world(Vec3L(1, 0, 0)), ey = cf.fr.to_world(Vec3L(0, 1, 0));
  // The edge band's azimuths, computed by the first ring in it (float: the last few KS slabs; in double and long
  // double, whose band is about 1e-11 wide, no ring).
  std::once_flag band_once;
  std::vector<std::array<Real, 2>> band_azimuths;
  auto ring_at = [&](Real t, std::vector<Real>& ring, long& calls) {
    ring.assign(std::size_t(A), 0);
    const Real o = t * cf.omc;
    const Real cos_c = 1 - o, sin_c = std::sqrt(std::max<Real>(0, o * (2 - o)));
    const Vec3L centre = cos_c * cf.fr.to_world(Vec3L(0, 0, 1));
    if (t > 1 - sp.resolution) {
      std::call_once(band_once, [&] { band_azimuths = edge_band_azimuths(A); });
      edge_band_ring(s, band_azimuths, centre, sin_c * ex, sin_c * ey, ring, calls);
      return;
    }
    std::vector<Real> phi_edges = phi_edges_whole;
    ring_crossing_azimuths(m, cos_c, sin_c, phi_edges);
    const std::vector<Real> pe = edges_of(phi_edges, 0, kTwoPi<Real>);
    std::vector<Piece> pieces;
    for (std::size_t i = 0; i + 1 < pe.size(); ++i) {
      if (!(pe[i + 1] > pe[i])) continue;
      const int c = std::min(A - 1, int((pe[i] + pe[i + 1]) / 2 / kTwoPi<Real> * A));
      pieces.push_back({pe[i], pe[i + 1], c, pe[i] == phi_edges_whole[c] && pe[i + 1] == phi_edges_whole[c + 1]});
    }
    auto direction = [&](const Piece& p, Real v, Real& jac) {
      jac = p.b - p.a;
      const Real phi = p.a + (p.b - p.a) * v;
      return centre + sin_c * (cosine(phi) * ex + sine(phi) * ey);
    };
    auto piece_nodes = [&](const Piece& p, PieceNodes& pn) {
      for (int i = 0; i < 15; ++i) {
        if (!p.whole) {
          pn.w[i] = direction(p, kRule15.v[i], pn.jac[i]);
          continue;
        }
        const auto& [cp, sp_] = table[std::size_t(p.slot) * 15 + i];
        pn.w[i] = centre + sin_c * (cp * ex + sp_ * ey), pn.jac[i] = p.b - p.a;
      }
    };
    integrate_pieces(s, pieces, sp.rel_tol, piece_nodes, direction, ring, calls);
  };
  std::vector<Real> slab_mass(sp.xr.size() - 1, 0);
  out.bins_check.assign(std::size_t(R) * A, 0);
  // A column's integrand has a square-root kink at a tangency (the slab's substitution smooths it), a plain kink
  // at the other cuts (splitting there is enough).
  for (const Slab& sl : integrate_slabs(slabs_between(e, tangencies), true, sp, ring_at)) {
    out.pdf_calls += sl.calls;
    if (sl.depth < 0) continue;
    const Real mid = (sl.a + sl.b) / 2;
    const int j = std::min(R - 1, int(mid * R));
    Real sum = 0;
    for (int i = 0; i < kSlabNodes; ++i)
      for (int c = 0; c < A; ++c) {
        const Real v = cf.omc * sl.weight[i] * sl.value[i][std::size_t(c)];
        out.bins_check[std::size_t(j) * A + c] += v, sum += v;
      }
    slab_mass[interval_of(sp.xr, mid)] += sum;
  }
  out.Fr.assign(sp.xr.size(), 0);
  for (std::size_t k = 0; k + 1 < sp.xr.size(); ++k) out.Fr[k + 1] = out.Fr[k] + slab_mass[k];
}

}  // namespace

CapGrid integrate_cap_grid(const SamplerUnderTest& s, const CapGridSpec& spec) {
  const CapFrame cf(s.bounding_cap);
  const std::vector<Circle> m = local_circles(boundary_of(s), cf.fr);
  CapGrid g;
  integrate_lines(s, spec, cf, m, g);
  integrate_rings(s, spec, cf, m, g);
  return g;
}

}  // namespace warpcheck::validation::battery
