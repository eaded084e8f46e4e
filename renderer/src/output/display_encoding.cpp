// SPDX-License-Identifier: MIT
// Built into the program and into the OpenColorIO plug-in (output/ocio_plugin.h), which
// both describe encodings.
#include "output/color_management.h"

namespace whitted {

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
