// warpcheck/validation/registry.h: the kernels and named configurations the CLI validates.
//
// Each kernel family of lib/warpcheck/catalogue.h has one registrar function (register_<family>_kernels) in
// validation/catalogue/<family>.cpp that adds one Case per (kernel, scalar type, configuration), named by the
// kernel's catalogue name. default_registry() calls every registrar; adding a family means adding its registrar
// there.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "warpcheck/validation/battery.h"
#include "warpcheck/validation/sampler.h"

namespace warpcheck::validation {

struct Case {
  std::string kernel;       // e.g. "sphere-solid-angle"
  std::string scalar;       // "float", "double", "long double"
  std::string config;       // e.g. "near"
  std::string description;  // one line: the geometry in words
  std::function<SamplerUnderTest()> make;
  // Extra results a family wants in the JSON for this case (e.g. estimator variances, which the report
  // compares across kernels). Deterministic results only: p_value null; passed is set by the family.
  std::function<std::vector<TestResult>(const BatteryOptions&)> extras;
  // Non-empty when this case is a documented, expected failure (e.g. float on a 1 mm light 40 m away): the
  // battery still runs it and reports it, with this reason, but it does not fail the run.
  std::string known_limitation;
};

class Registry {
 public:
  void add(Case c) { cases_.push_back(std::move(c)); }
  const std::vector<Case>& cases() const { return cases_; }
  // Cases whose kernel name matches any of kernel_globs (or all if empty) and config any of config_globs.
  std::vector<const Case*> select(const std::vector<std::string>& kernel_globs,
                                  const std::vector<std::string>& config_globs) const;

 private:
  std::vector<Case> cases_;
};

// fnmatch-style glob: '*' any run, '?' one character.
bool glob_match(const std::string& pattern, const std::string& text);

// Random geometries (validation/catalogue/random_geometries.cpp): `count` per kernel family drawn from `seed`,
// configurations random-s<seed>-<index>; `names` adds single ones by that name (the replay of a failure).
struct RandomGeometries {
  int count = 0;
  std::uint64_t seed = 1;
  std::vector<std::string> names;
};

// The named configurations, the promoted geometries (data/promoted/*.txt, read at run time from the source tree),
// and the random geometries asked for.
Registry default_registry(const RandomGeometries& random = {});

void register_random_geometries(Registry& r, const RandomGeometries& random);
// The geometries of data/promoted/*.txt under `dir`, as configurations promoted-<file name without .txt>.
void register_promoted_geometries(Registry& r, const std::string& dir);
// Whether `name` is random-s<seed>-<index>; sets seed and index.
bool parse_random_config_name(const std::string& name, std::uint64_t* seed, int* index);

// Registrars, one per kernel family.
void register_sphere_kernels(Registry& r);
void register_polygon_kernels(Registry& r);
void register_projected_cap_kernels(Registry& r);
void register_sptd_kernels(Registry& r);

}  // namespace warpcheck::validation
