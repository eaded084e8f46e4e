// SPDX-License-Identifier: MIT
#pragma once

#include "whitted/image.h"

#include <string>

namespace whitted::reference {

/// An image read for `whitted compare`, turned into linear Rec.709 from what its metadata says
/// it holds: `meaning` says what was found and what was done, e.g. "sRGB transfer, Rec.709
/// primaries (PNG sRGB chunk): decoded to linear".
struct LinearImage {
    Image image;
    std::string meaning;
};

/// Reads `path` and converts it to linear Rec.709 when its metadata says, in a way known in
/// closed form, what the values are: float files (EXR) are linear; Whitted's own files say
/// it in whitted:encoding (PNG) or their image description (JPEG, TIFF); other files by what
/// OpenImageIO reports (oiio:ColorSpace: sRGB, GammaN, linear). Throws std::runtime_error
/// when the file cannot be read, and std::invalid_argument naming the file and what it says
/// when its values cannot be made linear (a tone curve, unknown primaries or colour space).
LinearImage read_as_linear_rec709(const std::string& path);

}  // namespace whitted::reference
