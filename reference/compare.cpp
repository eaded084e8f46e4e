// SPDX-License-Identifier: MIT
// Pixel comparison of two linear images, the pass rule, and the image reading it needs. The
// figures are accumulated in double: a million float differences of ~1e-5 summed in float would
// lose the very digits the check is about.

#include "reference/compare.h"

#include "scene/description.h"

#include <OpenImageIO/imageio.h>
#include <fmt/format.h>
#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <stdexcept>

namespace whitted::reference {
namespace {

std::string file_kind(mode_t mode) {
    if (S_ISDIR(mode)) return "a directory";
    if (S_ISCHR(mode)) return "a character device";
    if (S_ISBLK(mode)) return "a block device";
    if (S_ISFIFO(mode)) return "a fifo";
    if (S_ISSOCK(mode)) return "a socket";
    return "not a regular file";
}

uint32_t big_endian_32(const unsigned char* b) {
    return uint32_t(b[0]) << 24 | uint32_t(b[1]) << 16 | uint32_t(b[2]) << 8 | uint32_t(b[3]);
}

/// A PNG is a signature and chunks (length, type, data, CRC) ending with IEND. OpenImageIO
/// reads a PNG cut short without an error (the missing rows come back as zeros, which a
/// comparison would then judge), so the chunk structure is walked first: every chunk must fit
/// in the file and IEND must be there. Other formats are left to their readers.
void check_png_complete(const std::string& path, uint64_t size) {
    static const unsigned char signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    std::ifstream in(path, std::ios::binary);
    unsigned char head[8];
    if (!in.read(reinterpret_cast<char*>(head), 8) || std::memcmp(head, signature, 8) != 0) return;
    uint64_t offset = 8;
    while (offset + 8 <= size) {
        in.seekg(std::streamoff(offset));
        if (!in.read(reinterpret_cast<char*>(head), 8)) break;
        const uint64_t length = big_endian_32(head);
        if (length > 0x7fffffffu) throw std::runtime_error("cannot read '" + path + "': a PNG chunk is corrupt");
        const uint64_t next = offset + 12 + length;  // length, type, data, CRC
        if (next > size) break;
        if (std::memcmp(head + 4, "IEND", 4) == 0) return;
        offset = next;
    }
    throw std::runtime_error("cannot read '" + path + "': the PNG file is truncated (it ends before its IEND chunk)");
}

/// Where a pixel goes among the worst kept so far: after every pixel with an error at least as
/// large, so that equal errors keep reading order.
void keep_if_worst(std::vector<PixelError>& worst, size_t count, const PixelError& pixel) {
    if (count == 0 || (worst.size() == count && !(pixel.error > worst.back().error))) return;
    const auto at = std::upper_bound(worst.begin(), worst.end(), pixel.error,
                                     [](double error, const PixelError& kept) { return error > kept.error; });
    worst.insert(at, pixel);
    if (worst.size() > count) worst.pop_back();
}

}  // namespace

std::string format_codes(double value) {
    if (std::isinf(value)) return "inf";
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

std::vector<std::string> failed_rules(const ImageComparison& c, const PassRule& rule, const std::string& ours,
                                      const std::string& theirs) {
    std::vector<std::string> failures;
    if (c.fraction_within() < rule.required_fraction)
        failures.push_back(fmt::format("share ({} within {:g}/65535 < {:g}%)", format_percent(c),
                                       rule.tolerance * 65535, rule.required_fraction * 100));
    // NaN compares false with everything, so the cap is checked as "not within" rather than
    // "above": a NaN error can never pass it.
    if (!(c.max_error <= rule.max_error))
        failures.push_back(fmt::format("cap (max {} codes > {:g})", format_codes(c.max_error), rule.max_error * 65535));
    if (c.nonfinite_ours + c.nonfinite_theirs > 0)
        failures.push_back(fmt::format("finite ({} NaN/Inf value(s) in {}, {} in {})", c.nonfinite_ours, ours,
                                       c.nonfinite_theirs, theirs));
    return failures;
}

std::vector<std::string> shape_mismatches(const ImageShape& a, const ImageShape& b, ChannelRule channels) {
    std::vector<std::string> failures;
    if (a.width != b.width || a.height != b.height)
        failures.push_back(fmt::format("size ({}x{} vs {}x{})", a.width, a.height, b.width, b.height));
    if (channels == ChannelRule::exact && a.channels != b.channels)
        failures.push_back(fmt::format("channels ({} vs {})", a.channels, b.channels));
    // What is compared is the colour, the first three channels (one, for a grey image): an RGBA
    // PNG or an EXR with render layers compares with a plain RGB image.
    else if ((a.channels >= 3) != (b.channels >= 3))
        failures.push_back(fmt::format("channels ({} vs {}: {} against {})", a.channels, b.channels,
                                       a.channels >= 3 ? "colour" : "grey", b.channels >= 3 ? "colour" : "grey"));
    return failures;
}

std::string verdict_figures(const ImageComparison& c, const PassRule& rule) {
    return fmt::format("{} of pixels within {:g}/65535 ({:g}% required), max {} codes (cap {:g})", format_percent(c),
                       rule.tolerance * 65535, rule.required_fraction * 100, format_codes(c.max_error),
                       rule.max_error * 65535);
}

std::string verdict_text(const std::string& subject, const std::string& figures,
                         const std::vector<std::string>& failures) {
    std::string text = (failures.empty() ? "PASS " : "FAIL ") + subject + ":";
    if (!figures.empty()) text += " " + figures;
    if (!failures.empty()) {
        text += figures.empty() ? " failed: " : "; failed: ";
        for (size_t i = 0; i < failures.size(); ++i) text += (i ? ", " : "") + failures[i];
    }
    return text;
}

ImageComparison compare_images(const Image& ours, const Image& theirs, double tolerance, size_t worst_count) {
    if (ours.width != theirs.width || ours.height != theirs.height)
        throw std::invalid_argument("cannot compare a " + std::to_string(ours.width) + "x" +
                                    std::to_string(ours.height) + " image with a " + std::to_string(theirs.width) +
                                    "x" + std::to_string(theirs.height) + " one");
    ImageComparison c;
    c.width = ours.width;
    c.height = ours.height;
    c.tolerance = tolerance;
    c.pixels = size_t(ours.width) * size_t(ours.height);
    double sum = 0, sum_squares = 0;
    for (int y = 0; y < ours.height; ++y) {
        for (int x = 0; x < ours.width; ++x) {
            const float* a = ours.pixel(x, y);
            const float* b = theirs.pixel(x, y);
            bool within = true;
            double pixel_max = 0;
            for (int ch = 0; ch < 3; ++ch) {
                c.nonfinite_ours += !std::isfinite(a[ch]);
                c.nonfinite_theirs += !std::isfinite(b[ch]);
                const double d = std::abs(double(a[ch]) - double(b[ch]));
                // A NaN or infinite value is as wrong as a value can be (and `d > tolerance`
                // is false for NaN); inf − inf, equal as they look, is NaN too.
                const double error = std::isfinite(d) ? d : std::numeric_limits<double>::infinity();
                sum += error;
                sum_squares += error * error;
                within &= error <= tolerance;
                pixel_max = std::max(pixel_max, error);
            }
            if (within) ++c.pixels_within;
            c.max_error = std::max(c.max_error, pixel_max);
            if (worst_count > 0 && (c.worst.size() < worst_count || pixel_max > c.worst.back().error)) {
                PixelError pixel;
                pixel.x = x;
                pixel.y = y;
                pixel.error = pixel_max;
                for (int ch = 0; ch < 3; ++ch) pixel.ours[ch] = a[ch], pixel.theirs[ch] = b[ch];
                keep_if_worst(c.worst, worst_count, pixel);
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

ImageShape read_image_shape(const std::string& path) {
    struct stat status {};
    if (::stat(path.c_str(), &status) != 0)
        throw std::runtime_error("cannot read '" + path + "': " + std::strerror(errno));
    if (!S_ISREG(status.st_mode))
        throw std::runtime_error("cannot read '" + path + "': it is " + file_kind(status.st_mode) +
                                 ", not an image file");
    check_png_complete(path, uint64_t(status.st_size));
    auto in = OIIO::ImageInput::open(path);
    if (!in) throw std::runtime_error("cannot read '" + path + "': " + OIIO::geterror());
    const OIIO::ImageSpec& spec = in->spec();
    ImageShape shape{spec.width, spec.height, spec.nchannels};
    in->close();
    if (shape.channels < 1) throw std::runtime_error("'" + path + "' has no channels");
    if (shape.width <= 0 || shape.height <= 0) throw std::runtime_error("'" + path + "' is empty");
    // The header's size is checked before a single pixel is allocated: a PNG of a few bytes
    // can claim 65535x65535 (17 GB as float RGB).
    if (shape.width > limits::max_image_side || shape.height > limits::max_image_side ||
        int64_t(shape.width) * int64_t(shape.height) > limits::max_image_pixels)
        throw std::runtime_error(fmt::format("'{}' is {}x{}; the limit is {} per side and {} pixels", path, shape.width,
                                             shape.height, limits::max_image_side, limits::max_image_pixels));
    return shape;
}

Image read_linear_image(const std::string& path) {
    read_image_shape(path);
    // ImageInput hands back the stored values and never converts colour spaces: a 16-bit code c
    // arrives as exactly c/65535 whatever the gAMA/sRGB chunks say (only the metadata
    // "oiio:ColorSpace" reflects them). Alpha is left unassociated in case a file has one.
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    auto in = OIIO::ImageInput::open(path, &config);
    if (!in) throw std::runtime_error("cannot read '" + path + "': " + OIIO::geterror());
    const OIIO::ImageSpec& spec = in->spec();
    // Only the channels used are read, so memory stays at 3 floats per pixel whatever the file
    // holds beyond RGB.
    const int read_channels = std::min(spec.nchannels, 3);
    std::vector<float> all(size_t(spec.width) * size_t(spec.height) * size_t(read_channels));
    // A reader may return true and still have recorded an error (a damaged file read as far as
    // it went): either way the file is unreadable.
    if (!in->read_image(0, 0, 0, read_channels, OIIO::TypeDesc::FLOAT, all.data()) || in->has_error())
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
            const int source = read_channels >= 3 ? ch : 0;
            image.rgb[3 * i + ch] = all[i * size_t(read_channels) + size_t(source)];
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
