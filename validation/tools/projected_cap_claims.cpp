// projected_cap_claims: measures the claims of Peters & Dachsbacher 2019 ("Sampling Projected Spherical Caps in
// Real Time") on lib/warpcheck/projected_cap.h and writes them beside the paper's figures.
//
//   build/projected_cap_claims [--configurations N] [--out FILE]
//
// Default: N = 1000000 random Case-3 configurations, FILE = data/projected-cap/claims.json (under the source dir).
// Prints and writes: the quintic's maximal error against the exact inverse of A(X) (paper: 4.6e-5), and that of
// the sampler's rescaled form of it; the largest
// Case-3 density ratio max p / min p found, its largest ratio to the paper's bound (must be <= 1), and the largest
// ratios among |d| >= 1.094 r (paper: <= 2) and |d| >= 2 r (paper: <= sqrt 2); per named configuration, the KS
// distance D_true of the round-tripped u0 (exact inverse of the quintic's samples) and the sample count
// (1.63 / D_true)^2 a KS test needs to see it; and the relative variance of the Lambertian estimator with this
// sampler (quintic and exact inverse) and with solid-angle sampling (the paper's Fig. 9 story), by quadrature.
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>

#include "tools/projected_cap_claims.h"

using namespace warpcheck;
using namespace warpcheck::validation;
using namespace warpcheck::validation::projected_cap_test;

namespace {

// Alg. 5's quintic fit of X(A), as published and as the sampler rescales it: the largest error.
std::string quintic_claims() {
  std::string json;
  char buf[2048];
  const QuinticError q = quintic_max_error(20000);
  std::printf("quintic (Alg. 5): max |X(A) - fit| = %.4Le at A = %.6Lf (paper: 4.6e-5)\n", q.max_error, q.at);
  std::snprintf(
      buf, sizeof buf,
      "  \"quintic_max_error\": {\"measured\": %.6Le, \"at_A\": %.10Le, \"paper\": 4.6e-5, \"method\": \"20001-point "
      "grid on [0, pi/2] + Brent refinement; exact X(A) by Boost TOMS 748 on A(X) in long double\"},\n",
      q.max_error, q.at);
  json += buf;
  const QuinticError qr = quintic_max_error(20000, rescaled_quintic_inverse_of_A);
  std::printf("sampler's rescaled quintic (no fold, lib/warpcheck/projected_cap.h): max error %.4Le at A = %.6Lf\n",
              qr.max_error, qr.at);
  std::snprintf(
      buf, sizeof buf,
      "  \"rescaled_quintic_max_error\": {\"measured\": %.6Le, \"at_A\": %.10Le, \"kappa\": %.21Lg, \"what\": "
      "\"the paper's g evaluated at kappa (pi/2 - |A|), kappa = e0 / (pi/2), g(pi/2 - e0) e0^(2/3) = 1: the "
      "sampler's fit, continuous at A = 0 (ours, not the paper's)\"},\n",
      qr.max_error, qr.at, kQuinticKappa<Real>);
  json += buf;

  return json;
}

// Alg. 4's Case-3 density ratio against the paper's bounds, over random configurations.
std::string case3_claims(long configurations) {
  std::string json;
  char buf[2048];
  const Case3RatioStats s = case3_ratio_search<long double>(configurations, 8, 20260501);
  std::printf(
      "Case 3 (Alg. 4): %ld random configurations: max p/min p up to %.6f; max ratio/bound %.15f (at d/r %.6g, depth "
      "%.6g)\n"
      "  largest ratio with |d| >= 1.094 r: %.6f (paper: <= 2); with |d| >= 2 r: %.6f (paper: <= sqrt 2 = 1.414214)\n",
      s.configurations, s.worst_ratio, s.worst_ratio_over_bound, s.worst_d_over_r, s.worst_depth,
      s.worst_ratio_d_ge_1_094, s.worst_ratio_d_ge_2);
  std::snprintf(
      buf, sizeof buf,
      "  \"case3_density_ratio\": {\"configurations\": %ld, \"sampling\": \"d/r log-uniform in [1+1e-6, 1e3], depth "
      "-h/r_y uniform in (0,1), seed 20260501, density on a 9x9 grid of cut-disk points incl. corners, "
      "long double, exact cut-disk inverse\", \"largest_ratio\": %.9g, \"largest_ratio_over_bound\": %.17g, "
      "\"at_d_over_r\": %.9g, "
      "\"at_depth\": %.9g, \"largest_ratio_d_ge_1.094r\": %.9g, \"paper_bound_d_ge_1.094r\": 2, "
      "\"largest_ratio_d_ge_2r\": %.9g, \"paper_bound_d_ge_2r\": 1.4142135623730951},\n",
      s.configurations, s.worst_ratio, s.worst_ratio_over_bound, s.worst_d_over_r, s.worst_depth,
      s.worst_ratio_d_ge_1_094, s.worst_ratio_d_ge_2);
  json += buf;

  return json;
}

// Per named configuration: the KS round-trip deviation and the Lambertian estimator's variances.
std::string configuration_claims() {
  std::string json;
  char buf[2048];
  json += "  \"configurations\": [\n";
  bool first = true;
  std::printf("%-22s %4s %12s %12s %14s %14s %14s %14s\n", "config", "case", "KS D_true", "KS n*", "relvar quintic",
              "relvar exact", "relvar solid", "hit-bias quint");
  for (const ProjectedCapConfig& c : projected_cap_configs()) {
    const ProjectedCapView<Real> v = make_projected_cap_view(c.g);
    if (!v.valid()) continue;
    const Real d = round_trip_u0_deviation(c.g, 100000);
    const Real phi = reference_projected_solid_angle(c.g);
    const LambertianMoments mq = projected_cap_lambertian_moments<SphereProjectedCap<double>>(c.g, 1e-10L);
    const LambertianMoments me = projected_cap_lambertian_moments<SphereProjectedCapExact<double>>(c.g, 1e-10L);
    const SphereView<Real> sv = make_sphere_view(c.g);
    const Real omega = kTwoPi<Real> * sv.one_minus_cos_max;
    const Real var_sa = omega * cap_cosine_moment(c.g, 2) / (phi * phi) - 1;
    const Real var_q = mq.m2 / (phi * phi) - (mq.m1 / phi) * (mq.m1 / phi);
    const Real var_e = me.m2 / (phi * phi) - (me.m1 / phi) * (me.m1 / phi);
    const Real bias_q = mq.m1_in / phi - 1;
    std::printf("%-22s %4d %12.4Le %12.3Le %14.4Le %14.4Le %14.4Le %14.4Le\n", c.name, v.which_case, d,
                (1.63L / d) * (1.63L / d), var_q, var_e, var_sa, bias_q);
    std::snprintf(
        buf, sizeof buf,
        "%s    {\"config\": \"%s\", \"case\": %d, \"projected_solid_angle\": %.15Le, \"ks_round_trip_u0_D_true\": "
        "%.6Le, "
        "\"ks_samples_needed_1pct\": %.4Le, \"relative_variance_lambertian\": {\"quintic\": %.6Le, \"exact_inverse\": "
        "%.6Le, \"solid_angle_sampling\": %.6Le}, \"quintic_relative_bias_of_hits\": %.6Le}",
        first ? "" : ",\n", c.name, v.which_case, phi, d, (1.63L / d) * (1.63L / d), var_q, var_e, var_sa, bias_q);
    json += buf;
    first = false;
  }
  json += "\n  ],\n";
  return json;
}

}  // namespace

