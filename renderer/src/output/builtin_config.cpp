// SPDX-License-Identifier: MIT
// The built-in config's display transforms, computed by the program (builtin_config.h says
// why): the matrix and the transfer function in double, each value rounded to float once.
#include "output/builtin_config.h"

#include "output/chromaticities.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace whitted {
namespace {

/// Applies `transform` to every pixel (its three floats, in place): a large buffer in chunks on
/// all cores, a small one on the calling thread (a PNG's rows come eight at a time). A pixel
/// equal to the one before it (a background, a flat wall) takes that one's result: the
/// transform's `pow` per value is most of the cost of writing a file.
template <class Transform>
void for_each_pixel(float* rgb, size_t pixel_count, const Transform& transform) {
    constexpr size_t chunk = 32768;
    const auto run = [&](size_t first, size_t count) {
        float before[3] = {NAN, NAN, NAN}, after[3] = {};
        for (float *p = rgb + 3 * first, *end = p + 3 * count; p != end; p += 3) {
            if (p[0] == before[0] && p[1] == before[1] && p[2] == before[2]) {
                std::copy_n(after, 3, p);
                continue;
            }
            std::copy_n(p, 3, before);
            transform(p);
            std::copy_n(p, 3, after);
        }
    };
    if (pixel_count <= chunk) return run(0, pixel_count);
    tbb::parallel_for(size_t(0), (pixel_count + chunk - 1) / chunk, [&](size_t c) {
        const size_t first = c * chunk;
        run(first, std::min(chunk, pixel_count - first));
    });
}

}  // namespace

DisplayTransformParts builtin_display_transform(const std::string& display, const std::string& view) {
    DisplayTransformParts parts;
    parts.source = "built-in";
    parts.config_name = builtin_config_name;
    const BuiltinDisplay* chosen = display.empty() ? &builtin_displays[0] : nullptr;
    for (const BuiltinDisplay& d : builtin_displays)
        if (d.name == display) chosen = &d;
    if (!chosen)
        throw std::invalid_argument("OpenColorIO display '" + display +
                                    "' is not in the config (built-in); displays: " + builtin_display_list());
    parts.display = chosen->name;
    parts.view = view.empty() ? builtin_views[0] : view;
    if (parts.view != builtin_views[0] && parts.view != builtin_views[1])
        throw std::invalid_argument("OpenColorIO view '" + parts.view + "' is not a view of display '" + parts.display +
                                    "'; views: " + builtin_view_list());

    if (parts.view == builtin_views[1]) {
        // Raw: a data space, the scene values as they are (the file clips them).
        parts.colorspace = builtin_raw;
        parts.encoding = {DisplayEncoding::Transfer::linear, DisplayEncoding::Primaries::rec709};
        parts.apply = [](float*, size_t) {};
        return parts;
    }
    parts.colorspace = chosen->colorspace;
    parts.encoding = {chosen->transfer, chosen->primaries};
    const DisplayEncoding::Transfer transfer = chosen->transfer;
    // A value at or below 0 (or NaN) has no light to encode: code 0, which is also what the
    // files clip it to.
    const auto code = [transfer](double linear) { return linear > 0 ? float(encode(transfer, linear)) : 0.0f; };
    if (chosen->primaries == DisplayEncoding::Primaries::display_p3) {
        // Rec.709 → P3-D65, both D65: no adaptation.
        const Matrix3 m = multiply(inverse(rgb_to_xyz(display_p3_chromaticities)), rgb_to_xyz(rec709_chromaticities));
        parts.apply = [m, code](float* rgb, size_t pixel_count) {
            for_each_pixel(rgb, pixel_count, [&](float* p) {
                const double r = p[0], g = p[1], b = p[2];
                for (size_t k = 0; k < 3; ++k) p[k] = code(m[k][0] * r + m[k][1] * g + m[k][2] * b);
            });
        };
    } else {
        parts.apply = [code](float* rgb, size_t pixel_count) {
            for_each_pixel(rgb, pixel_count, [&](float* p) {
                for (size_t k = 0; k < 3; ++k) p[k] = code(p[k]);
            });
        };
    }
    return parts;
}

}  // namespace whitted
