// Specification: each kernel's public entry points agree bit for bit. The battery binds a kernel through its
// catalogue trait (the view overload with the trait's fixed options); a renderer calls the geometry overload with
// its default arguments (sample_polygon_projected_solid_angle(g, u): 2 iterations; sample_ltc_polygon(g, u): 4;
// sample_polygon_solid_angle(g, u): not clipped). So what the battery validates is what users call only if the
// two return the same direction and pdf, and pdf(direction) the same value, on every geometry: checked here on
// random geometries of every family (the battery's own, random_geometries.cpp) in float, double and long double.
#include <gtest/gtest.h>

#include <cstring>
#include <functional>

#include "catalogue/random_geometries.h"
#include "warpcheck/catalogue.h"

using namespace warpcheck;
using namespace warpcheck::validation;

namespace {

template <class T> bool same_bits(const T& a, const T& b) { return std::memcmp(&a, &b, sizeof(T)) == 0; }
template <class T> bool same_bits(const Vec3<T>& a, const Vec3<T>& b) {
  return same_bits(a.x(), b.x()) && same_bits(a.y(), b.y()) && same_bits(a.z(), b.z());
}

template <class T> SphereLightGeometry<T> cast_sphere(const SphereLightGeometry<Real>& g) {
  return {ShadingPoint<T>{g.shading.position.cast<T>(), g.shading.normal.cast<T>()},
          SphereLight<T>{g.light.center.cast<T>(), T(g.light.radius)}};
}

// The trait K against the geometry overloads `sample` and `pdf` on geometry g, over a grid of u and at each
// sampled direction. Returns the number of disagreements (0 expected); counts the valid samples in *valid.
template <class K, class G, class Sample, class Pdf>
int disagreements(const G& g, Sample&& sample, Pdf&& pdf, int* valid) {
  using T = typename K::Scalar;
  const auto v = K::view(g);
  int bad = 0;
  for (int i = 0; i < 16; ++i)
    for (int j = 0; j < 16; ++j) {
      const Vec2<T> u(T((i + 0.37L) / 16), T((j + 0.61L) / 16));
      const DirectionSample<T> a = K::sample(v, u), b = sample(g, u);
      bad += !same_bits(a.direction, b.direction) || !same_bits(a.pdf, b.pdf) || a.valid() != b.valid();
      if (!a.valid()) continue;
      ++*valid;
      const T pa = K::pdf(v, a.direction), pb = pdf(g, a.direction);
      bad += !same_bits(pa, pb);
    }
  return bad;
}

// Every kernel's geometry overloads in scalar T on the random geometries of seeds 1..count of every family.
template <class T> void check_all(int count) {
  int valid = 0;
  for (int index = 0; index < count; ++index)
    for (const GeometryText& t : random_geometry_texts(1, index)) {
      const std::string where = t.family + " random-s1-" + std::to_string(index) + " " + scalar_name<T>();
      if (t.family == "sphere" || t.family == "projected-cap") {
        const SphereLightGeometry<T> g = cast_sphere<T>(sphere_geometry(t));
        auto s1 = [](const auto& g, const auto& u) { return sample_sphere_solid_angle(g, u); };
        auto p1 = [](const auto& g, const auto& w) { return pdf_sphere_solid_angle(g, w); };
        EXPECT_EQ((disagreements<SphereSolidAngle<T>>(g, s1, p1, &valid)), 0) << where;
        auto s2 = [](const auto& g, const auto& u) { return sample_sphere_visible_area(g, u); };
        auto p2 = [](const auto& g, const auto& w) { return pdf_sphere_visible_area(g, w); };
        EXPECT_EQ((disagreements<SphereVisibleArea<T>>(g, s2, p2, &valid)), 0) << where;
        auto s3 = [](const auto& g, const auto& u) { return sample_projected_spherical_cap(g, u); };  // the quintic
        auto p3 = [](const auto& g, const auto& w) { return pdf_projected_spherical_cap(g, w); };
        EXPECT_EQ((disagreements<SphereProjectedCap<T>>(g, s3, p3, &valid)), 0) << where;
        auto s4 = [](const auto& g, const auto& u) {
          return sample_projected_spherical_cap<T, CutDiskInverse::kExact>(g, u);
        };
        auto p4 = [](const auto& g, const auto& w) {
          return pdf_projected_spherical_cap<T, CutDiskInverse::kExact>(g, w);
        };
        EXPECT_EQ((disagreements<SphereProjectedCapExact<T>>(g, s4, p4, &valid)), 0) << where;
      } else if (t.family == "polygon" || t.family == "rectangle") {
        const PolygonLightGeometry<T> g = polygon_geometry(t).template cast<T>();
        auto s1 = [](const auto& g, const auto& u) { return sample_polygon_projected_solid_angle(g, u); };
        auto p1 = [](const auto& g, const auto& w) { return pdf_polygon_projected_solid_angle(g, w); };
        EXPECT_EQ((disagreements<PolygonProjectedSolidAngle<T>>(g, s1, p1, &valid)), 0) << where;
        auto s2 = [](const auto& g, const auto& u) { return sample_polygon_projected_solid_angle_biased(g, u); };
        auto p2 = [](const auto& g, const auto& w) { return pdf_polygon_projected_solid_angle_biased(g, w); };
        EXPECT_EQ((disagreements<PolygonProjectedSolidAngleBiased<T>>(g, s2, p2, &valid)), 0) << where;
        auto s3 = [](const auto& g, const auto& u) { return sample_polygon_solid_angle(g, u); };
        auto p3 = [](const auto& g, const auto& w) { return pdf_polygon_solid_angle(g, w); };
        EXPECT_EQ((disagreements<PolygonSolidAngle<T>>(g, s3, p3, &valid)), 0) << where;
        auto s4 = [](const auto& g, const auto& u) { return sample_polygon_solid_angle(g, u, true); };
        auto p4 = [](const auto& g, const auto& w) { return pdf_polygon_solid_angle(g, w, true); };
        EXPECT_EQ((disagreements<PolygonSolidAngleClipped<T>>(g, s4, p4, &valid)), 0) << where;
        auto s5 = [](const auto& g, const auto& u) { return sample_arvo_triangle_fan(g, u); };
        auto p5 = [](const auto& g, const auto& w) { return pdf_arvo_triangle_fan(g, w); };
        EXPECT_EQ((disagreements<BaselineArvoTriangle<T>>(g, s5, p5, &valid)), 0) << where;
        auto s6 = [](const auto& g, const auto& u) { return sample_turk_area(g, u); };
        auto p6 = [](const auto& g, const auto& w) { return pdf_turk_area(g, w); };
        EXPECT_EQ((disagreements<BaselineTurkArea<T>>(g, s6, p6, &valid)), 0) << where;
        auto s7 = [](const auto& g, const auto& u) { return sample_spherical_rectangle(g, u); };
        auto p7 = [](const auto& g, const auto& w) { return pdf_spherical_rectangle(g, w); };
        EXPECT_EQ((disagreements<BaselineUrenaRectangle<T>>(g, s7, p7, &valid)), 0) << where;
      } else if (t.family == "ltc") {
        const LtcPolygonGeometry<T> g = ltc_geometry(t).template cast<T>();
        auto s = [](const auto& g, const auto& u) { return sample_ltc_polygon(g, u); };
        auto p = [](const auto& g, const auto& w) { return pdf_ltc_polygon(g, w); };
        EXPECT_EQ((disagreements<PolygonLtc<T>>(g, s, p, &valid)), 0) << where;
      } else if (t.family == "sptd") {
        const SptdCapGeometry<T> g = sptd_geometry(t).template cast<T>();
        auto s = [](const auto& g, const auto& u) { return sample_sptd_cap(g, u); };
        auto p = [](const auto& g, const auto& w) { return pdf_sptd_cap(g, w); };
        if (g.sptd.base == SptdBase::kUniform)
          EXPECT_EQ((disagreements<SptdUniformCap<T>>(g, s, p, &valid)), 0) << where;
        else
          EXPECT_EQ((disagreements<SptdCosineCap<T>>(g, s, p, &valid)), 0) << where;
      }
    }
  EXPECT_GT(valid, 1000);  // the comparison saw samples, not only "no sample"
}

}  // namespace

TEST(EntryPoints, GeometryOverloadsAgreeWithTheBatterysTraitsBitForBitInFloat) { check_all<float>(4); }
TEST(EntryPoints, GeometryOverloadsAgreeWithTheBatterysTraitsBitForBitInDouble) { check_all<double>(4); }
TEST(EntryPoints, GeometryOverloadsAgreeWithTheBatterysTraitsBitForBitInLongDouble) { check_all<long double>(4); }
