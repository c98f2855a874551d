// Sample sets for the report's kernel pages: points of primary sample space and the directions a sampler maps
// them to, in the equal-area view of its bounding cap. Computed by build/sample_sets (sample_sets.cpp), drawn
// by `warpcheck report` (reports/svg.cpp) from the JSON the tool writes.
//
// The blue noise is Mitchell's best-candidate algorithm (1991) from a fixed seed, written here because Debian
// packages no blue-noise point-set library and the algorithm is a dozen lines; it is enough to show how a kernel
// distorts a well-spread set.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <random>
#include <vector>

#include <cstdio>
#include <string>

#include "warpcheck/validation/battery.h"
#include "warpcheck/validation/registry.h"

namespace warpcheck::validation::sample_sets {

using Point2 = std::array<double, 2>;

// n points of the unit square: each new point is the farthest, in the toroidal metric, from the points placed so
// far among `candidates` uniform candidates. O(n^2 candidates): about 3e7 distance evaluations for 1024 points.
inline std::vector<Point2> best_candidate_blue_noise(int n, std::uint64_t seed, int candidates = 32) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::vector<Point2> out;
  out.reserve(std::size_t(std::max(n, 0)));
  auto torus_d2 = [](const Point2& a, const Point2& b) {
    double dx = std::abs(a[0] - b[0]), dy = std::abs(a[1] - b[1]);
    dx = std::min(dx, 1 - dx), dy = std::min(dy, 1 - dy);
    return dx * dx + dy * dy;
  };
  for (int k = 0; k < n; ++k) {
    Point2 best{U(rng), U(rng)};
    double best_d = -1;
    const int m = k == 0 ? 1 : std::max(candidates, 1);
    for (int c = 0; c < m; ++c) {
      const Point2 cand = c == 0 ? best : Point2{U(rng), U(rng)};
      double d = std::numeric_limits<double>::infinity();
      for (const auto& p : out) d = std::min(d, torus_d2(cand, p));
      if (d > best_d) best_d = d, best = cand;
    }
    out.push_back(best);
  }
  return out;
}

// The points of `lines` lines u0 = const and then `lines` lines u1 = const, `line_samples` points each, both ends
// included: the order in which the report draws them.
inline std::vector<Point2> grid_line_points(int lines, int line_samples) {
  std::vector<Point2> u;
  for (int dir = 0; dir < 2; ++dir)
    for (int i = 0; i < lines; ++i) {
      const double fixed = lines > 1 ? double(i) / (lines - 1) : 0.5;
      for (int k = 0; k < line_samples; ++k) {
        const double v = line_samples > 1 ? double(k) / (line_samples - 1) : 0.5;
        u.push_back(dir == 0 ? Point2{fixed, v} : Point2{v, fixed});
      }
    }
  return u;
}

// A mapped direction in the bounding cap's equal-area view, sqrt(t) (cos phi, sin phi), and whether it lies
// outside the cap (t > 1 beyond rounding); nothing when the sampler declined or returned a non-direction.
struct MappedPoint {
  double x = 0, y = 0;
  bool outside = false;
};

inline std::optional<MappedPoint> map_point(const SamplerUnderTest& s, const Point2& u) {
  const Sample x = s.sample(u[0], u[1]);
  if (!x.valid || !std::isfinite(double(x.direction.norm())) || !(x.direction.norm() > 0)) return std::nullopt;
  Real t, phi;
  cap_coordinates(s.bounding_cap, Vec3L(x.direction.normalized()), t, phi);
  const double rho = std::sqrt(std::max(0.0, double(t)));
  MappedPoint m{rho * std::cos(double(phi)), rho * std::sin(double(phi)), double(t) > 1 + 1e-9};
  if (!std::isfinite(m.x) || !std::isfinite(m.y)) return std::nullopt;
  return m;
}

// What the report draws: 17 + 17 lines of 96 points, and 1024 blue-noise points from seed 1.
constexpr int kGridLines = 17, kGridLineSamples = 96, kBlueNoisePoints = 1024;
constexpr std::uint64_t kBlueNoiseSeed = 1;

inline std::string fixed4(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.4f", v);
  return std::string(b) == "-0.0000" ? "0.0000" : b;
}

inline std::string quoted(const std::string& s) {
  std::string o = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\')
      o += std::string("\\") + c;
    else if (static_cast<unsigned char>(c) < 0x20)
      o += ' ';
    else
      o += c;
  }
  return o + "\"";
}

inline std::string mapped_points(const SamplerUnderTest& s, const std::vector<Point2>& u) {
  std::string o = "[";
  for (std::size_t i = 0; i < u.size(); ++i) {
    const auto m = map_point(s, u[i]);
    if (i) o += ',';
    if (!m) {
      o += "null";
      continue;
    }
    o.append(1, '[').append(fixed4(m->x)).append(1, ',').append(fixed4(m->y)).append(m->outside ? ",1]" : "]");
  }
  return o + "]";
}

inline std::string case_json(const Case& c, const std::vector<Point2>& grid, const std::vector<Point2>& blue) {
  std::string o = "{\"kernel\": " + quoted(c.kernel) + ", \"scalar\": " + quoted(c.scalar) +
                  ", \"config\": " + quoted(c.config) + ", \"description\": " + quoted(c.description);
  try {
    const SamplerUnderTest s = c.make();
    o += std::string(", \"expect_no_sample\": ") + (s.expect_no_sample ? "true" : "false");
    o += ",\n   \"grid\": " + mapped_points(s, grid) + ",\n   \"blue\": " + mapped_points(s, blue);
  } catch (const std::exception& e) {
    o += ", \"error\": " + quoted(e.what());
  }
  return o + "}";
}

// The JSON build/sample_sets writes (sample_sets.cpp documents it) for these cases, written by hand to fix four
// decimals (a tenth of a pixel of the report's disk), which keeps the file small.
inline std::string sample_sets_json(const std::vector<const Case*>& cases, const std::string& command) {
  const std::vector<Point2> grid = grid_line_points(kGridLines, kGridLineSamples);
  const std::vector<Point2> blue = best_candidate_blue_noise(kBlueNoisePoints, kBlueNoiseSeed);
  std::string j = "{\"command\": " + quoted(command) + ", \"grid_lines\": " + std::to_string(kGridLines) +
                  ", \"grid_line_samples\": " + std::to_string(kGridLineSamples) +
                  ",\n \"blue_noise\": {\"seed\": " + std::to_string(kBlueNoiseSeed) + ", \"u\": [";
  for (std::size_t i = 0; i < blue.size(); ++i)
    j.append(i ? ",[" : "[").append(fixed4(blue[i][0])).append(1, ',').append(fixed4(blue[i][1])).append(1, ']');
  j += "]},\n \"cases\": [\n";
  for (std::size_t i = 0; i < cases.size(); ++i) j += (i ? ",\n  " : "  ") + case_json(*cases[i], grid, blue);
  return j + "\n]}\n";
}

}  // namespace warpcheck::validation::sample_sets
