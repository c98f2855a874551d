// sptd_claims: measures the two approximations of Dupuy, Heitz & Belcour 2017 and writes them, with the command
// that produced them, to data/sptd/claims.json (and prints the same JSON).
//
//   sptd_claims [--pairs N] [--seed S] [--out FILE]
//
// 1. The Henyey-Greenstein fit (Eqs. 27-28): for g on a grid in [-0.99, 0.99], the pivot phase function (Eq. 25)
//    with g_p = sign(g) Q(|g|) against HG (Eq. 26). Reported per g: the L1 distance between the two densities
//    over the sphere, int |f_pivot - f_HG| d omega = 2 pi int_{-1}^{1} |...| d mu (0 = identical, 2 = disjoint),
//    the pivot function's mean cosine (HG's is g), and, to separate the fit's error from the model's, the g_p
//    minimising the L1 distance (Boost's Brent minimiser) with its distance. The paper states no number for
//    this fit ("very similar renderings"); these are ours.
// 2. The two-cap approximation Eq. 37 (Oat & Sander) against the exact Eqs. 35-36 (Appendix B; checked against
//    quadrature in test_sptd.cpp): N random pairs of caps, axes uniform on the sphere, half-angles uniform in
//    (0, pi), restricted to the partial-overlap case where Eq. 37 applies; errors in steradians and relative to
//    the smaller cap's solid angle (Eq. 37's own scale), for N pairs with half-angles uniform in (0, pi) and N
//    more with half-angles uniform in (0, 30 degrees) (the sphere-light regime). Pairs whose union covers the
//    sphere (psi_1 + psi_2 + psi_d >= 2 pi, where Eq. 35 as printed is wrong too) are counted separately. The
//    paper states no error for Eq. 37 either; each section's "paper" field quotes what it does say.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <boost/math/quadrature/gauss_kronrod.hpp>
#include <boost/math/tools/minima.hpp>

#include "warpcheck/sptd.h"

using namespace warpcheck;
using L = long double;

