// SPDX-License-Identifier: MIT
// The OpenImageIO plug-in (lib/libwhitted_oiio.so; why it is separate: whitted/core/plugin.h).
// Its entry points are looked up by name with dlsym; both sides are built together by the same
// compiler, so they pass C++ types.

#include "reference/check.h"
#include "reference/file_colour.h"
#include "whitted/scene/errors.h"
#include "whitted/scene/source_location.h"
#include "whitted/scene/text_checks.h"
#include "whitted/whitted.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

namespace {

/// What `check` throws: a scene or an option it cannot check with is the caller's input (POV-Ray
/// missing included), as for every command.
whitted::api::ErrorContext check_context(const std::string& scene_path) {
    return {"checking " + scene_path, "", whitted::api::Error::Kind::bad_input};
}

}  // namespace

extern "C" {

/// `whitted check`: returns the exit status (0 pass, 1 images differ, 2 cannot check, 128 +
/// the signal when interrupted) and prints its own messages.
__attribute__((visibility("default"))) int whitted_run_check(const std::string& scene_path,
                                                             const whitted::reference::CheckRun& options,
                                                             const std::atomic<int>& signal) {
    try {
        if (options.terms) return whitted::reference::run_check_terms(scene_path, options) ? 0 : 1;
        return whitted::reference::run_check(scene_path, options).passed ? 0 : 1;
    } catch (const whitted::reference::Interrupted&) {
        std::fprintf(stderr, "whitted: interrupted; POV-Ray stopped, temporary files removed\n");
        return 128 + (signal.load() ? signal.load() : SIGINT);
    } catch (...) {
        return whitted::api::report(whitted::api::current_error(check_context(scene_path)));
    }
}

/// whitted::api::check (whitted/whitted.h): run_check with its result and verdict line handed
/// back, and its errors as a value (exceptions stay on this side of dlopen). Returns 0 when the
/// check ran (passed or not), 2 for bad input, 1 for a failure.
__attribute__((visibility("default"))) int whitted_api_check(const std::string& scene_path,
                                                             const whitted::reference::CheckRun& options,
                                                             whitted::reference::CheckRecord& result,
                                                             std::string& verdict, whitted::api::Error& error) {
    try {
        result = whitted::reference::run_check(scene_path, options);
        verdict = whitted::reference::verdict_line(scene_path, result, options);
        return 0;
    } catch (...) {
        error = whitted::api::current_error(check_context(scene_path));
        return whitted::api::exit_status(error);
    }
}

/// `whitted compare A B`: per-channel comparison of two images under `rule` (the share, cap,
/// finite, size and channels rules), each first converted to linear Rec.709 from its colour
/// metadata (refused, exit 2, when that is not known); with `clip` both are then clipped to
/// [0, 1] (to compare a float EXR with a PNG, which clips), NaN/Inf values counted before that.
/// Returns 0 when every rule holds, else 1; 2 when an image cannot be read or decoded.
__attribute__((visibility("default"))) int whitted_run_compare(const std::string& first, const std::string& second,
                                                               const whitted::reference::PassRule& rule, bool clip) {
    using namespace whitted::reference;
    try {
        // Both headers first: an unreadable second file is found before the first is read.
        const ImageShape shape_a = read_image_shape(first), shape_b = read_image_shape(second);
        const std::string subject = first + " vs " + second;
        std::vector<std::string> failures = shape_mismatches(shape_a, shape_b);
        if (!failures.empty()) {
            std::printf("%s\n", verdict_text(subject, "", failures).c_str());
            return 1;
        }
        // Each file as what its metadata says it is, in linear Rec.709: a linear EXR against a
        // display-referred PNG compares light with light, not light with display codes.
        const LinearImage first_linear = read_as_linear_rec709(first), second_linear = read_as_linear_rec709(second);
        std::printf("%s: %s\n%s: %s\n", first.c_str(), first_linear.meaning.c_str(), second.c_str(),
                    second_linear.meaning.c_str());
        whitted::Image a = first_linear.image, b = second_linear.image;
        size_t nonfinite[2] = {0, 0};
        int index = 0;
        for (auto* image : {&a, &b}) {
            for (float& v : image->rgb) {
                nonfinite[index] += !std::isfinite(v);
                // Clipping would turn an Inf into 1: counted above, and kept NaN here.
                if (clip && std::isfinite(v)) v = std::min(std::max(v, 0.0f), 1.0f);
            }
            ++index;
        }
        ImageComparison c = compare_images(a, b, rule.tolerance, 1);
        c.nonfinite_ours = nonfinite[0];
        c.nonfinite_theirs = nonfinite[1];
        failures = failed_rules(c, rule, first, second);
        std::string figures = verdict_figures(c, rule);
        if (!c.worst.empty())
            figures += " at (" + std::to_string(c.worst[0].x) + ", " + std::to_string(c.worst[0].y) + ")";
        char rms[32];
        std::snprintf(rms, sizeof rms, ", RMS %.3g", c.rms_error);
        std::printf("%s\n", verdict_text(subject, figures + rms, failures).c_str());
        return failures.empty() ? 0 : 1;
    } catch (...) {
        // An image that cannot be read or decoded is the caller's input.
        return whitted::api::report(whitted::api::current_error(
            {"comparing " + first + " and " + second, "", whitted::api::Error::Kind::bad_input}));
    }
}

}  // extern "C"
