// Specification: each kernel's public entry points agree bit for bit. The battery binds a kernel through its
// catalogue trait (the view overload with the trait's fixed options); a renderer calls the geometry overload with
// its default arguments (sample_polygon_projected_solid_angle(g, u): 2 iterations; sample_ltc_polygon(g, u): 4;
// sample_polygon_solid_angle(g, u): not clipped). So what the battery validates is what users call only if the
// two return the same direction and pdf, and pdf(direction) the same value, on every geometry: checked here on
// random geometries of every family (the battery's own, random_geometries.cpp) in float, double and long double.
// A polygon light prepared once (prepare_polygon_light) gives the same bits as one validated by every view.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "catalogue/random_geometries.h"
#include "warpcheck/catalogue.h"

using namespace warpcheck;
using namespace warpcheck::validation;

namespace {

// The same value, sign of zero included (NaN equals NaN); long double's padding bytes are not compared.
template <class T> bool same_bits(T a, T b) {
  return (a == b && std::signbit(a) == std::signbit(b)) || (std::isnan(a) && std::isnan(b));
}
template <class T> bool same_bits(const Vec3<T>& a, const Vec3<T>& b) {
  return same_bits(a.x(), b.x()) && same_bits(a.y(), b.y()) && same_bits(a.z(), b.z());
}

template <class T> SphereLightGeometry<T> cast_sphere(const SphereLightGeometry<Real>& g) {
  return {ShadingPoint<T>{g.shading.position.cast<T>(), g.shading.normal.cast<T>()},
          SphereLight<T>{g.light.center.cast<T>(), T(g.light.radius)}};
}

// The trait K on geometry g against the geometry overloads `sample` of u and `pdf` of w (on g), over a grid of u and at
// each sampled direction. Returns the number of disagreements (0 expected); counts the valid samples in *valid.
template <class K, class G, class Sample, class Pdf>
int disagreements(const G& g, Sample&& sample, Pdf&& pdf, int* valid) {
  using T = typename K::Scalar;
  const auto v = K::view(g);
  int bad = 0;
  for (int i = 0; i < 16; ++i)
    for (int j = 0; j < 16; ++j) {
      const Vec2<T> u(T((i + 0.37L) / 16), T((j + 0.61L) / 16));
      const DirectionSample<T> a = K::sample(v, u), b = sample(u);
      bad += !same_bits(a.direction, b.direction) || !same_bits(a.pdf, b.pdf) || a.valid() != b.valid();
      if (!a.valid()) continue;
      ++*valid;
      const T pa = K::pdf(v, a.direction), pb = pdf(a.direction);
      bad += !same_bits(pa, pb);
    }
  return bad;
}

// Kernel K<T> through its trait against the call `sample` of (g, u) and the call `pdf` of (g, w), on the
// geometry g in scope.
#define AGREE(K, sample, pdf)                                                                           \
  EXPECT_EQ((disagreements<K<T>>(                                                                       \
                g, [&](const auto& u) { return sample; }, [&](const auto& w) { return pdf; }, &valid)), \
            0)                                                                                          \
      << #K << " " << where

// Every kernel's geometry overloads in scalar T on the random geometries of seeds 1..count of every family.
template <class T> void check_all(int count) {
  int valid = 0;
  for (int index = 0; index < count; ++index)
    for (const GeometryText& t : random_geometry_texts(1, index)) {
      const std::string where = t.family + " random-s1-" + std::to_string(index) + " " + scalar_name<T>();
      if (t.family == "sphere" || t.family == "projected-cap") {
        const SphereLightGeometry<T> g = cast_sphere<T>(sphere_geometry(t));
        AGREE(SphereSolidAngle, sample_sphere_solid_angle(g, u), pdf_sphere_solid_angle(g, w));
        AGREE(SphereVisibleArea, sample_sphere_visible_area(g, u), pdf_sphere_visible_area(g, w));
        AGREE(SphereProjectedCap, sample_projected_spherical_cap(g, u), pdf_projected_spherical_cap(g, w));
        AGREE(SphereProjectedCapExact, (sample_projected_spherical_cap<T, CutDiskInverse::kExact>(g, u)),
              (pdf_projected_spherical_cap<T, CutDiskInverse::kExact>(g, w)));
      } else if (t.family == "polygon" || t.family == "rectangle") {
        const PolygonLightGeometry<T> g = polygon_geometry(t).template cast<T>();
        // The calls on `call` against the traits on g: first g itself, then g with its light prepared once
        // (prepare_polygon_light), as a renderer makes them.
        const PreparedPolygonLight<T> prepared = prepare_polygon_light(g.light);
        PolygonLightGeometry<T> gp = g;
        gp.prepared = &prepared;
        for (const PolygonLightGeometry<T>* call : std::initializer_list<const PolygonLightGeometry<T>*>{&g, &gp}) {
          const PolygonLightGeometry<T>& c = *call;
          AGREE(PolygonProjectedSolidAngle, sample_polygon_projected_solid_angle(c, u),
                pdf_polygon_projected_solid_angle(c, w));
          AGREE(PolygonProjectedSolidAngleBiased, sample_polygon_projected_solid_angle_biased(c, u),
                pdf_polygon_projected_solid_angle_biased(c, w));
          AGREE(PolygonSolidAngle, sample_polygon_solid_angle(c, u), pdf_polygon_solid_angle(c, w));
          AGREE(PolygonSolidAngleClipped, sample_polygon_solid_angle(c, u, true), pdf_polygon_solid_angle(c, w, true));
          AGREE(BaselineArvoTriangle, sample_arvo_triangle_fan(c, u), pdf_arvo_triangle_fan(c, w));
          AGREE(BaselineTurkArea, sample_turk_area(c, u), pdf_turk_area(c, w));
          AGREE(BaselineUrenaRectangle, sample_spherical_rectangle(c, u), pdf_spherical_rectangle(c, w));
        }
      } else if (t.family == "ltc") {
        const LtcPolygonGeometry<T> g = ltc_geometry(t).template cast<T>();
        AGREE(PolygonLtc, sample_ltc_polygon(g, u), pdf_ltc_polygon(g, w));
        const PreparedPolygonLight<T> prepared = prepare_polygon_light(g.polygon.light);
        LtcPolygonGeometry<T> gp = g;
        gp.polygon.prepared = &prepared;
        AGREE(PolygonLtc, sample_ltc_polygon(gp, u), pdf_ltc_polygon(gp, w));
      } else if (t.family == "sptd") {
        const SptdCapGeometry<T> g = sptd_geometry(t).template cast<T>();
        if (g.sptd.base == SptdBase::kUniform) {
          AGREE(SptdUniformCap, sample_sptd_cap(g, u), pdf_sptd_cap(g, w));
        } else {
          AGREE(SptdCosineCap, sample_sptd_cap(g, u), pdf_sptd_cap(g, w));
        }
      }
    }
  EXPECT_GT(valid, 1000);  // the comparison saw samples, not only "no sample"
}

}  // namespace

