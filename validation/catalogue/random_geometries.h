// validation/catalogue/random_geometries.h: the hooks through which random and promoted geometries join the
// registry (random_geometries.cpp), and the text form of a geometry that the results file and data/promoted/ hold.
//
// Each family registrar exposes its cases on one geometry given by the caller: every kernel of the family, in
// double and long double, with the same sampler, normalisations and known limitations as its named
// configurations. The name and description must outlive the registry (intern() keeps them for the process).
#pragma once

#include <map>
#include <string>
#include <vector>

#include "warpcheck/catalogue.h"
#include "warpcheck/validation/registry.h"

namespace warpcheck::validation {

// A string that lives as long as the process (the families' configurations name their cases by const char*).
const char* intern(const std::string& s);

std::vector<Case> sphere_geometry_cases(const char* name, const char* description, const SphereLightGeometry<Real>& g);
std::vector<Case> projected_cap_geometry_cases(const char* name, const char* description,
                                               const SphereLightGeometry<Real>& g);
// rectangle: also the kernels that take only rectangles (Urena et al. 2013).
std::vector<Case> polygon_geometry_cases(const char* name, const char* description, const PolygonLightGeometry<Real>& g,
                                         bool rectangle);
// The SPTD cap kernel whose base is g's.
std::vector<Case> sptd_geometry_cases(const char* name, const char* description, const SptdCapGeometry<Real>& g);
std::vector<Case> ltc_geometry_cases(const char* name, const char* description, const LtcPolygonGeometry<Real>& g);

// A geometry as text, "family key=v,v,v key=..." with every number printed to round-trip (17 significant digits
// of the doubles the generators draw), and back. Families: sphere, projected-cap, polygon, rectangle, sptd, ltc.
struct GeometryText {
  std::string family;
  std::map<std::string, std::vector<long double>> values;
};
std::string to_text(const GeometryText& g);
GeometryText parse_geometry_text(const std::string& text);  // throws std::runtime_error on malformed text

// The geometry of a text of its family (throws std::runtime_error when a value is missing).
SphereLightGeometry<Real> sphere_geometry(const GeometryText& t);    // sphere, projected-cap
PolygonLightGeometry<Real> polygon_geometry(const GeometryText& t);  // polygon, rectangle, ltc
LtcPolygonGeometry<Real> ltc_geometry(const GeometryText& t);        // ltc
SptdCapGeometry<Real> sptd_geometry(const GeometryText& t);          // sptd

// Random geometry `index` of seed `seed` of every family that has one (random-s<seed>-<index>).
std::vector<GeometryText> random_geometry_texts(std::uint64_t seed, int index);

// The cases of one geometry given as text (a promoted geometry), under the configuration name `name`.
std::vector<Case> geometry_text_cases(const std::string& name, const std::string& description, const GeometryText& g);

}  // namespace warpcheck::validation
