// SPDX-License-Identifier: MIT
#pragma once

#include "whitted/image.h"

#include <string>
#include <vector>

namespace whitted::reference {

/// One pixel of a comparison, with both images' values.
struct PixelError {
    int x = 0, y = 0;
    double error = 0;  ///< largest |ours − theirs| over R, G, B; infinity when a value is NaN/Inf
    float ours[3] = {0, 0, 0}, theirs[3] = {0, 0, 0};
};

/// Per-channel absolute differences between two images of the same size.
struct ImageComparison {
    int width = 0, height = 0;
    double tolerance = 0;   ///< per channel, absolute (linear units)
    double max_error = 0;   ///< largest |ours − theirs| over all channels; infinity with any NaN/Inf
    double mean_error = 0;  ///< mean over all channels
    double rms_error = 0;
    double psnr = 0;  ///< dB, peak 1.0; infinity when identical
    size_t pixels = 0;
    size_t pixels_within = 0;  ///< pixels whose every channel is within tolerance
    double fraction_within() const { return pixels ? double(pixels_within) / double(pixels) : 1.0; }
    /// NaN or ±Inf values (channels, not pixels) in each image: a renderer that produces them
    /// is broken wherever they are, however few.
    size_t nonfinite_ours = 0, nonfinite_theirs = 0;
    /// The worst pixels, largest error first; equal errors in reading order (so reports are
    /// stable). At most the `worst_count` given to compare_images; empty only for empty images.
    std::vector<PixelError> worst;
};

/// The pass rule of `whitted check` and `whitted compare` (docs/validation.md): all of
///  * share: at least `required_fraction` of the pixels have every channel within `tolerance`;
///  * cap: no channel of any pixel is off by more than `max_error`;
///  * finite: no value of either image is NaN or ±Inf;
///  * size and channels: both images have the same width, height and channel count.
/// The share rule alone let a few pixels be arbitrarily wrong; the cap and the finite rule
/// leave them no hiding place.
struct PassRule {
    double tolerance = 2.0 / 65535.0;   ///< per channel, absolute, linear
    double required_fraction = 0.999;   ///< share of pixels that must be within tolerance
    double max_error = 64.0 / 65535.0;  ///< per channel, absolute, linear: the hard cap
};

/// What an image file holds, read from its header alone.
struct ImageShape {
    int width = 0, height = 0, channels = 0;
};

/// The rules a comparison broke, each as "NAME (details)" with NAME one of share, cap, finite;
/// empty when it passed. `ours`/`theirs` name the two images in the details.
std::vector<std::string> failed_rules(const ImageComparison& comparison, const PassRule& rule,
                                      const std::string& ours = "the first image",
                                      const std::string& theirs = "the second image");

/// How the channel counts must agree: `colour`, as `whitted compare` reads images (the first three
/// channels, or one for grey: an RGBA PNG or an EXR with render layers is colour like RGB);
/// `exact`, as `whitted check` wants POV-Ray's output (RGB, no alpha, as its .ini asks).
enum class ChannelRule { colour, exact };
/// The size and channels rules: "size (96x72 vs 95x72)", "channels (3 vs 1: colour against
/// grey)", or empty.
std::vector<std::string> shape_mismatches(const ImageShape& ours, const ImageShape& theirs,
                                          ChannelRule channels = ChannelRule::colour);

/// The figures of a verdict line: "99.913% of pixels within 2/65535 (99.9% required), max
/// 1000.0 codes (cap 64)".
std::string verdict_figures(const ImageComparison& comparison, const PassRule& rule);

/// "PASS SUBJECT: FIGURES", or "FAIL SUBJECT: FIGURES; failed: RULE, RULE" (FIGURES may be
/// empty when the images could not be compared at all, e.g. sizes differ).
std::string verdict_text(const std::string& subject, const std::string& figures,
                         const std::vector<std::string>& failures);

/// The share of pixels within tolerance as a percentage with three decimals, rounded down so
/// that a failing share never reads "100.000%".
std::string format_percent(const ImageComparison& comparison);

/// A linear value in 16-bit codes (× 65535) with one decimal, e.g. "1.5" ("inf" for infinity).
std::string format_codes(double value);

/// Compares two images of the same size (throws std::invalid_argument otherwise), keeping the
/// `worst_count` worst pixels.
ImageComparison compare_images(const Image& ours, const Image& theirs, double tolerance, size_t worst_count = 10);

/// Checks that `path` can be read as an image before anything is read: a regular file (not a
/// directory, device or fifo, which would hang or never end), in a format OpenImageIO knows,
/// at most limits::max_image_side per side and limits::max_image_pixels pixels, and for a PNG, every chunk up to IEND
/// present (a truncated PNG is refused, not read with missing rows). Throws std::runtime_error saying which.
ImageShape read_image_shape(const std::string& path);

/// Reads any image read_image_shape accepts as linear float RGB (no colour conversion: PNGs
/// that POV-Ray wrote with File_Gamma=1.0 are linear already); a grey image repeats its one
/// channel and channels past RGB are dropped (the channels rule sees the file's own count).
/// Throws std::runtime_error.
Image read_linear_image(const std::string& path);

/// Averages n×n blocks (the box filter of image.samples = n).
Image downsample_box(const Image& image, int n);

}  // namespace whitted::reference
