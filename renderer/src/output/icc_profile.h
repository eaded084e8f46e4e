// SPDX-License-Identifier: MIT
#pragma once

#include "output/color_management.h"

#include <string>
#include <vector>

namespace whitted {

/// An ICC v4 display profile (matrix/TRC: D50-adapted primaries, parametric curves) that says
/// what a display-referred JPEG or TIFF holds; `description` becomes its 'desc' tag. Empty when
/// the encoding is not known (nothing truthful to embed).
std::vector<unsigned char> icc_profile(const DisplayEncoding& encoding, const std::string& description);

}  // namespace whitted
