// SPDX-License-Identifier: MIT
// The OpenImageIO plug-in (lib/libwhitted_oiio.so; why it is separate: whitted/output/plugin.h).
// Its entry points are looked up by name with dlsym; both sides are built together by the same
// compiler, so they pass C++ types.

#include "reference/check.h"
#include "whitted/scene/source_location.h"

#include <OpenImageIO/imageio.h>

#include <cstdio>
#include <string>
#include <utility>
#include <vector>

extern "C" {

/// Writes display-referred RGB (already through the OCIO transform) as an 8- or 16-bit file of
/// the type `format_path`'s extension names, to `temp_path`. Returns "" or the error.
__attribute__((visibility("default"))) std::string whitted_write_display_image(
    const std::string& format_path, const std::string& temp_path, int width, int height, const float* rgb, int bits,
    const std::vector<std::pair<std::string, std::string>>& metadata) {
    OIIO::ImageSpec spec(width, height, 3, bits == 16 ? OIIO::TypeDesc::UINT16 : OIIO::TypeDesc::UINT8);
    for (const auto& [key, value] : metadata) spec.attribute(key, value);
    auto out = OIIO::ImageOutput::create(format_path);
    if (!out) return OIIO::geterror();
    if (!out->open(temp_path, spec)) return out->geterror();
    // OpenImageIO rounds and clamps the floats to the integer range.
    const bool wrote = out->write_image(OIIO::TypeDesc::FLOAT, rgb);
    const bool closed = out->close();
    return wrote && closed ? std::string() : out->geterror();
}

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

}  // extern "C"
