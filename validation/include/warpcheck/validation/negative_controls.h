// warpcheck/validation/negative_controls.h: deliberately broken samplers the battery must reject.
//
// Each control wraps the correct double-precision sphere solid-angle sampler of the "near" configuration (a
// uniform cone, where t = (1 - cos theta) / (1 - cos theta_max) is uniform and equals u0) and breaks one thing:
//   pdf-1pct-high-on-tenth  samples are 1% denser than the reported pdf on t in [0, 0.1] (a tenth of the
//                           support), and 0.1/0.9 % thinner elsewhere; the reported pdf is the correct uniform one
//   wrong-cosine            t = u0^1.005 instead of u0: the cosine follows a slightly wrong distribution
//   outside-now-and-then    when frac(1e7 u1) < 1e-5 (one draw in 1e5), the sample lands outside the light at
//                           t in [1.05, 1.2]; otherwise correct
//   pdf-disagrees-with-warp samples are correct but sample and pdf() both report pdf (1 + 0.02 (t - 0.5)), which
//                           still integrates to 1 and is not the warp's density
//   pdf-1pct-low-everywhere samples are correct but sample and pdf() both report 0.99 of the density: a pdf that
//                           integrates to less than 1 (a missing share of the mass)
// Tests (validation/tests/test_negative_controls.cpp) assert that the battery rejects each at the default
// sample count with a p-value below 1e-6; `warpcheck validate --negative-controls` runs them from the CLI.
#pragma once

#include <vector>

#include "warpcheck/validation/registry.h"
#include "warpcheck/validation/sampler.h"

namespace warpcheck::validation {

std::vector<SamplerUnderTest> negative_controls();
// The same controls as registry cases (kernel "negative-control:<name>", scalar double, config "near").
Registry negative_control_registry();

}  // namespace warpcheck::validation