namespace {

struct Stats {
  double p50 = 0, p99 = 0, max = 0;
  std::size_t n = 0;
};
Stats stats(std::vector<double> v) {
  Stats s;
  s.n = v.size();
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  auto at = [&](double q) { return v[std::min(v.size() - 1, std::size_t(q * double(v.size())))]; };
  s.p50 = at(0.5), s.p99 = at(0.99), s.max = v.back();
  return s;
}
std::string json(const Stats& s) {
  char b[200];
  std::snprintf(b, sizeof b, "{\"n\": %zu, \"p50\": %.3e, \"p99\": %.3e, \"max\": %.3e}", s.n, s.p50, s.p99, s.max);
  return b;
}

// Integrals over mu in [-1, 1] of a function peaked at mu = +-1 for |g| near 1: split at mu = +-0.9 and +-0.99.
template <class F> L integrate_mu(F&& f) {
  using GK = boost::math::quadrature::gauss_kronrod<L, 61>;
  const L cuts[] = {-1, -0.99L, -0.9L, 0, 0.9L, 0.99L, 1};
  L sum = 0;
  for (int i = 0; i + 1 < 7; ++i) sum += GK::integrate(f, cuts[i], cuts[i + 1], 15, 1e-14L);
  return sum;
}
L l1_distance(L gp, L g) {
  return kTwoPi<L> *
         integrate_mu([&](L mu) { return std::abs(pivot_phase_function(mu, gp) - henyey_greenstein(mu, g)); });
}
L mean_cosine(L gp) {
  return kTwoPi<L> * integrate_mu([&](L mu) { return mu * pivot_phase_function(mu, gp); });
}
L total_mass(L gp) {
  return kTwoPi<L> * integrate_mu([&](L mu) { return pivot_phase_function(mu, gp); });
}

Vec3<L> random_unit(std::mt19937_64& r) {
  std::normal_distribution<double> n;
  for (;;) {
    const Vec3<L> v(n(r), n(r), n(r));
    if (v.norm() > 1e-3L) return v / v.norm();
  }
}

// Section 1: the pivot phase function fitted to Henyey-Greenstein (Eqs. 25-28), L1 distance on a grid of g.
std::string hg_fit_section() {
  std::string hg_rows;
  double worst_fit = 0, worst_fit_g = 0, worst_opt = 0, worst_mass = 0;
  std::vector<L> grid;
  for (int k = -19; k <= 19; ++k) grid.push_back(L(k) / 20);
  grid.insert(grid.begin(), -0.99L);
  grid.push_back(0.99L);
  for (L g : grid) {
    const L gp = hg_to_pivot(g);
    const L d = l1_distance(gp, g);
    const auto best =
        boost::math::tools::brent_find_minima([&](L x) { return l1_distance(x, g); }, L(-0.999L), L(0.999L), 40);
    worst_mass = std::max(worst_mass, double(std::abs(total_mass(gp) - 1)));
    if (double(d) > worst_fit) worst_fit = double(d), worst_fit_g = double(g);
    worst_opt = std::max(worst_opt, double(best.second));
    char b[256];
    std::snprintf(
        b, sizeof b,
        "    {\"g\": %.2f, \"g_p\": %.6f, \"l1\": %.4e, \"mean_cosine_pivot\": %.6f, \"g_p_l1_optimal\": %.6f, "
        "\"l1_optimal\": %.4e}",
        double(g), double(gp), double(d), double(mean_cosine(gp)), double(best.first), double(best.second));
    hg_rows += (hg_rows.empty() ? "" : ",\n") + std::string(b);
  }
  std::string j = "  \"hg_fit\": {\n";
  j += "    \"what\": \"pivot phase function (Eq. 25) with g_p from Eqs. 27-28 vs Henyey-Greenstein (Eq. 26): L1 "
       "distance over the sphere (0 identical, 2 disjoint)\",\n";
  j += "    \"paper\": \"no number: the fit gives 'very similar renderings' (Sec. 6.2; Fig. 15 polar plots, Fig. 16 "
       "renderings, Fig. 18 at g = 0.9)\",\n";
  char b[400];
  std::snprintf(b, sizeof b,
                "    \"max_l1\": %.4e, \"at_g\": %.2f, \"max_l1_with_optimal_g_p\": %.4e, "
                "\"max_normalisation_error_eq9\": %.3e,\n",
                worst_fit, worst_fit_g, worst_opt, worst_mass);
  j += b;
  j += "    \"rows\": [\n" + hg_rows + "\n    ]\n  },\n";
  return j;
}

// Section 2: Eq. 37's approximate two-cap intersection against Eqs. 35-36 on random partially overlapping pairs, in
// two regimes: half-angles uniform in (0, pi), and in (0, pi / 6) (sphere lights and bent cones).
std::string two_cap_section(long pairs, unsigned long seed) {
  std::mt19937_64 r(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<double> abs_err[2], rel_err[2];
  long covering[2] = {0, 0};
  for (int regime = 0; regime < 2; ++regime) {
    const L max_psi = regime == 0 ? kPi<L> : kPi<L> / 6;
    for (long i = 0; i < pairs; ++i) {
      const L psi1 = max_psi * L(u(r)), psi2 = max_psi * L(u(r));
      const Cap<L> c1{random_unit(r), 1 - std::cos(psi1)}, c2{random_unit(r), 1 - std::cos(psi2)};
      const L p1 = cap_half_angle(c1), p2 = cap_half_angle(c2), pd = angle_between_unit(c1.axis, c2.axis);
      if (std::abs(p2 - p1) >= pd || p1 + p2 <= pd) continue;  // nested or disjoint: Eq. 35 is exact there
      if (p1 + p2 + pd >= kTwoPi<L>) {
        ++covering[regime];
        continue;
      }
      const L exact = cap_intersection_solid_angle(c1, c2), approx = cap_intersection_solid_angle_approx(c1, c2);
      const L scale = std::min(c1.solid_angle(), c2.solid_angle());
      abs_err[regime].push_back(double(std::abs(approx - exact)));
      rel_err[regime].push_back(double(std::abs(approx - exact) / scale));
    }
  }
  std::string j = "  \"two_cap_eq37\": {\n";
  j += "    \"what\": \"|Eq. 37 - Eqs. 35-36| on random partially overlapping cap pairs (axes uniform on the sphere, "
       "half-angles uniform in each regime)\",\n";
  j += "    \"paper\": \"no number: Eq. 37 (Oat and Sander 2007) is 'an approximation of Equation (36)' used in the "
       "real-time implementation (Appendix B)\",\n";
  j += "    \"pairs_drawn_per_regime\": " + std::to_string(pairs) + ",\n";
  j += "    \"half_angles_up_to_180_deg\": {\"partial_overlap\": " + std::to_string(abs_err[0].size()) +
       ", \"union_covers_sphere\": " + std::to_string(covering[0]) + ", \"abs_error_sr\": " + json(stats(abs_err[0])) +
       ", \"error_relative_to_smaller_cap\": " + json(stats(rel_err[0])) + "},\n";
  j += "    \"half_angles_up_to_30_deg\": {\"partial_overlap\": " + std::to_string(abs_err[1].size()) +
       ", \"abs_error_sr\": " + json(stats(abs_err[1])) +
       ", \"error_relative_to_smaller_cap\": " + json(stats(rel_err[1])) + "}\n";
  j += "  }\n";
  return j;
}

}  // namespace

int main(int argc, char** argv) {
  long pairs = 1'000'000;
  unsigned long seed = 1;
  std::string out = std::string(WARPCHECK_SOURCE_DIR) + "/data/sptd/claims.json";
  std::string command = "sptd_claims";
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (i + 1 >= argc || (a != "--pairs" && a != "--seed" && a != "--out")) {
      std::fprintf(stderr, "usage: sptd_claims [--pairs N] [--seed S] [--out FILE]\n");
      return 2;
    }
    const std::string v = argv[++i];
    if (a == "--pairs") pairs = std::atol(v.c_str());
    if (a == "--seed") seed = std::strtoul(v.c_str(), nullptr, 10);
    if (a == "--out")
      out = v;
    else
      command += " " + a + " " + v;
  }
  const std::string hg = hg_fit_section();
  std::string j = "{\n";
  j += "  \"command\": \"" + command + "\",\n";
  j += "  \"seed\": " + std::to_string(seed) + ",\n";
  j += hg + two_cap_section(pairs, seed) + "}\n";
  std::fputs(j.c_str(), stdout);
  const std::filesystem::path parent = std::filesystem::path(out).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent);
  std::ofstream f(out);
  f << j;
  if (!f) {
    std::fprintf(stderr, "cannot write %s\n", out.c_str());
    return 1;
  }
  return 0;
}
