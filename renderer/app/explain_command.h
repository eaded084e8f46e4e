// SPDX-License-Identifier: MIT
#pragma once

#include <string>

namespace whitted {

/// `whitted explain SCENE --pixel X,Y [--json]`: prints every term of the pixel's equation
/// (docs/layers.md). Returns the exit status: 0, 1 (failure while tracing), 2 (bad input or usage).
int run_explain(const std::string& scene_path, const std::string& pixel, bool json, int threads);

}  // namespace whitted
