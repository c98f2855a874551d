// The recorded worst cases (data/worst-cases/*.json) of the searches that measure one algorithm step through their
// own call of it, replayed through the kernel's public sampling code on the same recorded input, so that a change of
// the production path is seen and not only a change of the step (test_worst_case_replay.cpp replays the searches'
// own objectives).
//
// Searches that already measure through the production entry point, K::sample on K::view of the catalogue traits
// (searches/kernels.cpp), and need no second replay: precision-<kernel>-<float|double>-<angle|backward> and
// pdf-warp-<kernel>; projected-cap-case3-ratio calls sample_projected_spherical_cap<kExact>, which is
// sphere-projected-cap-exact's sample.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <numbers>
#include <optional>

#include "warpcheck/catalogue.h"
#include "warpcheck/validation/searches.h"
#include "worst_case_fixtures.h"

using namespace warpcheck;
using namespace warpcheck::validation;

namespace {

using L = long double;

// The unit vector at polar angle `polar` from the z axis and azimuth `azimuth`, as the searches parameterise them.
Vec3<L> unit_vector(L polar, L azimuth) {
  return Vec3<L>(std::sin(polar) * std::cos(azimuth), std::sin(polar) * std::sin(azimuth), std::cos(polar));
}

// ---- polygon-backward-k*: Peters 2021 Sec. 3.6's backward error, through a polygon ----------------------------

// The quad whose one decentral sector is the search's (searches/polygon.cpp: inner and outer edge normals from tilt
// and azimuth, the sector from azimuth 0 over sector_deg): vertices on the inner and outer great circles at both
// ends, at height z = -(n_xy . d) / n_z above azimuth d, the last one scaled onto the plane of the other three. The
// ellipses are centrally symmetric, so the sector turned by pi has the same areas; the turn that puts all four
// vertices above the horizon is taken. A great circle's ellipse has radius 1 / sqrt(1 + (n_xy . w / n_z)^2) in
// direction w, so the normal (-n_xy, n_z) draws the same ellipse: where the search's two edges lie above the
// horizon on opposite sides, the inner one is taken so reflected. nullopt where no turn puts all four above.
std::optional<PolygonLightGeometry<L>> polygon_of_sector(const std::vector<L>& p) {
  Vec3<L> inner = unit_vector(p[0], p[1]);
  const Vec3<L> outer = unit_vector(p[2], p[3]);
  const L angle = p[4] * std::numbers::pi_v<L> / 180;
  const L mid_x = std::cos(angle / 2), mid_y = std::sin(angle / 2);
  if ((inner.x() * mid_x + inner.y() * mid_y) * (outer.x() * mid_x + outer.y() * mid_y) < 0)
    inner = Vec3<L>(-inner.x(), -inner.y(), inner.z());
  for (const L turn : {L(0), std::numbers::pi_v<L>}) {
    auto vertex = [&](const Vec3<L>& n, L azimuth) {
      const L x = std::cos(azimuth + turn), y = std::sin(azimuth + turn);
      return Vec3<L>(x, y, -(n.x() * x + n.y() * y) / n.z());
    };
    const Vec3<L> a = vertex(inner, 0), b = vertex(outer, 0), c = vertex(outer, angle), d = vertex(inner, angle);
    if (!(a.z() > 0 && b.z() > 0 && c.z() > 0 && d.z() > 0)) continue;
    const Vec3<L> plane = (b - a).cross(c - a);
    PolygonLightGeometry<L> g;
    g.shading = ShadingPoint<L>{Vec3<L>::Zero(), Vec3<L>(0, 0, 1)};
    g.light = PolygonLight<L>{a, b, c, Vec3<L>(d * (a.dot(plane) / d.dot(plane)))};
    return g;
  }
  return std::nullopt;
}

// The backward error |A_delta| / A_sector of the kernel's sampler with `iterations` tangent-line steps at the
// recorded target A = xi A_sector: u0 = (areas before + A) / A_Sigma sampled (u1 = 1/2; the azimuth does not depend
// on it), and the sample's exact u0 from the kernel's inverse (invert_polygon_projected_solid_angle, Eq. 7's closed
// form), |u0' - u0| A_Sigma / A_sector. Two iterations go through the kernel's own sample (its paper default).
std::optional<L> polygon_backward_error(const std::vector<L>& p, int iterations) {
  using K = PolygonProjectedSolidAngle<L>;
  const auto g = polygon_of_sector(p);
  if (!g) return std::nullopt;
  const K::View v = K::view(*g);
  if (!v.valid() || v.central) return std::nullopt;
  int k = 0;
  for (int i = 1; i < v.sector_count; ++i)
    if (v.sectors[i].area > v.sectors[k].area) k = i;  // the others are the radial edges' (area 0)
  L before = 0;
  for (int i = 0; i < k; ++i) before += v.sectors[i].area;
  const L area = v.sectors[k].area, u0 = (before + p[5] * area) / v.projected_solid_angle;
  const Vec2<L> u(u0, 0.5L);
  const DirectionSample<L> s =
      iterations == 2 ? K::sample(v, u) : sample_polygon_projected_solid_angle(v, u, iterations);
  Vec2<L> back;
  if (!s.valid() || !K::invert(v, s.direction, back)) return std::nullopt;
  return std::abs(back[0] - u0) * v.projected_solid_angle / area;
}

// ---- projected-cap-quintic: Alg. 5's abscissa, through the sphere light's sampler ----------------------------

// A unit sphere 4 radii straight above the shading point: its projected cap is a disk of radius r = 1/4 about the
// zenith, one piece, whose left-area is u0 pi (Alg. 2). The sampler's abscissa d_x in units of r at the recorded
// offset area A (left-area pi/2 + A), for the quintic (the kernel sphere-projected-cap) or the exact inverse.
template <CutDiskInverse M> L overhead_sphere_abscissa(L offset_area) {
  const SphereLightGeometry<L> g{ShadingPoint<L>{Vec3<L>::Zero(), Vec3<L>(0, 0, 1)},
                                 SphereLight<L>{Vec3<L>(0, 0, 4), 1}};
  const ProjectedCapView<L> v = make_projected_cap_view(g);
  const L u0 = (std::numbers::pi_v<L> / 2 + offset_area) / std::numbers::pi_v<L>;
  const DirectionSample<L> s = sample_projected_spherical_cap<L, M>(v, Vec2<L>(u0, 0.5L));
  const Vec3<L> local = v.to_local(s.direction);
  return Vec2<L>(local.x(), local.y()).norm() / L(0.25L) * (local.x() >= 0 ? 1 : -1);
}

// Each record of a polygon-backward search whose sector is a polygon's: the kernel's sampler, on the quad with
// that sector, has the recorded backward error to one part in 1e9 (the replay's slack) plus 64 long double epsilons
// (the quad's edge normals and sector area come from its vertices by Kahan cross products, the search's from the
// parameters: a rounding-level difference that only k3's 6.4e-11 notices, by 2.4e-19).
void replay_polygon_backward(const SearchRecord& r, int iterations) {
  EXPECT_TRUE(polygon_of_sector(r.best_x)) << "the recorded sector is no polygon's";
  const std::optional<L> now = polygon_backward_error(r.best_x, iterations);
  EXPECT_TRUE(now) << "the kernel declined the polygon of the recorded sector";
  if (now) {
    EXPECT_NEAR(*now, r.best_f, 1e-9L * r.best_f + 64 * std::numeric_limits<L>::epsilon())
        << "recorded " << double(r.best_f) << ", through the kernel " << double(*now);
  }
}

// projected-cap-quintic records the published fit's error (paper_quintic_x). The kernel evaluates that fit at the
// rescaled argument kappa e (e the area to the disk's nearer end; docs/derivations/projected-cap.md), so at the
// recorded input its abscissa is the published fit's at kappa e, to the sampler's rounding (the disk's radius 1/4
// and the lift to the sphere), and its error against the exact inverse is the rescaled fit's, below its maximum
// 8.94e-5 (ProjectedCapQuintic.RescaledFitErrorAgainstTheExactInverse). The search's own measure at the same input,
// taken on the exact sampler's abscissa, is the recorded error to the same rounding.
void replay_projected_cap_quintic(const SearchRecord& r) {
  const L offset = r.best_x[0], pi = std::numbers::pi_v<L>;
  const L quintic = overhead_sphere_abscissa<CutDiskInverse::kQuintic>(offset);
  const L exact = overhead_sphere_abscissa<CutDiskInverse::kExact>(offset);
  const L e = pi / 2 - offset;  // the left-area pi/2 + A is e from the disk's right end
  EXPECT_NEAR(quintic, paper_quintic_x<L>(pi - kQuinticKappa<L> * e), 1e-15L);
  EXPECT_NEAR(std::abs(paper_quintic_x<L>(pi / 2 + offset) - exact), r.best_f, 1e-15L);
  EXPECT_LE(std::abs(quintic - exact), 8.94e-5L);
}

// ---- sptd-cap-invariance: Eqs. 6-7's image cap, through the uniform SPTD's sampler -----------------------------

// The search's input (searches/caps.cpp): pivot r_p, cap C of half-angle alpha, and w on C's boundary.
struct CapInvarianceInput {
  Vec3<L> pivot, w;
  Cap<L> cap;
  L alpha;
};
CapInvarianceInput cap_invariance_input(const std::vector<L>& p) {
  const Vec3<L> axis = unit_vector(p[3], p[4]);
  const L alpha = p[5], half = std::sin(alpha / 2);
  const Frame<L> f = Frame<L>::from_z(axis);
  const Vec3<L> w = std::cos(alpha) * axis + std::sin(alpha) * (std::cos(p[6]) * f.x + std::sin(p[6]) * f.y);
  return {p[0] * unit_vector(p[1], p[2]), w, Cap<L>{axis, 2 * half * half}, alpha};
}

// The search measures, in the image, the angle by which g(w) misses the boundary of g(C). Through the kernel: the
// uniform SPTD's sample on the boundary of g(C) (u0 = 1, at the azimuth of g(w) from the kernel's inverse) misses
// the boundary of C by an angle that g carries to the image with its conformal scale k / |w - r_p|^2 (Eq. 4's
// Jacobian is its square); u0 below 1 samples inside the boundary. nullopt where the kernel declines the input.
std::optional<L> sptd_boundary_error_through_the_sampler(const std::vector<L>& p, L u0 = 1) {
  using K = SptdUniformCap<L>;
  const CapInvarianceInput in = cap_invariance_input(p);
  SptdCapGeometry<L> g;
  g.sptd.pivot = in.pivot, g.sptd.base = SptdBase::kUniform, g.cap = in.cap;
  const K::View v = K::view(g);
  Vec2<L> u;
  if (!v.valid() || !K::invert(v, in.w, u)) return std::nullopt;
  const DirectionSample<L> s = K::sample(v, Vec2<L>(u0, u[1]));
  if (!s.valid()) return std::nullopt;
  const L to_axis = std::atan2(s.direction.cross(in.cap.axis).norm(), s.direction.dot(in.cap.axis));
  return std::abs(to_axis - in.alpha) * v.k / (in.w - in.pivot).squaredNorm();
}

// The record's input through the kernel has the search's error at that input (which the replay test holds to the
// record) to 256 long double epsilons: the sample's own roundings (the image frame, the cap offset at u0 = 1, g and
// the normalisation; 42 epsilons at the recorded input), the two sharing the rounding of g(C)'s 1 - cos.
void replay_sptd_cap_invariance(const SearchRecord& r) {
  const std::optional<L> now = sptd_boundary_error_through_the_sampler(r.best_x);
  EXPECT_TRUE(now) << "the uniform SPTD declined the recorded pivot and cap";
  if (now) {
    const L search = find_search(r.search)->objective(r.best_x);
    EXPECT_NEAR(*now, search, 256 * std::numeric_limits<L>::epsilon())
        << "the search's step " << double(search) << ", through the kernel " << double(*now);
  }
}

// How each recorded search is replayed through the kernels: a replay, or none where the search
// already measures through the production entry point or its replay is not written (file comment).
std::optional<std::function<void(const SearchRecord&)>> production_replay(const std::string& search) {
  const std::map<std::string, int> backward = {{"polygon-backward-k0", 0},
                                               {"polygon-backward-k1", 1},
                                               {"polygon-backward-k2", 2},
                                               {"polygon-backward-k3", 3},
                                               {"polygon-backward-k2-area1e-7", 2}};
  if (const auto it = backward.find(search); it != backward.end())
    return [k = it->second](const SearchRecord& r) { return replay_polygon_backward(r, k); };
  if (search == "projected-cap-quintic") return replay_projected_cap_quintic;
  if (search == "sptd-cap-invariance") return replay_sptd_cap_invariance;
  return std::nullopt;
}

bool measured_through_the_production_entry_point(const std::string& search) {
  return search.rfind("precision-", 0) == 0 || search.rfind("pdf-warp-", 0) == 0 ||
         search == "projected-cap-case3-ratio";
}

}  // namespace

