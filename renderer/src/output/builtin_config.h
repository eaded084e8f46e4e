// SPDX-License-Identifier: MIT
#pragma once

#include "output/color_management.h"

#include <string>

/// Whitted's built-in colour config, described once. Every display of it is closed-form (a
/// transfer function, for Display P3 after a 3×3 matrix), so the program applies it itself,
/// exactly (builtin_config.cpp), and a PNG, JPEG or TIFF written with it needs no
/// OpenColorIO; the OpenColorIO plug-in builds the same config from this table as an OCIO
/// config, for `whitted colour --write-config` and `--list` (ocio_display.cpp).
namespace whitted {

/// One display: its Standard view writes `colorspace`, which is `transfer` on `primaries`.
struct BuiltinDisplay {
    const char* name;
    const char* colorspace;
    const char* description;
    DisplayEncoding::Transfer transfer;
    DisplayEncoding::Primaries primaries;
};

inline constexpr const char* builtin_config_name = "whitted-builtin";
inline constexpr const char* builtin_config_description =
    "Whitted's built-in config: linear Rec.709 scene values; sRGB, Gamma 2.2, BT.1886 and Display P3 "
    "displays, each with a Standard view (the display's encoding) and a Raw view (no conversion).";
inline constexpr const char* builtin_scene_linear = "Linear Rec.709 (sRGB)";

/// In the config's order: the first is the default display.
inline constexpr BuiltinDisplay builtin_displays[] = {
    {"sRGB", "sRGB - Display", "The sRGB piecewise curve (IEC 61966-2-1) on Rec.709 primaries, D65.",
     DisplayEncoding::Transfer::srgb, DisplayEncoding::Primaries::rec709},
    {"Gamma 2.2", "Gamma 2.2 Rec.709 - Display",
     "A pure 2.2 power law on Rec.709 primaries, D65 (the Cornell course's reference images).",
     DisplayEncoding::Transfer::gamma22, DisplayEncoding::Primaries::rec709},
    {"BT.1886", "BT.1886 Rec.709 - Display",
     "Rec.709 video as an ITU-R BT.1886 display shows it (black 0, white 1: a 2.4 power law) on Rec.709 "
     "primaries, D65.",
     DisplayEncoding::Transfer::gamma24, DisplayEncoding::Primaries::rec709},
    {"Display P3", "Display P3 - Display", "Apple's Display P3: the sRGB curve on P3-D65 (SMPTE EG 432-1) primaries.",
     DisplayEncoding::Transfer::srgb, DisplayEncoding::Primaries::display_p3},
};

/// Every display's views, the first the default: Standard writes the display's colour space,
/// Raw writes the scene values unchanged (colour space builtin_raw, a data space).
inline constexpr const char* builtin_views[] = {"Standard", "Raw"};
inline constexpr const char* builtin_raw = "Raw";
inline constexpr const char* builtin_raw_description =
    "No conversion: the linear Rec.709 values, clipped to the file's range.";

/// The displays' names as the config's active list writes them: "sRGB, Gamma 2.2, ...".
inline std::string builtin_display_list() {
    std::string list;
    for (const BuiltinDisplay& display : builtin_displays) {
        if (!list.empty()) list += ", ";
        list += display.name;
    }
    return list;
}

/// The views' names the same way: "Standard, Raw".
inline std::string builtin_view_list() {
    std::string list;
    for (const char* view : builtin_views) {
        if (!list.empty()) list += ", ";
        list += view;
    }
    return list;
}

/// The display transform of the built-in config for `display` and `view` (empty: the
/// defaults), computed in double and rounded to float once per value. Throws
/// std::invalid_argument for an unknown name, listing the known ones (the words OpenColorIO's
/// side uses for a config file).
DisplayTransformParts builtin_display_transform(const std::string& display, const std::string& view);

}  // namespace whitted
