// SPDX-License-Identifier: MIT
#pragma once

#include "whitted/image.h"

#include <string>
#include <utility>
#include <vector>

namespace whitted {

/// Writes the scene-linear image (and its render layers) as an OpenEXR file with OpenEXR
/// directly: full or `half` floats, `compression` none (also ""), zip, zips, piz or rle, the
/// metadata as string attributes and Rec.709 chromaticities. Built into the plug-in
/// lib/libwhitted_exr.so (format_plugins.h). Throws std::invalid_argument for an unknown
/// compression, std::runtime_error with OpenEXR's reason.
void write_exr(const std::string& path, const Image& image, bool half, const std::string& compression,
               const std::vector<std::pair<std::string, std::string>>& metadata);

}  // namespace whitted
