// SPDX-License-Identifier: MIT
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace whitted {

/// Writes display-referred RGB (already through the display transform; clipped and rounded
/// here) as an 8- or 16-bit RGB TIFF with libtiff directly (deflate at level 1 with the
/// horizontal predictor), with `icc_profile` (if any), Software and an ImageDescription of one
/// "key: value" a line. Throws std::runtime_error with libtiff's or the system's reason; the
/// caller removes the file.
void write_tiff(const std::string& path, int width, int height, const float* rgb, int bits,
                const std::vector<std::pair<std::string, std::string>>& metadata,
                const std::vector<unsigned char>& icc_profile);

}  // namespace whitted
