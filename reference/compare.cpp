// SPDX-License-Identifier: MIT
// Pixel comparison of two linear images, and the image reading it needs. The figures are
// accumulated in double: a million float differences of ~1e-5 summed in float would lose the
// very digits the check is about.

#include "reference/compare.h"

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace whitted::reference {

std::string format_codes(double value) {
    char text[32];
    std::snprintf(text, sizeof text, "%.1f", value * 65535.0);
    return text;
}

std::string format_percent(const ImageComparison& c) {
    if (c.pixels_within == c.pixels) return "100.000%";
    char text[32];
    std::snprintf(text, sizeof text, "%.3f%%", std::floor(c.fraction_within() * 100000.0) / 1000.0);
    return text;
}

ImageComparison compare_images(const Image& ours, const Image& theirs, double tolerance) {
    if (ours.width != theirs.width || ours.height != theirs.height)
        throw std::runtime_error("cannot compare a " + std::to_string(ours.width) + "x" + std::to_string(ours.height) +
                                 " image with a " + std::to_string(theirs.width) + "x" + std::to_string(theirs.height) +
                                 " one");
    ImageComparison c;
    c.width = ours.width;
    c.height = ours.height;
    c.tolerance = tolerance;
    c.pixels = size_t(ours.width) * size_t(ours.height);
    double sum = 0, sum_squares = 0;
    bool have_worst = false;
    for (int y = 0; y < ours.height; ++y) {
        for (int x = 0; x < ours.width; ++x) {
            const float* a = ours.pixel(x, y);
            const float* b = theirs.pixel(x, y);
            bool within = true;
            double pixel_max = 0;
            for (int ch = 0; ch < 3; ++ch) {
                const double d = std::abs(double(a[ch]) - double(b[ch]));
                // NaN must count as a failure, and `d > tolerance` is false for NaN.
                const double error = std::isnan(d) ? std::numeric_limits<double>::infinity() : d;
                sum += error;
                sum_squares += error * error;
                within &= error <= tolerance;
                pixel_max = std::max(pixel_max, error);
            }
            if (within) ++c.pixels_within;
            // The first pixel (in reading order) with the largest error, so reports are stable.
            if (!have_worst || pixel_max > c.max_error) {
                have_worst = true;
                c.max_error = pixel_max;
                c.worst_x = x;
                c.worst_y = y;
                for (int ch = 0; ch < 3; ++ch) c.worst_ours[ch] = a[ch], c.worst_theirs[ch] = b[ch];
            }
        }
    }
    const double values = double(c.pixels) * 3.0;
    if (values > 0) {
        c.mean_error = sum / values;
        c.rms_error = std::sqrt(sum_squares / values);
    }
    c.psnr = c.rms_error > 0 ? 20.0 * std::log10(1.0 / c.rms_error) : std::numeric_limits<double>::infinity();
    return c;
}

Image read_linear_image(const std::string& path) {
    // ImageInput hands back the stored values and never converts colour spaces: a 16-bit code c
    // arrives as exactly c/65535 whatever the gAMA/sRGB chunks say (only the metadata
    // "oiio:ColorSpace" reflects them). Alpha is left unassociated in case a file has one.
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    auto in = OIIO::ImageInput::open(path, &config);
    if (!in) throw std::runtime_error("cannot read '" + path + "': " + OIIO::geterror());
    const OIIO::ImageSpec& spec = in->spec();
    if (spec.nchannels < 1) throw std::runtime_error("'" + path + "' has no channels");
    if (spec.width <= 0 || spec.height <= 0) throw std::runtime_error("'" + path + "' is empty");
    std::vector<float> all(size_t(spec.width) * size_t(spec.height) * size_t(spec.nchannels));
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, all.data()))
        throw std::runtime_error("cannot read '" + path + "': " + in->geterror());
    in->close();

    Image image;
    image.width = spec.width;
    image.height = spec.height;
    image.rgb.resize(size_t(spec.width) * size_t(spec.height) * 3);
    const size_t pixels = size_t(spec.width) * size_t(spec.height);
    for (size_t i = 0; i < pixels; ++i) {
        for (int ch = 0; ch < 3; ++ch) {
            // A grey file repeats its one channel; anything past RGB (alpha) is dropped.
            const int source = spec.nchannels >= 3 ? ch : 0;
            image.rgb[3 * i + ch] = all[i * size_t(spec.nchannels) + size_t(source)];
        }
    }
    return image;
}

Image downsample_box(const Image& image, int n) {
    if (n <= 1) return image;
    if (image.width % n != 0 || image.height % n != 0)
        throw std::runtime_error("cannot average " + std::to_string(n) + "x" + std::to_string(n) + " blocks of a " +
                                 std::to_string(image.width) + "x" + std::to_string(image.height) + " image");
    Image out;
    out.width = image.width / n;
    out.height = image.height / n;
    out.rgb.resize(size_t(out.width) * size_t(out.height) * 3);
    // Summed in double in the same row-major order as Whitted's own sample loop.
    const double weight = 1.0 / double(n * n);
    for (int y = 0; y < out.height; ++y) {
        for (int x = 0; x < out.width; ++x) {
            double sum[3] = {0, 0, 0};
            for (int b = 0; b < n; ++b)
                for (int a = 0; a < n; ++a) {
                    const float* p = image.pixel(x * n + a, y * n + b);
                    for (int ch = 0; ch < 3; ++ch) sum[ch] += double(p[ch]);
                }
            float* o = &out.rgb[3 * (size_t(y) * size_t(out.width) + size_t(x))];
            for (int ch = 0; ch < 3; ++ch) o[ch] = float(sum[ch] * weight);
        }
    }
    return out;
}

}  // namespace whitted::reference
