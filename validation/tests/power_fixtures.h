// The case the power tests inject errors into and plan for: sphere-solid-angle, double, near (a uniform cone over
// its bounding cap, so that each alternative's g is exactly what the figures assume).
#pragma once

#include <stdexcept>

#include "warpcheck/validation/registry.h"

namespace warpcheck::validation {

inline SamplerUnderTest uniform_cone_case() {
  const Registry reg = default_registry();
  for (const Case* c : reg.select({"sphere-solid-angle"}, {"near"}))
    if (c->scalar == "double") return c->make();
  throw std::logic_error("no sphere-solid-angle / double / near case in the registry");
}

}  // namespace warpcheck::validation
