// SPDX-License-Identifier: MIT
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace whitted {

/// Writes display-referred RGB (already through the display transform; clipped and rounded
/// here) as a baseline 8-bit JPEG at quality 98 with libjpeg directly, with `icc_profile` (if
/// any) in APP2 markers and the metadata in an Exif block (Software, ImageDescription) and a
/// comment, one "key: value" a line. Throws std::runtime_error with libjpeg's or the system's
/// reason; the caller removes the file.
void write_jpeg(const std::string& path, int width, int height, const float* rgb,
                const std::vector<std::pair<std::string, std::string>>& metadata,
                const std::vector<unsigned char>& icc_profile);

}  // namespace whitted
