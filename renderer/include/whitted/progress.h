// SPDX-License-Identifier: MIT
#pragma once

// How far a render is: public (whitted/whitted.h hands it to RenderOptions::on_progress) and the
// one type the renderer reports progress in. Plain data, no dependencies.

#include <cstddef>
#include <cstdint>

namespace whitted::api {

/// How far a render is.
struct Progress {
    size_t tiles_done = 0, tiles_total = 0;
    uint64_t rays = 0;
    double seconds = 0;  ///< since the render started
};

}  // namespace whitted::api
