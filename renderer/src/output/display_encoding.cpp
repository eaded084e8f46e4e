// SPDX-License-Identifier: MIT
// Built into the program and into the OpenColorIO plug-in (output/ocio_plugin.h), which
// both describe encodings.
#include "output/color_management.h"

#include <cmath>

namespace whitted {

double encode(DisplayEncoding::Transfer transfer, double linear) {
    switch (transfer) {
        case DisplayEncoding::Transfer::srgb:
            return linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1 / 2.4) - 0.055;
        case DisplayEncoding::Transfer::gamma22:
            return std::pow(linear, 1 / 2.2);
        case DisplayEncoding::Transfer::gamma24:
            return std::pow(linear, 1 / 2.4);
        case DisplayEncoding::Transfer::linear:
        case DisplayEncoding::Transfer::unknown:
            break;
    }
    return linear;
}

double decode(DisplayEncoding::Transfer transfer, double code) {
    switch (transfer) {
        case DisplayEncoding::Transfer::srgb:
            return code <= 0.04045 ? code / 12.92 : std::pow((code + 0.055) / 1.055, 2.4);
        case DisplayEncoding::Transfer::gamma22:
            return std::pow(code, 2.2);
        case DisplayEncoding::Transfer::gamma24:
            return std::pow(code, 2.4);
        case DisplayEncoding::Transfer::linear:
        case DisplayEncoding::Transfer::unknown:
            break;
    }
    return code;
}

std::string DisplayEncoding::description() const {
    std::string text;
    switch (transfer) {
        case Transfer::linear:
            text = "linear (no transfer function)";
            break;
        case Transfer::srgb:
            text = "sRGB transfer (IEC 61966-2-1)";
            break;
        case Transfer::gamma22:
            text = "gamma 2.2";
            break;
        case Transfer::gamma24:
            text = "gamma 2.4 (BT.1886)";
            break;
        case Transfer::unknown:
            return "not a plain transfer function (the file records only the names)";
    }
    switch (primaries) {
        case Primaries::rec709:
            return text + ", Rec.709 primaries, D65 white";
        case Primaries::display_p3:
            return text + ", P3-D65 primaries, D65 white";
        case Primaries::unknown:
            break;
    }
    return text + ", other primaries (the file records only the names)";
}

}  // namespace whitted
