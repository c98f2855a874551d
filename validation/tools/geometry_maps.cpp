// geometry_maps: the report's maps over geometry, measured and written as JSON for `warpcheck report` to draw.
//
//   build/geometry_maps [--cases N] [--grid NX NY] [--data DIR]
//
// DIR/polygon/geometry-map.json: the backward error |A_delta| / sector area (Peters 2021 Sec. 3.6, Eq. 7) of the
// decentral sector inversion after 0 and 2 iterations, in double, on N random decentral sectors
// (polygon_error_analysis.h's distribution, seed 1), with each sector's opening angle and the target's position
// xi = target / sector area. Default N = 2000.
// DIR/projected-cap/geometry-map.json: the Case-3 density ratio max / min of Alg. 4 (Peters & Dachsbacher 2019
// Sec. 3.5) and the paper's bound, in long double, on an NX x NY grid of cell centres: log10(d / r) from
// log10(1.001) to 3, depth of the centre below the horizon / r_y from 0 to 1. Default 60 x 40; DIR = data/.
// Numbers are written in the shortest form that reads back to the same double; null where there is none.
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "tools/projected_cap_claims.h"
#include "warpcheck/polygon_error_analysis.h"

using namespace warpcheck;
using namespace warpcheck::validation::projected_cap_test;

namespace {

std::string number(double x) {
  if (!std::isfinite(x)) return "null";
  char b[32];
  return std::string(b, std::to_chars(b, b + sizeof b, x).ptr);
}

std::string array(const std::vector<double>& v) {
  std::string s = "[";
  for (std::size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + number(v[i]);
  return s + "]";
}

std::string quoted(const std::string& s) {
  std::string o = "\"";
  for (char c : s) o += c == '"' || c == '\\' ? std::string("\\") + c : std::string(1, c);
  return o + "\"";
}

std::string polygon_map(int cases, const std::string& command) {
  const unsigned seed = 1;
  const int iterations[] = {0, 2};
  std::mt19937_64 rng(seed);
  std::vector<double> angle, xi, error[2];
  for (int i = 0; i < cases; ++i) {
    const RandomSectorCase<double> c = random_decentral_case<double>(rng, 1e-2);
    angle.push_back(std::atan2(kahan_cross2(c.sector.s0, c.sector.s1), c.sector.s0.dot(c.sector.s1)) * 180 / M_PI);
    xi.push_back(c.target / c.sector.area);
    for (int k = 0; k < 2; ++k) error[k].push_back(decentral_backward_error<double>(c, iterations[k]));
  }
  std::string j = "{\n  \"command\": " + quoted(command) + ",\n";
  j += "  \"what\": \"backward error |A_delta| / sector area (Peters 2021 Sec. 3.6, Eq. 7) of the decentral sector "
       "inversion on random decentral sectors (polygon_error_analysis.h, min area 1e-2)\",\n";
  j += "  \"scalar\": \"double\",\n  \"seed\": " + std::to_string(seed) + ",\n  \"cases\": " + std::to_string(cases) +
       ",\n";
  j += "  \"opening_angle_degrees\": " + array(angle) + ",\n  \"xi\": " + array(xi) + ",\n";
  j += "  \"backward_error\": [\n";
  for (int k = 0; k < 2; ++k)
    j += "    {\"iterations\": " + std::to_string(iterations[k]) + ", \"values\": " + array(error[k]) + "}" +
         (k ? "\n" : ",\n");
  return j + "  ]\n}\n";
}

std::string case3_map(int nx, int ny, const std::string& command) {
  const double lo = std::log10(1.001), hi = 3;
  std::vector<std::vector<double>> ratio(nx, std::vector<double>(ny, NAN)), bound = ratio;
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j) {
      const double log_d = lo + (hi - lo) * (i + 0.5) / nx, depth = (j + 0.5) / ny;
      const long double ry = 1 / std::pow(10.0L, log_d), h = -depth * ry;
      const ProjectedCapView<long double> p = make_projected_cap_view(unit_geometry<long double>(h, ry));
      if (!p.valid() || p.which_case != 3) continue;
      ratio[i][j] = double(case3_density_ratio(p, 8));
      bound[i][j] = double(case3_bound(p));
    }
  auto rows = [](const std::vector<std::vector<double>>& m) {
    std::string s = "[\n";
    for (std::size_t i = 0; i < m.size(); ++i) s += "    " + array(m[i]) + (i + 1 < m.size() ? ",\n" : "\n");
    return s + "  ]";
  };
  std::string j = "{\n  \"command\": " + quoted(command) + ",\n";
  j += "  \"what\": \"Case-3 density ratio max / min of Alg. 4 over the cut disk (Peters & Dachsbacher 2019 Sec. "
       "3.5, 9 x 9 cut-disk points) and the paper's bound, unit sphere, at cell centres of a grid over log10(d / r) "
       "and the depth of the centre below the horizon / r_y; null where the geometry is not Case 3\",\n";
  j += "  \"scalar\": \"long double\",\n  \"nx\": " + std::to_string(nx) + ",\n  \"ny\": " + std::to_string(ny) + ",\n";
  j += "  \"log10_distance_range\": [" + number(lo) + ", " + number(hi) + "],\n  \"depth_range\": [0, 1],\n";
  j += "  \"ratio\": " + rows(ratio) + ",\n  \"bound\": " + rows(bound) + "\n}\n";
  return j;
}

bool write(const std::filesystem::path& p, const std::string& text) {
  std::filesystem::create_directories(p.parent_path());
  std::ofstream f(p, std::ios::binary | std::ios::trunc);
  f << text;
  if (f) std::printf("wrote %s\n", p.c_str());
  return bool(f);
}

}  // namespace

int main(int argc, char** argv) {
  int cases = 2000, nx = 60, ny = 40;
  std::filesystem::path data = std::string(WARPCHECK_SOURCE_DIR) + "/data";
  std::string command = "build/geometry_maps";
  for (int i = 1; i < argc; ++i) {
    const int left = argc - 1 - i;
    if (!std::strcmp(argv[i], "--cases") && left >= 1) {
      cases = std::atoi(argv[++i]);
      command += std::string(" --cases ") + argv[i];
    } else if (!std::strcmp(argv[i], "--grid") && left >= 2) {
      nx = std::atoi(argv[++i]), ny = std::atoi(argv[++i]);
      command += " --grid " + std::to_string(nx) + " " + std::to_string(ny);
    } else if (!std::strcmp(argv[i], "--data") && left >= 1) {
      data = argv[++i];
    } else {
      std::fprintf(stderr, "usage: geometry_maps [--cases N] [--grid NX NY] [--data DIR]\n");
      return 2;
    }
  }
  if (cases < 1 || nx < 1 || ny < 1) {
    std::fprintf(stderr, "geometry_maps: --cases and --grid need positive counts\n");
    return 2;
  }
  const bool ok = write(data / "polygon" / "geometry-map.json", polygon_map(cases, command)) &&
                  write(data / "projected-cap" / "geometry-map.json", case3_map(nx, ny, command));
  if (!ok) std::fprintf(stderr, "geometry_maps: cannot write under %s\n", data.c_str());
  return ok ? 0 : 1;
}
