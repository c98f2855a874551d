// Random geometries for the battery (warpcheck validate --random N): each kernel family gets N seeded geometries
// drawn by the family's fuzz decoder (fuzz/checks/*.h: the same generators the fuzz targets use, leaning to the
// degenerate and lopsided) from a byte stream of a seeded Mersenne twister, kept only when the light is valid and
// sampleable by the battery (below), and named random-s<seed>-<index>: the name alone determines the geometry, so
// `warpcheck validate --config random-s<seed>-<index>` replays it. Every fourth geometry is any accepted one; the
// other three must be lopsided in at least one way (tags in the description): tiny or huge, straddling the
// horizon, nearly edge-on or tangent to it, long and thin, or with one part (a vertex, the pivot's side) holding
// most of the measure. The geometries are decoded in double, so long double and double see the same light.
//
// "Sampleable by the battery": finite, with the conditioning kappa (fuzz/checks/common.h) at most 1e4 (the
// inputs determine the directions to 1e-12 in double, far below the battery's 1e-6 tolerance), a bounding cap of
// half-angle at least 1e-4 rad (the named configurations go down to 2.5e-5 rad, but kernels documented as
// cancelling there are not what random cases are for), a view that samples, and at least 1 % of a light's cap
// above the horizon for the kernels that clip to it. Float is left out: its tolerances are measured per named
// configuration (sphere.cpp, projected_cap.cpp), and no a-priori float tolerance covers arbitrary geometry.
#include "catalogue/random_geometries.h"

#include <Eigen/SVD>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <random>
#include <stdexcept>

#include "fuzz/checks/ltc.h"
#include "fuzz/checks/polygon.h"
#include "fuzz/checks/projected_cap.h"
#include "fuzz/checks/sptd.h"

