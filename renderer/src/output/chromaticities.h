// SPDX-License-Identifier: MIT
#pragma once

#include <array>

namespace whitted {

/// CIE xy of an RGB space's primaries and white point.
struct Chromaticities {
    double red[2], green[2], blue[2], white[2];
};

/// ITU-R BT.709 (= sRGB) primaries, D65 white: what Whitted's scene-linear values are in.
inline constexpr Chromaticities rec709_chromaticities{{0.64, 0.33}, {0.30, 0.60}, {0.15, 0.06}, {0.3127, 0.3290}};
/// SMPTE EG 432-1 "P3-D65" (Apple's Display P3), D65 white.
inline constexpr Chromaticities display_p3_chromaticities{
    {0.680, 0.320}, {0.265, 0.690}, {0.150, 0.060}, {0.3127, 0.3290}};

using Matrix3 = std::array<std::array<double, 3>, 3>;

/// Linear RGB → CIE XYZ (white Y = 1), from the chromaticities (SMPTE RP 177).
Matrix3 rgb_to_xyz(const Chromaticities& c);
Matrix3 inverse(const Matrix3& m);
Matrix3 multiply(const Matrix3& a, const Matrix3& b);
/// Bradford chromatic adaptation from `from` to `to` (white points as XYZ).
Matrix3 bradford(const std::array<double, 3>& from, const std::array<double, 3>& to);

}  // namespace whitted
