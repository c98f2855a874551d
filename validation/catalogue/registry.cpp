#include "warpcheck/validation/registry.h"

namespace warpcheck::validation {

bool glob_match(const std::string& p, const std::string& s) {
  // Iterative wildcard match with backtracking to the last '*'.
  std::size_t i = 0, j = 0, star = std::string::npos, mark = 0;
  while (j < s.size()) {
    if (i < p.size() && (p[i] == '?' || p[i] == s[j])) {
      ++i, ++j;
    } else if (i < p.size() && p[i] == '*') {
      star = i++, mark = j;
    } else if (star != std::string::npos) {
      i = star + 1, j = ++mark;
    } else {
      return false;
    }
  }
  while (i < p.size() && p[i] == '*') ++i;
  return i == p.size();
}

static bool any_match(const std::vector<std::string>& globs, const std::string& s) {
  if (globs.empty()) return true;
  for (const auto& g : globs)
    if (glob_match(g, s)) return true;
  return false;
}

std::vector<const Case*> Registry::select(const std::vector<std::string>& kernel_globs,
                                          const std::vector<std::string>& config_globs) const {
  std::vector<const Case*> out;
  for (const Case& c : cases_)
    if (any_match(kernel_globs, c.kernel) && any_match(config_globs, c.config)) out.push_back(&c);
  return out;
}

Registry default_registry(const RandomGeometries& random) {
  Registry r;
  // One line per kernel family.
  register_sphere_kernels(r);
  register_polygon_kernels(r);
  register_projected_cap_kernels(r);
  register_sptd_kernels(r);
  register_promoted_geometries(r, WARPCHECK_SOURCE_DIR "/data/promoted");
  register_random_geometries(r, random);
  return r;
}

}  // namespace warpcheck::validation