namespace warpcheck::validation {

const char* intern(const std::string& s) {
  static std::mutex m;
  static std::deque<std::string> pool;  // a deque never moves its elements
  std::lock_guard<std::mutex> lock(m);
  for (const std::string& p : pool)
    if (p == s) return p.c_str();
  return pool.emplace_back(s).c_str();
}

namespace {

using fuzz::L;

// ---- Text form ------------------------------------------------------------------------------------------------

void put(GeometryText& t, const char* key, const Vec3L& v) { t.values[key] = {v.x(), v.y(), v.z()}; }
void put(GeometryText& t, const char* key, Real x) { t.values[key] = {x}; }
Vec3L vec(const GeometryText& t, const char* key) {
  const auto it = t.values.find(key);
  if (it == t.values.end() || it->second.size() != 3)
    throw std::runtime_error(std::string("geometry: no 3-vector ") + key);
  return Vec3L(it->second[0], it->second[1], it->second[2]);
}
Real num(const GeometryText& t, const char* key) {
  const auto it = t.values.find(key);
  if (it == t.values.end() || it->second.size() != 1)
    throw std::runtime_error(std::string("geometry: no number ") + key);
  return it->second[0];
}

GeometryText text_of(const char* family, const SphereLightGeometry<Real>& g) {
  GeometryText t{family, {}};
  put(t, "x", g.shading.position), put(t, "n", g.shading.normal), put(t, "c", g.light.center);
  put(t, "r", g.light.radius);
  return t;
}
GeometryText text_of(const char* family, const PolygonLightGeometry<Real>& g) {
  GeometryText t{family, {}};
  put(t, "x", g.shading.position), put(t, "n", g.shading.normal);
  auto& v = t.values["v"];
  for (int i = 0; i < g.light.count; ++i)
    for (int k = 0; k < 3; ++k) v.push_back(g.light.vertices[i][k]);
  return t;
}
GeometryText text_of(const LtcPolygonGeometry<Real>& g) {
  GeometryText t = text_of("ltc", g.polygon);
  auto& m = t.values["m"];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m.push_back(g.m(i, j));
  return t;
}
GeometryText text_of(const SptdCapGeometry<Real>& g) {
  GeometryText t{"sptd", {}};
  put(t, "pivot", g.sptd.pivot), put(t, "axis", g.sptd.base_axis);
  put(t, "base", g.sptd.base == SptdBase::kUniform ? 0 : 1);
  put(t, "cap", g.cap.axis), put(t, "omc", g.cap.one_minus_cos);
  return t;
}

// ---- Drawing --------------------------------------------------------------------------------------------------

// The byte stream of one attempt: 1 KiB from a Mersenne twister seeded by (seed, family, index, attempt).
std::vector<std::uint8_t> bytes_of(std::uint64_t seed, int family, int index, int attempt) {
  std::seed_seq seq{std::uint32_t(seed), std::uint32_t(seed >> 32), std::uint32_t(family), std::uint32_t(index),
                    std::uint32_t(attempt)};
  std::mt19937_64 rng(seq);
  std::vector<std::uint8_t> b(1024);
  for (std::size_t i = 0; i < b.size(); i += 8) {
    const std::uint64_t x = rng();
    for (int k = 0; k < 8; ++k) b[i + k] = std::uint8_t(x >> (8 * k));
  }
  return b;
}

constexpr L kMaxKappa = 1e4L, kMinHalfAngle = 1e-4L, kMaxMagnitude = 1e30L;

bool moderate(const Vec3<double>& v) { return all_finite(v) && v.cwiseAbs().maxCoeff() <= double(kMaxMagnitude); }
L half_angle(const Cap<Real>& c) { return fuzz::half_angle_of(c.one_minus_cos); }

// A lopsided geometry's tags ("" when it is none of them).
struct Tags {
  std::string s;
  void add(bool on, const char* tag) {
    if (on) s += s.empty() ? tag : std::string(",") + tag;
  }
};

// The fraction of a cap above the plane normal to n: 1000 directions of a fixed Fibonacci lattice on the cap.
Real fraction_above(const Cap<Real>& c, const Vec3L& n) {
  const Frame<Real> f = Frame<Real>::from_z(c.axis.normalized());
  const Vec3L nn = n.normalized();
  int above = 0;
  for (int i = 0; i < 1000; ++i) {
    const Real omc = c.one_minus_cos * (Real(i) + 0.5L) / 1000, cz = 1 - omc;
    const Real s = std::sqrt(std::max<Real>(0, omc * (2 - omc))), phi = 2.39996322972865332L * i;
    above += (f.x * (s * std::cos(phi)) + f.y * (s * std::sin(phi)) + f.z * cz).dot(nn) > 0;
  }
  return Real(above) / 1000;
}

// ---- Per family: decode, accept, tag --------------------------------------------------------------------------

struct Drawn {
  bool accepted = false;
  std::string tags;
  GeometryText text;
};

Drawn draw_sphere(FuzzedDataProvider& in, bool projected) {
  Drawn d;
  const SphereLightGeometry<double> gd =
      projected ? fuzz::decode_projected_cap<double>(in) : fuzz::decode_sphere<double>(in);
  if (!moderate(gd.light.center) || !moderate(gd.shading.position) || !moderate(gd.shading.normal) ||
      !(gd.light.radius > 0) || !(gd.light.radius <= double(kMaxMagnitude)) || gd.shading.normal.norm() < 1e-30)
    return d;
  const SphereLightGeometry<Real> g{
      ShadingPoint<Real>{gd.shading.position.cast<Real>(), gd.shading.normal.cast<Real>()},
      SphereLight<Real>{gd.light.center.cast<Real>(), Real(gd.light.radius)}};
  const fuzz::SphereReference ref = fuzz::sphere_reference(gd);
  const SphereView<Real> v = make_sphere_view(g);
  if (!v.valid() || ref.kappa > kMaxKappa || !((ref.d - ref.r) >= 1e-4L * ref.r)) return d;
  const Cap<Real> cap = v.cap();
  const L alpha = half_angle(cap), frac = fraction_above(cap, g.shading.normal);
  if (alpha < kMinHalfAngle || frac < 0.01L) return d;
  if (projected && !SphereProjectedCap<Real>::view(g).valid()) return d;
  // Elevation of the centre above the horizon, against the half-angle.
  const L elevation = std::asin(std::clamp<L>(v.frame.z.dot(g.shading.normal.normalized()), -1, 1));
  Tags t;
  t.add(alpha < 1e-2L, "tiny");
  t.add(alpha > 1.2L, "huge");
  t.add(std::abs(elevation) < alpha, "straddling-horizon");
  t.add(std::abs(std::abs(elevation) - alpha) < 0.05L * alpha, "tangent-to-horizon");
  t.add(frac < 0.1L, "mostly-below-horizon");
  d.accepted = true, d.tags = t.s, d.text = text_of(projected ? "projected-cap" : "sphere", g);
  return d;
}

// Polygon acceptance and tags shared by the polygon and LTC families.
Drawn accept_polygon(const PolygonLightGeometry<double>& gd, const char* family) {
  Drawn d;
  if (gd.light.count < 3 || gd.light.count > kMaxPolygonVertices || !moderate(gd.shading.position) ||
      !moderate(gd.shading.normal) || gd.shading.normal.norm() < 1e-30)
    return d;
  for (int i = 0; i < gd.light.count; ++i)
    if (!moderate(gd.light.vertices[i])) return d;
  if (check_polygon(gd.light) != NoSample::kNone) return d;
  if (fuzz::polygon_kappa(gd, true) > kMaxKappa) return d;
  const PolygonLightGeometry<Real> g = gd.cast<Real>();
  const auto whole = PolygonSolidAngle<Real>::view(g), clipped = PolygonSolidAngleClipped<Real>::view(g);
  if (!PolygonSolidAngle<Real>::sample(whole, Vec2<Real>(0.5L, 0.5L)).valid()) return d;
  const L omega = PolygonSolidAngle<Real>::normaliser(whole),
          above = PolygonSolidAngleClipped<Real>::normaliser(clipped);
  const L alpha = half_angle(PolygonSolidAngle<Real>::bounding_cap(g));
  if (alpha < kMinHalfAngle || !(above >= 0.01L * omega)) return d;
  // Shape and position: diameter, area, distance of x from the plane, nearest and farthest vertex.
  const fuzz::PolygonDiameter dia = fuzz::polygon_diameter(g.light);
  const Vec3L area = polygon_area_vector(g.light);
  const L plane = std::abs(area.normalized().dot(Vec3L(g.light.vertices[0] - g.shading.position)));
  L near = std::numeric_limits<L>::infinity(), far = 0;
  int below = 0;
  for (int i = 0; i < g.light.count; ++i) {
    const Vec3L p = g.light.vertices[i] - g.shading.position;
    near = std::min(near, p.norm()), far = std::max(far, p.norm());
    below += p.dot(g.shading.normal) < 0;
  }
  if (plane < 1e-3L * dia.length) return d;  // edge-on beyond what the kernels' planarity tolerance resolves
  Tags t;
  t.add(omega < 1e-4L, "tiny");
  t.add(omega > 1.5L, "huge");
  t.add(below > 0 && below < g.light.count, "straddling-horizon");
  t.add(plane < 0.05L * dia.length, "nearly-edge-on");
  t.add(dia.length * dia.length > 50 * area.norm(), "long-thin");
  t.add(near < 0.1L * far, "one-vertex-close");
  d.accepted = true, d.tags = t.s, d.text = text_of(family, g);
  return d;
}

Drawn draw_polygon(FuzzedDataProvider& in, bool rectangle) {
  const PolygonLightGeometry<double> gd = fuzz::decode_polygon_geometry<double>(in, rectangle);
  Drawn d = accept_polygon(gd, rectangle ? "rectangle" : "polygon");
  if (d.accepted && rectangle &&
      !BaselineUrenaRectangle<Real>::sample(BaselineUrenaRectangle<Real>::view(gd.cast<Real>()), Vec2<Real>(0.5L, 0.5L))
           .valid())
    d.accepted = false;
  return d;
}

Drawn draw_ltc(FuzzedDataProvider& in) {
  LtcPolygonGeometry<double> gd;
  gd.polygon.light = fuzz::decode_polygon<double>(in);
  gd.polygon.shading = fuzz::decode_polygon_shading<double>(in, gd.polygon.light);
  gd.m = fuzz::decode_ltc_matrix<double>(in);
  Drawn d = accept_polygon(gd.polygon, "ltc");
  if (!d.accepted) return d;
  const LtcPolygonGeometry<Real> g = gd.cast<Real>();
  const Eigen::JacobiSVD<Mat3<Real>> svd(g.m);
  const Real cond = svd.singularValues()(0) / svd.singularValues()(2);
  if (!(cond <= kMaxKappa) || !PolygonLtc<Real>::sample(PolygonLtc<Real>::view(g), Vec2<Real>(0.5L, 0.5L)).valid())
    return d.accepted = false, d;
  Tags t;
  t.add(cond > 100, "ill-conditioned");
  d.tags += d.tags.empty() || t.s.empty() ? t.s : "," + t.s;
  d.text = text_of(g);
  return d;
}

Drawn draw_sptd(FuzzedDataProvider& in, SptdBase base) {
  Drawn d;
  const fuzz::SptdCase<double> c = fuzz::decode_sptd<double>(in, base);
  const SptdCapGeometry<double>& gd = c.geo;
  if (!moderate(gd.sptd.pivot) || !moderate(gd.sptd.base_axis) || !moderate(gd.cap.axis) ||
      !std::isfinite(gd.cap.one_minus_cos) || gd.sptd.base != base)
    return d;
  const SptdCapGeometry<Real> g = gd.cast<Real>();
  const L rp = g.sptd.pivot.norm();
  if (rp > 0.999L || !(g.cap.one_minus_cos >= 5e-9L) || !(g.cap.one_minus_cos <= 2) || g.cap.axis.norm() < 1e-30L ||
      (base == SptdBase::kClampedCosine && g.sptd.base_axis.norm() < 1e-30L))
    return d;
  const bool valid =
      base == SptdBase::kUniform ? SptdUniformCap<Real>::view(g).valid() : SptdCosineCap<Real>::view(g).valid();
  if (!valid) return d;
  const Cap<Real> bound =
      base == SptdBase::kUniform ? SptdUniformCap<Real>::bounding_cap(g) : SptdCosineCap<Real>::bounding_cap(g);
  if (half_angle(bound) < kMinHalfAngle) return d;
  Tags t;
  t.add(rp > 0.9L, "pivot-near-sphere");
  t.add(g.cap.one_minus_cos < 1e-4L, "tiny");
  t.add(g.cap.one_minus_cos > 1.5L, "huge");
  t.add(base == SptdBase::kClampedCosine && std::abs(g.cap.axis.normalized().dot(g.sptd.base_axis.normalized())) < 0.2L,
        "near-horizon");
  d.accepted = true, d.tags = t.s, d.text = text_of(g);
  return d;
}

// The families, each with the kernels its geometries go to.
enum Family { kSphere, kProjectedCap, kPolygon, kRectangle, kSptdUniform, kSptdCosine, kLtc, kFamilies };

Drawn draw(Family f, FuzzedDataProvider& in) {
  switch (f) {
    case kSphere:
      return draw_sphere(in, false);
    case kProjectedCap:
      return draw_sphere(in, true);
    case kPolygon:
      return draw_polygon(in, false);
    case kRectangle:
      return draw_polygon(in, true);
    case kSptdUniform:
      return draw_sptd(in, SptdBase::kUniform);
    case kSptdCosine:
      return draw_sptd(in, SptdBase::kClampedCosine);
    default:
      return draw_ltc(in);
  }
}

// Geometry `index` of family f: the first accepted draw, lopsided unless index % 4 == 0; after 4000 attempts
// without a lopsided one, the first accepted draw (none at all: no geometry).
Drawn draw_geometry(Family f, std::uint64_t seed, int index) {
  Drawn first;
  for (int attempt = 0; attempt < 4000; ++attempt) {
    const std::vector<std::uint8_t> b = bytes_of(seed, int(f), index, attempt);
    FuzzedDataProvider in(b.data(), b.size());
    Drawn d = draw(f, in);
    if (!d.accepted) continue;
    if (index % 4 == 0 || !d.tags.empty()) return d;
    if (!first.accepted) first = std::move(d);
  }
  return first;
}

// The polygon kernels get two geometries per index, a polygon and a rectangle (which Urena et al. also take):
// the rectangle's configuration carries this suffix, so that (kernel, scalar, configuration) names one case.
constexpr const char* kRectangleSuffix = "-rectangle";

std::string config_name(std::uint64_t seed, int index) {
  return std::string("random-s").append(std::to_string(seed)).append("-").append(std::to_string(index));
}

// The geometry as the results file's first line of the case: a deterministic result "geometry" whose detail is
// the geometry's text (and the replay command is printed by warpcheck validate for a failing case).
void attach_geometry(std::vector<Case>& cases, const std::string& text) {
  for (Case& c : cases) {
    c.extras = [prev = c.extras, text, kernel = c.kernel, scalar = c.scalar,
                config = c.config](const BatteryOptions& o) {
      std::vector<TestResult> out;
      TestResult g;
      g.kernel = kernel, g.scalar = scalar, g.config = config, g.test = "geometry";
      g.statistic = std::numeric_limits<double>::quiet_NaN();
      g.passed = true;
      g.detail = text;
      out.push_back(g);
      if (prev) {
        std::vector<TestResult> more = prev(o);
        out.insert(out.end(), more.begin(), more.end());
      }
      return out;
    };
  }
}

}  // namespace

SphereLightGeometry<Real> sphere_geometry(const GeometryText& t) {
  return {ShadingPoint<Real>{vec(t, "x"), vec(t, "n")}, SphereLight<Real>{vec(t, "c"), num(t, "r")}};
}
PolygonLightGeometry<Real> polygon_geometry(const GeometryText& t) {
  PolygonLightGeometry<Real> g;
  g.shading = ShadingPoint<Real>{vec(t, "x"), vec(t, "n")};
  const auto it = t.values.find("v");
  if (it == t.values.end() || it->second.size() % 3 != 0 || it->second.size() / 3 > kMaxPolygonVertices)
    throw std::runtime_error("geometry: vertices v must be up to " + std::to_string(kMaxPolygonVertices) +
                             " 3-vectors");
  g.light.count = int(it->second.size() / 3);
  for (int i = 0; i < g.light.count; ++i)
    g.light.vertices[i] = Vec3L(it->second[3 * i], it->second[3 * i + 1], it->second[3 * i + 2]);
  return g;
}

LtcPolygonGeometry<Real> ltc_geometry(const GeometryText& t) {
  LtcPolygonGeometry<Real> g;
  g.polygon = polygon_geometry(t);
  const auto it = t.values.find("m");
  if (it == t.values.end() || it->second.size() != 9) throw std::runtime_error("geometry: ltc needs m (9 numbers)");
  for (int i = 0; i < 9; ++i) g.m(i / 3, i % 3) = it->second[i];
  return g;
}

SptdCapGeometry<Real> sptd_geometry(const GeometryText& t) {
  SptdCapGeometry<Real> g;
  g.sptd.pivot = vec(t, "pivot"), g.sptd.base_axis = vec(t, "axis");
  g.sptd.base = num(t, "base") == 0 ? SptdBase::kUniform : SptdBase::kClampedCosine;
  g.cap = Cap<Real>{vec(t, "cap"), num(t, "omc")};
  return g;
}

std::string to_text(const GeometryText& g) {
  std::string s = g.family;
  char buf[64];
  for (const auto& [key, values] : g.values) {
    s += " " + key + "=";
    for (std::size_t i = 0; i < values.size(); ++i) {
      std::snprintf(buf, sizeof buf, "%s%.21Lg", i ? "," : "", values[i]);
      s += buf;
    }
  }
  return s;
}

GeometryText parse_geometry_text(const std::string& text) {
  GeometryText g;
  std::size_t i = text.find(' ');
  g.family = text.substr(0, i);
  while (i != std::string::npos) {
    const std::size_t start = i + 1, end = text.find(' ', start), eq = text.find('=', start);
    if (eq == std::string::npos || eq > end) throw std::runtime_error("geometry text: expected key=values: " + text);
    auto& v = g.values[text.substr(start, eq - start)];
    std::string list = text.substr(eq + 1, end == std::string::npos ? std::string::npos : end - eq - 1);
    std::size_t p = 0;
    while (p <= list.size()) {
      const std::size_t q = std::min(list.find(',', p), list.size());
      const std::string item = list.substr(p, q - p);
      char* stop = nullptr;
      const long double x = std::strtold(item.c_str(), &stop);
      if (item.empty() || *stop != '\0') throw std::runtime_error("geometry text: not a number '" + item + "'");
      v.push_back(x);
      p = q + 1;
    }
    i = end;
  }
  return g;
}

std::vector<Case> geometry_text_cases(const std::string& name, const std::string& description, const GeometryText& t) {
  const char* n = intern(name);
  const char* desc = intern(description);
  std::vector<Case> cases;
  if (t.family == "sphere") {
    cases = sphere_geometry_cases(n, desc, sphere_geometry(t));
  } else if (t.family == "projected-cap") {
    cases = projected_cap_geometry_cases(n, desc, sphere_geometry(t));
  } else if (t.family == "polygon" || t.family == "rectangle") {
    cases = polygon_geometry_cases(n, desc, polygon_geometry(t), t.family == "rectangle");
  } else if (t.family == "ltc") {
    cases = ltc_geometry_cases(n, desc, ltc_geometry(t));
  } else if (t.family == "sptd") {
    cases = sptd_geometry_cases(n, desc, sptd_geometry(t));
  } else {
    throw std::runtime_error("geometry text: unknown family '" + t.family + "'");
  }
  attach_geometry(cases, to_text(t));
  return cases;
}

bool parse_random_config_name(const std::string& full, std::uint64_t* seed, int* index) {
  const std::string suffix = kRectangleSuffix;
  const bool rectangle = full.size() > suffix.size() && full.ends_with(suffix);
  const std::string name = rectangle ? full.substr(0, full.size() - suffix.size()) : full;
  unsigned long long s = 0;
  int i = 0, used = 0;
  if (std::sscanf(name.c_str(), "random-s%llu-%d%n", &s, &i, &used) != 2 || used != int(name.size()) || i < 0)
    return false;
  if (config_name(s, i) != name) return false;  // no leading zeros or signs: one name per geometry
  *seed = s, *index = i;
  return true;
}

std::vector<GeometryText> random_geometry_texts(std::uint64_t seed, int index) {
  std::vector<GeometryText> out;
  for (int f = 0; f < kFamilies; ++f) {
    const Drawn d = draw_geometry(Family(f), seed, index);
    if (d.accepted) out.push_back(d.text);
  }
  return out;
}

void register_random_geometry(Registry& r, std::uint64_t seed, int index) {
  for (int f = 0; f < kFamilies; ++f) {
    const Drawn d = draw_geometry(Family(f), seed, index);
    if (!d.accepted) continue;
    const std::string description =
        "random " + d.text.family + " geometry" + (d.tags.empty() ? "" : " (" + d.tags + ")") + ": " + to_text(d.text);
    const std::string name = config_name(seed, index) + (f == kRectangle ? kRectangleSuffix : "");
    for (Case& c : geometry_text_cases(name, description, d.text)) r.add(std::move(c));
  }
}

// A promoted geometry's file (warpcheck promote writes it): '#' lines say where it came from; the one other line
// is the geometry's text.
void register_promoted_geometries(Registry& r, const std::string& dir) {
  std::error_code ec;
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec))
    if (e.path().extension() == ".txt") files.push_back(e.path());
  std::sort(files.begin(), files.end());  // a fixed order, whatever the directory's
  for (const auto& path : files) {
    std::ifstream in(path);
    std::string line, geometry, origin;
    while (std::getline(in, line)) {
      if (line.empty()) continue;
      if (line[0] == '#') {
        if (origin.empty()) origin = line.substr(line.find_first_not_of("# "));
      } else if (geometry.empty()) {
        geometry = line;
      } else {
        throw std::runtime_error(path.string() + ": more than one geometry line");
      }
    }
    const GeometryText t = parse_geometry_text(geometry);
    const std::string description = "promoted " + t.family + " geometry (" + origin + "): " + geometry;
    for (Case& c : geometry_text_cases(std::string("promoted-").append(path.stem().string()), description, t))
      r.add(std::move(c));
  }
}

void register_random_geometries(Registry& r, const RandomGeometries& random) {
  for (int i = 0; i < random.count; ++i) register_random_geometry(r, random.seed, i);
  for (const std::string& name : random.names) {
    std::uint64_t seed = 0;
    int index = 0;
    if (!parse_random_config_name(name, &seed, &index)) continue;
    if (seed == random.seed && index < random.count) continue;  // already registered
    register_random_geometry(r, seed, index);
  }
}

}  // namespace warpcheck::validation
