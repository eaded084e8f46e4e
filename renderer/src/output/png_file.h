// SPDX-License-Identifier: MIT
#pragma once

#include "output/color_management.h"
#include "whitted/image.h"

#include <string>
#include <utility>
#include <vector>

namespace whitted {

/// Writes the linear image through the display transform as an 8- or 16-bit PNG with libpng,
/// each display value rounded to the nearest code after clamping to [0, 1] (NaN gives 0).
/// `metadata` becomes text chunks. Throws std::runtime_error with libpng's reason.
void write_png(const std::string& path, const Image& linear, const DisplayTransform& display, int bits,
               const std::vector<std::pair<std::string, std::string>>& metadata);

}  // namespace whitted
