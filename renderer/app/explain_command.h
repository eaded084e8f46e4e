// SPDX-License-Identifier: MIT
#pragma once

#include "whitted/scene/scene.h"

#include <string>

namespace whitted {

/// `whitted explain SCENE --pixel X,Y [--json | --summary]`: prints every term of the pixel's
/// equation, or (--summary) each term averaged over its samples (docs/layers.md). Returns the
/// exit status: 0, 1 (failure while tracing), 2 (bad input or usage).
/// The pixel's explanation as `whitted explain --json` prints it (docs/explain.schema.json), for
/// `whitted live`; `scene_path` names the file in it. Throws std::invalid_argument for a pixel
/// outside the image.
std::string explain_pixel_json(const Scene& scene, const std::string& scene_path, int x, int y, int threads);

int run_explain(const std::string& scene_path, const std::string& pixel, bool json, bool summary, int threads);

}  // namespace whitted
