// SPDX-License-Identifier: MIT
#pragma once

#include "whitted/render/renderer.h"

#include <string>

namespace whitted::reference {

/// Per-channel absolute differences between two images of the same size.
struct ImageComparison {
    int width = 0, height = 0;
    double tolerance = 0;   ///< per channel, absolute (linear units)
    double max_error = 0;   ///< largest |ours − theirs| over all channels
    double mean_error = 0;  ///< mean over all channels
    double rms_error = 0;
    double psnr = 0;  ///< dB, peak 1.0; infinity when identical
    size_t pixels = 0;
    size_t pixels_within = 0;  ///< pixels whose every channel is within tolerance
    double fraction_within() const { return pixels ? double(pixels_within) / double(pixels) : 1.0; }
    int worst_x = 0, worst_y = 0;
    float worst_ours[3] = {0, 0, 0}, worst_theirs[3] = {0, 0, 0};
};

/// The share of pixels within tolerance as a percentage with three decimals, rounded down so
/// that a failing share never reads "100.000%".
std::string format_percent(const ImageComparison& comparison);

/// A linear value in 16-bit codes (× 65535) with one decimal, e.g. "1.5".
std::string format_codes(double value);

ImageComparison compare_images(const Image& ours, const Image& theirs, double tolerance);

/// Reads any image OpenImageIO can read as linear float RGB (no colour conversion: PNGs that
/// POV-Ray wrote with File_Gamma=1.0 are linear already). Throws std::runtime_error.
Image read_linear_image(const std::string& path);

/// Averages n×n blocks (the box filter of image.samples = n).
Image downsample_box(const Image& image, int n);

}  // namespace whitted::reference