int main(int argc, char** argv) {
  long configurations = 1'000'000;
  std::string out = std::string(WARPCHECK_SOURCE_DIR) + "/data/projected-cap/claims.json";
  std::string command = "build/projected_cap_claims";
  for (int i = 1; i < argc; ++i) {
    command += std::string(" ") + argv[i];
    if (!std::strcmp(argv[i], "--configurations") && i + 1 < argc)
      configurations = std::stol(argv[++i]), command += std::string(" ") + argv[i];
    else if (!std::strcmp(argv[i], "--out") && i + 1 < argc)
      out = argv[++i], command += std::string(" ") + argv[i];
    else {
      std::fprintf(stderr, "usage: projected_cap_claims [--configurations N] [--out FILE]\n");
      return 2;
    }
  }
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  const auto t0 = std::chrono::steady_clock::now();
  std::string json = "{\n  \"command\": \"" + command + "\",\n";
  json += quintic_claims();
  json += case3_claims(configurations);
  json += configuration_claims();
  char buf[64];
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::snprintf(buf, sizeof buf, "  \"seconds\": %.1f\n}\n", secs);
  json += buf;
  std::ofstream f(out);
  if (!f) {
    std::fprintf(stderr, "cannot write %s (does its directory exist?)\n", out.c_str());
    return 1;
  }
  f << json;
  std::printf("wrote %s in %.1f s\n", out.c_str(), secs);
  return 0;
}
