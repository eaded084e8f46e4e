// SPDX-License-Identifier: MIT
#pragma once

#include "whitted/whitted.h"

#include <string>

namespace whitted {

/// `whitted explain SCENE --pixel X,Y [--json | --summary]`: prints every term of the pixel's
/// equation, or (--summary) each term averaged over its samples (docs/layers.md), with the
/// scene's settings replaced by `overrides` (--intersection). Returns the
/// exit status: 0, 1 (failure while tracing), 2 (bad input or usage).
int run_explain(const std::string& scene_path, const std::string& pixel, const api::SceneOverrides& overrides,
                bool json, bool summary, int threads);

}  // namespace whitted
