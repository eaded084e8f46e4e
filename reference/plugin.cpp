// SPDX-License-Identifier: MIT
// The OpenImageIO plug-in (lib/libwhitted_oiio.so; why it is separate: core/plugin.h).
// Its entry points are looked up by name with dlsym; both sides are built together by the same
// compiler, so they pass C++ types.

#include "reference/check.h"
#include "reference/file_colour.h"
#include "scene/errors.h"
#include "scene/source_location.h"
#include "scene/text_checks.h"
#include "whitted/whitted.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <atomic>
#include <cmath>
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

/// whitted::api::check (whitted/whitted.h): run_check, or run_check_terms, with what it found and
/// its verdict line handed back, and its errors as a value (exceptions stay on this side of
/// dlopen). False on an error: `error` then says what, of kind cancelled when a signal stopped it.
__attribute__((visibility("default"))) bool whitted_api_check(const std::string& scene_path,
                                                              const whitted::reference::CheckRun& options,
                                                              whitted::reference::CheckRecord& result,
                                                              std::vector<std::string>& failed_terms,
                                                              std::string& verdict, whitted::api::Error& error) {
    try {
        if (options.terms) {
            verdict = whitted::reference::run_check_terms(scene_path, options, failed_terms);
            result.passed = failed_terms.empty();
            return true;
        }
        result = whitted::reference::run_check(scene_path, options);
        verdict = whitted::reference::verdict_line(scene_path, result, options);
        return true;
    } catch (const whitted::reference::Interrupted&) {
        error = {"interrupted; POV-Ray stopped, temporary files removed", "", 0, 0,
                 whitted::api::Error::Kind::cancelled};
        return false;
    } catch (...) {
        error = whitted::api::current_error(check_context(scene_path));
        return false;
    }
}

/// whitted::api::compare_image_files: per-channel comparison of two images under `rule` (the
/// share, cap, finite, size and channels rules), each first converted to linear Rec.709 from its
/// colour metadata (refused when that is not known); with `clip` both are then clipped to [0, 1]
/// (to compare a float EXR with a PNG, which clips), NaN/Inf values counted before that. False
/// when an image cannot be read or decoded: `error` says why.
__attribute__((visibility("default"))) bool whitted_api_compare(const std::string& first, const std::string& second,
                                                                const whitted::api::PassRule& given, bool clip,
                                                                whitted::api::Comparison& out,
                                                                whitted::api::Error& error) {
    using namespace whitted::reference;
    try {
        PassRule rule;
        rule.tolerance = given.tolerance_codes / 65535.0;
        rule.required_fraction = given.min_fraction;
        rule.max_error = given.max_error_codes / 65535.0;
        // Both headers first: an unreadable second file is found before the first is read.
        const ImageShape shape_a = read_image_shape(first), shape_b = read_image_shape(second);
        const std::string subject = first + " vs " + second;
        out.failures = shape_mismatches(shape_a, shape_b);
        if (!out.failures.empty()) {
            out.verdict = verdict_text(subject, "", out.failures);
            return true;
        }
        // Each file as what its metadata says it is, in linear Rec.709: a linear EXR against a
        // display-referred PNG compares light with light, not light with display codes.
        const LinearImage first_linear = read_as_linear_rec709(first), second_linear = read_as_linear_rec709(second);
        out.first_meaning = first_linear.meaning;
        out.second_meaning = second_linear.meaning;
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
        out.failures = failed_rules(c, rule, first, second);
        std::string figures = verdict_figures(c, rule);
        if (!c.worst.empty())
            figures += " at (" + std::to_string(c.worst[0].x) + ", " + std::to_string(c.worst[0].y) + ")";
        char rms[32];
        std::snprintf(rms, sizeof rms, ", RMS %.3g", c.rms_error);
        out.verdict = verdict_text(subject, figures + rms, out.failures);
        out.passed = out.failures.empty();
        out.fraction_within = c.fraction_within();
        out.max_error_codes = c.max_error * 65535.0;
        out.rms_error = c.rms_error;
        return true;
    } catch (...) {
        // An image that cannot be read or decoded is the caller's input.
        error = whitted::api::current_error(
            {"comparing " + first + " and " + second, "", whitted::api::Error::Kind::bad_input});
        return false;
    }
}

}  // extern "C"
