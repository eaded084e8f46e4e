// SPDX-License-Identifier: MIT
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace whitted {

/// Writes display-referred RGB (already through the OCIO display transform, nominally 0-1) as
/// an 8- or 16-bit PNG with libpng, rounding each value to the nearest code after clamping to
/// [0, 1]. `metadata` becomes text chunks. Throws std::runtime_error with libpng's reason.
void write_png(const std::string& path, int width, int height, const float* rgb, int bits,
               const std::vector<std::pair<std::string, std::string>>& metadata);

}  // namespace whitted