// Every recorded worst case of a search that measures one step through its own call of it has the recorded error
// through the kernel's sampling code too; every recorded search is either replayed so or measured through the
// production entry point already (a new step search must choose).
TEST(RecordedWorstCasesThroughTheKernels, HaveTheRecordedErrorThroughTheKernelsSamplingCode) {
  int replayed = 0;
  for (const std::string& name : recorded_worst_case_files()) {
    const SearchRecord r = read_recorded_worst_case(name);
    SCOPED_TRACE(r.search);
    if (const auto replay = production_replay(r.search)) {
      (*replay)(r);
      ++replayed;
      continue;
    }
    EXPECT_TRUE(measured_through_the_production_entry_point(r.search))
        << "a recorded search without a replay through the kernel's sampling code";
  }
  EXPECT_GE(replayed, 7);  // polygon-backward-k0 to k3, k2-area1e-7, projected-cap-quintic, sptd-cap-invariance
}

// The replay sees a production change the search's own step does not: the kernel sampled with one iteration more
// than the record's (as if its count had changed) misses the recorded error by orders of magnitude.
TEST(RecordedWorstCasesThroughTheKernels, APolygonSamplerWithAnotherIterationCountMissesTheRecordedError) {
  const SearchRecord r = read_recorded_worst_case("polygon-backward-k2.json");
  const std::optional<L> three = polygon_backward_error(r.best_x, 3);
  ASSERT_TRUE(three);
  EXPECT_LT(*three, r.best_f / 1000);
}

// The SPTD replay sees a sampler that misses the image's boundary: a sample at u0 = 1 - 1e-9 instead of 1 lands
// inside C by about 1e-9 of g(C)'s width, carried back by g, orders of magnitude beyond the recorded error.
TEST(RecordedWorstCasesThroughTheKernels, AnSptdSampleInsideTheImageBoundaryMissesTheRecordedError) {
  const SearchRecord r = read_recorded_worst_case("sptd-cap-invariance.json");
  const std::optional<L> on_boundary = sptd_boundary_error_through_the_sampler(r.best_x);
  ASSERT_TRUE(on_boundary);
  EXPECT_LE(*on_boundary, r.best_f);
  const std::optional<L> inside = sptd_boundary_error_through_the_sampler(r.best_x, 1 - 1e-9L);
  ASSERT_TRUE(inside);
  EXPECT_GT(*inside, 1000 * r.best_f);
}
