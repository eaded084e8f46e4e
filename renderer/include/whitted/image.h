// SPDX-License-Identifier: MIT
#pragma once

// Whitted's image (film) type, public: the renderer fills it, the writers write it, the
// POV-Ray check compares it, and the library hands it to callers. Plain data, no dependencies.

#include <cstddef>
#include <string>
#include <vector>

namespace whitted {

/// One render layer of an image: `channels.size()` floats per pixel, named as EXR readers expect
/// (`diffuse.R`, `N.X`, `Z`, ...); docs/layers.md lists them.
struct ImageLayer {
    std::string name;
    std::vector<std::string> channels;  ///< full EXR channel names
    bool data = false;                  ///< a data layer (normals, ids, ...): always 32-bit float
    std::vector<float> values;          ///< channels.size() per pixel, rows from the top
};

/// A linear, scene-referred RGB image (Rec.709 primaries), rows from the top.
struct Image {
    int width = 0, height = 0;
    std::vector<float> rgb;          ///< 3 floats per pixel, R G B: the beauty
    std::vector<ImageLayer> layers;  ///< render layers, when asked for (docs/layers.md)
    const float* pixel(int x, int y) const { return &rgb[3 * (size_t(y) * size_t(width) + size_t(x))]; }
};

}  // namespace whitted
