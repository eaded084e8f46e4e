// SPDX-License-Identifier: MIT
// PNG through libpng directly rather than the OpenImageIO plug-in: loading OpenImageIO (about
// 250 shared libraries) took 0.17 s, and its writer compressed at zlib level 6; a 1280x960
// PNG took 0.40-0.47 s to write that way (docs/performance.md).

#include "whitted/output/png_file.h"

#include <png.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <stdexcept>

namespace whitted {
namespace {

/// Everything libpng needs, prepared before it runs: libpng reports errors by longjmp, which
/// must not jump over C++ objects with destructors.
struct PngJob {
    std::FILE* file;
    int width, height, bits;
    const unsigned char* rows;  ///< big-endian samples, `row_bytes` per row
    size_t row_bytes;
    png_text* texts;
    int text_count;
    char error[256];
};

extern "C" void on_png_error(png_structp png, png_const_charp message) {
    auto* job = static_cast<PngJob*>(png_get_error_ptr(png));
    std::snprintf(job->error, sizeof job->error, "%s", message);
    png_longjmp(png, 1);
}

extern "C" void on_png_warning(png_structp, png_const_charp) {}  // nothing a user could act on

bool run(PngJob& job) {
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &job, on_png_error, on_png_warning);
    png_infop info = png ? png_create_info_struct(png) : nullptr;
    if (!info) {
        if (png) png_destroy_write_struct(&png, nullptr);
        std::snprintf(job.error, sizeof job.error, "out of memory");
        return false;
    }
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        return false;
    }
    png_init_io(png, job.file);
    png_set_IHDR(png, info, png_uint_32(job.width), png_uint_32(job.height), job.bits, PNG_COLOR_TYPE_RGB,
                 PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    if (job.text_count > 0) png_set_text(png, info, job.texts, job.text_count);
    // Speed over size: zlib level 1 with the "up" filter. Measured on the 100-sphere anchor at
    // 1280x960, 8 bits: see docs/performance.md for the sizes and times of the choices.
    png_set_compression_level(png, 1);
    png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_UP);
    png_write_info(png, info);
    for (int y = 0; y < job.height; ++y) png_write_row(png, job.rows + size_t(y) * job.row_bytes);
    png_write_end(png, info);
    png_destroy_write_struct(&png, &info);
    return true;
}

bool is_ascii(const std::string& text) {
    return std::all_of(text.begin(), text.end(), [](char c) { return static_cast<unsigned char>(c) < 0x80; });
}

}  // namespace

void write_png(const std::string& path, const Image& linear, const DisplayTransform& display, int bits,
               const std::vector<std::pair<std::string, std::string>>& metadata) {
    if (bits != 8 && bits != 16) throw std::invalid_argument("PNG files hold 8 or 16 bits per channel");
    const int width = linear.width, height = linear.height;
    const size_t samples_per_row = 3 * size_t(width);
    const size_t row_bytes = samples_per_row * size_t(bits / 8);
    std::vector<unsigned char> rows(row_bytes * size_t(height));
    // In double, the product and the half are exact, so every value rounds to its nearest code
    // (in float, 0.7f * 255 + 0.5f came out 179, not 178).
    const double scale = bits == 16 ? 65535.0 : 255.0;
    // Bands of rows on all cores (OCIO's CPU processor may be applied from several threads at
    // once), each through a small buffer rather than a display-referred copy of the whole image.
    constexpr int band = 8;
    tbb::parallel_for(0, (height + band - 1) / band, [&](int b) {
        const int first = b * band, count = std::min(band, height - first);
        std::vector<float> values(linear.rgb.begin() + std::ptrdiff_t(samples_per_row * size_t(first)),
                                  linear.rgb.begin() + std::ptrdiff_t(samples_per_row * size_t(first + count)));
        display.apply(values.data(), size_t(width) * size_t(count));
        unsigned char* out = rows.data() + row_bytes * size_t(first);
        for (size_t i = 0; i < values.size(); ++i) {
            const float v = values[i] > 0 ? std::min(values[i], 1.0f) : 0.0f;  // NaN fails `> 0`
            const auto code = static_cast<uint32_t>(double(v) * scale + 0.5);
            if (bits == 16) {  // PNG samples are big-endian
                out[2 * i] = static_cast<unsigned char>(code >> 8);
                out[2 * i + 1] = static_cast<unsigned char>(code & 0xFF);
            } else {
                out[i] = static_cast<unsigned char>(code);
            }
        }
    });
    // Text chunks: tEXt holds Latin-1, so anything else (a UTF-8 scene path) goes in iTXt.
    std::vector<png_text> texts(metadata.size());
    for (size_t i = 0; i < metadata.size(); ++i) {
        std::memset(&texts[i], 0, sizeof texts[i]);
        texts[i].key = const_cast<char*>(metadata[i].first.c_str());
        texts[i].text = const_cast<char*>(metadata[i].second.c_str());
        texts[i].text_length = metadata[i].second.size();
        texts[i].compression = is_ascii(metadata[i].second) ? PNG_TEXT_COMPRESSION_NONE : PNG_ITXT_COMPRESSION_NONE;
    }
    std::FILE* file = std::fopen(path.c_str(), "wb");
    if (!file) throw std::runtime_error("cannot open '" + path + "' for writing: " + std::strerror(errno));
    PngJob job{file, width, height, bits, rows.data(), row_bytes, texts.data(), int(texts.size()), {}};
    const bool wrote = run(job);
    const bool closed = std::fclose(file) == 0;
    if (!wrote) throw std::runtime_error(std::string("libpng: ") + job.error);
    if (!closed) throw std::runtime_error("cannot finish '" + path + "': " + std::strerror(errno));
}

}  // namespace whitted