TEST(EntryPoints, GeometryOverloadsAgreeWithTheBatterysTraitsBitForBitInFloat) { check_all<float>(4); }
TEST(EntryPoints, GeometryOverloadsAgreeWithTheBatterysTraitsBitForBitInDouble) { check_all<double>(4); }
TEST(EntryPoints, GeometryOverloadsAgreeWithTheBatterysTraitsBitForBitInLongDouble) { check_all<long double>(4); }

// A preparation is used only for the light it was made from: a refused light's, attached to a valid light, changes
// nothing; a refused light's own preparation refuses it for the same reason.
TEST(EntryPoints, APolygonPreparationIsUsedOnlyForItsOwnLight) {
  const PolygonLightGeometry<double> g{ShadingPoint<double>{Vec3<double>(0.3, 0.2, 0), Vec3<double>(0, 0, 1)},
                                       PolygonLight<double>{{-1, -1, 1}, {1, -1, 1}, {1, 1, 1}, {-1, 1, 1}}};
  PolygonLight<double> bow_tie = g.light;
  std::swap(bow_tie.vertices[1], bow_tie.vertices[2]);
  const PreparedPolygonLight<double> refused = prepare_polygon_light(bow_tie);
  ASSERT_NE(refused.reason, NoSample::kNone);
  PolygonLightGeometry<double> other = g;
  other.prepared = &refused;
  int valid = 0;
  EXPECT_EQ(disagreements<PolygonSolidAngle<double>>(
                g, [&](const auto& u) { return sample_polygon_solid_angle(other, u); },
                [&](const auto& w) { return pdf_polygon_solid_angle(other, w); }, &valid),
            0);
  EXPECT_EQ(valid, 256);
  PolygonLightGeometry<double> own{g.shading, bow_tie, &refused};
  EXPECT_EQ(make_polygon_view(own).reason, refused.reason);
  own.prepared = nullptr;
  EXPECT_EQ(make_polygon_view(own).reason, refused.reason);
}

// The comparison sees an entry point that differs from the trait only in a default argument: one iteration of
// Peters 2021's Newton-bisection instead of two.
TEST(EntryPoints, TheComparisonSeesADifferentIterationCount) {
  int valid = 0, bad = 0;
  for (const GeometryText& t : random_geometry_texts(1, 0)) {
    if (t.family != "polygon") continue;
    const PolygonLightGeometry<double> g = polygon_geometry(t).cast<double>();
    const auto v = PolygonProjectedSolidAngle<double>::view(g);
    bad += disagreements<PolygonProjectedSolidAngle<double>>(
        g, [&](const Vec2<double>& u) { return sample_polygon_projected_solid_angle<double, false>(v, u, 1); },
        [&](const Vec3<double>& w) { return pdf_polygon_projected_solid_angle(g, w); }, &valid);
  }
  EXPECT_GT(valid, 0);
  EXPECT_GT(bad, 0);
}
