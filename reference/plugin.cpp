// SPDX-License-Identifier: MIT
// The OpenImageIO plug-in (lib/libwhitted_oiio.so; why it is separate: whitted/output/plugin.h).
// Its entry points are looked up by name with dlsym; both sides are built together by the same
// compiler, so they pass C++ types.

#include "reference/check.h"
#include "reference/file_colour.h"
#include "whitted/scene/source_location.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

extern "C" {

/// `whitted check`: returns the exit status (0 pass, 1 images differ, 2 cannot check) and
/// prints its own messages.
__attribute__((visibility("default"))) int whitted_run_check(const std::string& scene_path,
                                                             const whitted::reference::CheckOptions& options) {
    try {
        return whitted::reference::run_check(scene_path, options).passed ? 0 : 1;
    } catch (const whitted::InputError& e) {
        std::fprintf(stderr, "whitted: error: %s\n", e.what());
        return 2;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "whitted: error: %s\n", e.what());
        return 2;
    }
}

/// `whitted compare A B`: per-channel comparison of two images of the same size, each first
/// converted to linear Rec.709 from its colour metadata (refused, exit 2, when that is not
/// known); with `clip` both are then clipped to [0, 1] (to compare a float EXR with a PNG,
/// which clips).
/// Returns 0 when at least `required_fraction` of the pixels are within `tolerance`, else 1; 2
/// when an image cannot be read or the sizes differ.
__attribute__((visibility("default"))) int whitted_run_compare(const std::string& first, const std::string& second,
                                                               double tolerance, bool clip, double required_fraction) {
    using namespace whitted::reference;
    try {
        // Each file as what its metadata says it is, in linear Rec.709: a linear EXR against a
        // display-referred PNG compares light with light, not light with display codes.
        const LinearImage first_linear = read_as_linear_rec709(first), second_linear = read_as_linear_rec709(second);
        std::printf("%s: %s\n%s: %s\n", first.c_str(), first_linear.meaning.c_str(), second.c_str(),
                    second_linear.meaning.c_str());
        whitted::Image a = first_linear.image, b = second_linear.image;
        if (a.width != b.width || a.height != b.height) {
            std::fprintf(stderr, "whitted: error: %s is %dx%d but %s is %dx%d\n", first.c_str(), a.width, a.height,
                         second.c_str(), b.width, b.height);
            return 2;
        }
        if (clip)
            for (auto* image : {&a, &b})
                for (float& v : image->rgb) v = std::min(std::max(v, 0.0f), 1.0f);
        const ImageComparison c = compare_images(a, b, tolerance);
        const bool passed = c.fraction_within() >= required_fraction;
        std::printf("%s %s vs %s: %s of pixels within %.3g/65535, max %.2f codes at (%d, %d), RMS %.3g\n",
                    passed ? "PASS" : "FAIL", first.c_str(), second.c_str(), format_percent(c).c_str(),
                    tolerance * 65535, c.max_error * 65535, c.worst_x, c.worst_y, c.rms_error);
        return passed ? 0 : 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "whitted: error: %s\n", e.what());
        return 2;
    }
}

}  // extern "C"
