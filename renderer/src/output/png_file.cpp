// SPDX-License-Identifier: MIT
// PNG through libpng directly rather than the OpenImageIO plug-in: loading OpenImageIO (about
// 250 shared libraries) took 0.17 s, and its writer compressed at zlib level 6; a 1280x960
// PNG took 0.40-0.47 s to write that way (docs/performance.md). The image data is filtered and
// deflated here, on all cores (compress_rows); libpng writes the chunks around it.

#include "output/png_file.h"

#include "output/chromaticities.h"

#include <png.h>
#include <tbb/parallel_for.h>
#include <zlib.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <stdexcept>

namespace whitted {
namespace {

/// Everything libpng needs, prepared before it runs: libpng reports errors by longjmp, which
/// must not jump over C++ objects with destructors.
struct PngJob {
    std::FILE* file;
    int width, height, bits;
    const unsigned char* idat;  ///< the zlib stream of the filtered rows (compress_rows)
    size_t idat_size;
    png_text* texts;
    int text_count;
    DisplayEncoding encoding;
    char error[256];
};

extern "C" void on_png_error(png_structp png, png_const_charp message) {
    const int reason = errno;  // libpng's "Write Error" does not say why (a full disk, a quota)
    auto* job = static_cast<PngJob*>(png_get_error_ptr(png));
    if (reason)
        std::snprintf(job->error, sizeof job->error, "%s (%s)", message, std::strerror(reason));
    else
        std::snprintf(job->error, sizeof job->error, "%s", message);
    png_longjmp(png, 1);
}

extern "C" void on_png_warning(png_structp, png_const_charp) {}  // nothing a user could act on

/// sRGB, gAMA and cHRM, what readers without cICP go by: an sRGB chunk (with the gAMA and
/// cHRM the PNG specification asks to go with it) for the sRGB curve on Rec.709 primaries,
/// else gAMA with the curve's exponent (1.0 for linear values) and cHRM with the primaries.
void set_colour_chunks(png_structp png, png_infop info, const DisplayEncoding& encoding) {
    if (!encoding.known()) return;
    using T = DisplayEncoding::Transfer;
    if (encoding.transfer == T::srgb && encoding.primaries == DisplayEncoding::Primaries::rec709) {
        png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
        return;
    }
    // gAMA stores the encoding exponent (1/decoding gamma) times 100000; the sRGB curve on
    // other primaries is written as its usual approximation, 1/2.2.
    const double decoding_gamma = encoding.transfer == T::linear ? 1.0 : encoding.transfer == T::gamma24 ? 2.4 : 2.2;
    png_set_gAMA_fixed(png, info, png_fixed_point(std::lround(100000.0 / decoding_gamma)));
    const Chromaticities& c = encoding.primaries == DisplayEncoding::Primaries::display_p3 ? display_p3_chromaticities
                                                                                           : rec709_chromaticities;
    png_set_cHRM(png, info, c.white[0], c.white[1], c.red[0], c.red[1], c.green[0], c.green[1], c.blue[0], c.blue[1]);
}

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
    set_colour_chunks(png, info, job.encoding);
    png_write_info(png, info);
    // cICP (PNG third edition; libpng 1.6.39 has no setter, so written as a chunk of our own,
    // which must come before IDAT): the exact code points, which readers that know it prefer.
    if (job.encoding.known()) {
        using T = DisplayEncoding::Transfer;
        const T t = job.encoding.transfer;
        // ITU-T H.273: primaries 1 = BT.709, 12 = P3-D65; transfer 13 = sRGB, 8 = linear,
        // 4 = gamma 2.2, 1 = BT.709 (shown by a BT.1886 display); matrix 0 = RGB; full range.
        const png_byte cicp[4] = {png_byte(job.encoding.primaries == DisplayEncoding::Primaries::display_p3 ? 12 : 1),
                                  png_byte(t == T::srgb      ? 13
                                           : t == T::linear  ? 8
                                           : t == T::gamma22 ? 4
                                                             : 1),
                                  0, 1};
        png_write_chunk(png, reinterpret_cast<png_const_bytep>("cICP"), cicp, sizeof cicp);
    }
    // The image data was compressed beforehand (compress_rows); libpng frames it.
    constexpr size_t most_per_chunk = size_t(1) << 24;
    for (size_t at = 0; at < job.idat_size; at += most_per_chunk)
        png_write_chunk(png, reinterpret_cast<png_const_bytep>("IDAT"), job.idat + at,
                        std::min(most_per_chunk, job.idat_size - at));
    png_write_chunk(png, reinterpret_cast<png_const_bytep>("IEND"), nullptr, 0);
    png_destroy_write_struct(&png, &info);
    return true;
}

/// Rows of PNG samples from the linear image: the display transform, then each value rounded to
/// its nearest code (8 or 16 bits, big-endian).
class Samples {
public:
    /// Rows go through the display transform this many at a time, from a multiple of it, so that
    /// every row is transformed in the same company whichever band asks for it.
    static constexpr int chunk_rows = 8;

    Samples(const Image& linear, const DisplayTransform& display, int bits)
        : m_linear(linear), m_display(display), m_bits(bits), m_row_samples(3 * size_t(linear.width)) {}
    int height() const { return m_linear.height; }
    int bits() const { return m_bits; }
    size_t row_samples() const { return m_row_samples; }
    size_t row_bytes() const { return m_row_samples * size_t(m_bits / 8); }

    /// Rows [first, first + count) to out, `stride` bytes apart; `first` a multiple of
    /// chunk_rows. `values`: room for chunk_rows rows of floats.
    void rows(int first, int count, unsigned char* out, size_t stride, float* values) const {
        // In double, the product and the half are exact, so every value rounds to its nearest
        // code (in float, 0.7f * 255 + 0.5f came out 179, not 178).
        const double scale = m_bits == 16 ? 65535.0 : 255.0;
        for (int chunk = first; chunk < first + count; chunk += chunk_rows) {
            const int rows = std::min(chunk_rows, m_linear.height - chunk);
            const size_t samples = m_row_samples * size_t(rows);
            std::copy_n(m_linear.rgb.begin() + std::ptrdiff_t(m_row_samples * size_t(chunk)), samples, values);
            m_display.apply(values, size_t(m_linear.width) * size_t(rows));
            for (int r = 0; r < std::min(rows, first + count - chunk); ++r) {
                const float* from = values + m_row_samples * size_t(r);
                unsigned char* to = out + stride * size_t(chunk - first + r);
                for (size_t i = 0; i < m_row_samples; ++i) {
                    const float v = from[i] > 0 ? std::min(from[i], 1.0f) : 0.0f;  // NaN fails `> 0`
                    const auto code = static_cast<uint32_t>(double(v) * scale + 0.5);
                    if (m_bits == 16) {
                        to[2 * i] = static_cast<unsigned char>(code >> 8);
                        to[2 * i + 1] = static_cast<unsigned char>(code & 0xFF);
                    } else {
                        to[i] = static_cast<unsigned char>(code);
                    }
                }
            }
        }
    }
    /// Row `y` alone (the row above a band), in `room` (chunk_rows rows), where it is returned;
    /// the rows of its chunk go through the display transform with it.
    const unsigned char* row(int y, unsigned char* room, float* values) const {
        const int first = y - y % chunk_rows;
        rows(first, y - first + 1, room, row_bytes(), values);
        return room + row_bytes() * size_t(y - first);
    }

private:
    const Image& m_linear;
    const DisplayTransform& m_display;
    int m_bits;
    size_t m_row_samples;
};

/// The zlib stream of a PNG's image data: each row as the "up" filter (the difference from the
/// row above) behind its filter-type byte, deflated at level 1. Bands of rows are made from the
/// linear image (Samples), filtered and deflated on all cores, each band as its own run of
/// deflate blocks ended on a byte boundary (Z_SYNC_FLUSH), and joined, the way pigz does it;
/// their Adler-32 sums combine into the stream's. zlib's level 6 took 0.13 s for a 1280x960
/// 8-bit image and level 1 on one core 0.022 s (8 bits) or about 0.1 s (16 bits); see
/// docs/performance.md. No image-sized buffer of samples is made: a band's rows are written
/// where their filtered form goes, and filtered in place from the bottom up.
///
/// Its buffers are not zeroed first: every byte of a band's filtered rows is written, and of its
/// deflate output only what deflate wrote is kept (a zeroed output buffer, deflate's bound, was
/// mostly never written, and each of its fresh pages is a page fault, docs/performance.md).
std::vector<unsigned char> compress_rows(const Samples& samples) {
    const int height = samples.height(), bits = samples.bits();
    // 16-bit rows have noisy low bytes where deflate's string matching rarely pays: run-length
    // matching only was twice as fast on the spheres anchor (0.037 s against 0.072 s on one
    // core) for 16 % more bytes. On 8-bit rows it was no faster.
    const int strategy = bits == 16 ? Z_RLE : Z_DEFAULT_STRATEGY;
    constexpr int band = 64;
    static_assert(band % Samples::chunk_rows == 0);
    const size_t row_bytes = samples.row_bytes();
    const int bands = (height + band - 1) / band;
    const auto band_count = static_cast<size_t>(bands);
    struct Part {
        std::unique_ptr<unsigned char[]> bytes;
        size_t size = 0;
    };
    std::vector<Part> parts(band_count);
    std::vector<uLong> sums(band_count);
    std::vector<size_t> lengths(band_count);
    std::atomic<bool> failed{false};
    const auto make_band = [&](int b) {
        const int first = b * band, count = std::min(band, height - first);
        const size_t stride = row_bytes + 1, filtered_size = size_t(count) * stride;
        const auto filtered = std::make_unique_for_overwrite<unsigned char[]>(filtered_size);
        const auto values = std::make_unique_for_overwrite<float[]>(samples.row_samples() * Samples::chunk_rows);
        // The band's rows, each behind room for its filter-type byte; then each row less the one
        // above it, from the last row up, so that the row above is still whole when it is used.
        samples.rows(first, count, filtered.get() + 1, stride, values.get());
        for (int y = count - 1; y > 0; --y) {
            unsigned char* out = filtered.get() + size_t(y) * stride;
            const unsigned char* above = out - stride;
            out[0] = 2;  // PNG filter type 2, "up"
            for (size_t i = 1; i <= row_bytes; ++i) out[i] = static_cast<unsigned char>(out[i] - above[i]);
        }
        filtered[0] = 2;
        if (first > 0) {
            const auto room = std::make_unique_for_overwrite<unsigned char[]>(row_bytes * Samples::chunk_rows);
            const unsigned char* above = samples.row(first - 1, room.get(), values.get());
            for (size_t i = 0; i < row_bytes; ++i)
                filtered[1 + i] = static_cast<unsigned char>(filtered[1 + i] - above[i]);
        }
        sums[size_t(b)] = adler32(adler32(0, nullptr, 0), filtered.get(), uInt(filtered_size));
        lengths[size_t(b)] = filtered_size;
        z_stream stream{};
        if (deflateInit2(&stream, 1, Z_DEFLATED, -15, 8, strategy) != Z_OK) {
            failed = true;
            return;
        }
        Part& part = parts[size_t(b)];
        const size_t bound = deflateBound(&stream, uLong(filtered_size)) + 16;
        part.bytes = std::make_unique_for_overwrite<unsigned char[]>(bound);
        stream.next_in = filtered.get();
        stream.avail_in = uInt(filtered_size);
        stream.next_out = part.bytes.get();
        stream.avail_out = uInt(bound);
        const bool last = b == bands - 1;
        const int status = deflate(&stream, last ? Z_FINISH : Z_SYNC_FLUSH);
        if (status != (last ? Z_STREAM_END : Z_OK) || stream.avail_in != 0) failed = true;
        part.size = bound - stream.avail_out;
        deflateEnd(&stream);
    };
    // One band (an image of at most 64 rows) is made on this thread: starting TBB would cost
    // more than the band (render/renderer.h, most_pixels_on_one_thread).
    if (bands == 1)
        make_band(0);
    else
        tbb::parallel_for(0, bands, make_band);
    if (failed) throw std::runtime_error("zlib could not compress the image");
    size_t total = 2 + 4;
    for (const Part& part : parts) total += part.size;
    std::vector<unsigned char> stream = {0x78, 0x01};  // zlib header: deflate, 32K window, fastest
    stream.reserve(total);
    uLong sum = sums[0];
    for (size_t b = 0; b < parts.size(); ++b) {
        stream.insert(stream.end(), parts[b].bytes.get(), parts[b].bytes.get() + parts[b].size);
        if (b > 0) sum = adler32_combine(sum, sums[b], z_off_t(lengths[b]));
    }
    for (const int shift : {24, 16, 8, 0}) stream.push_back(static_cast<unsigned char>(sum >> shift));
    return stream;
}

bool is_ascii(const std::string& text) {
    return std::all_of(text.begin(), text.end(), [](char c) { return static_cast<unsigned char>(c) < 0x80; });
}

}  // namespace

void write_png(const std::string& path, const Image& linear, const DisplayTransform& display, int bits,
               const std::vector<std::pair<std::string, std::string>>& metadata) {
    if (bits != 8 && bits != 16) throw std::invalid_argument("PNG files hold 8 or 16 bits per channel");
    const int width = linear.width, height = linear.height;
    const Samples samples(linear, display, bits);
    // Text chunks: tEXt holds Latin-1, so anything else (a UTF-8 scene path) goes in iTXt.
    std::vector<png_text> texts(metadata.size());
    for (size_t i = 0; i < metadata.size(); ++i) {
        std::memset(&texts[i], 0, sizeof texts[i]);
        texts[i].key = const_cast<char*>(metadata[i].first.c_str());
        texts[i].text = const_cast<char*>(metadata[i].second.c_str());
        texts[i].text_length = metadata[i].second.size();
        texts[i].compression = is_ascii(metadata[i].second) ? PNG_TEXT_COMPRESSION_NONE : PNG_ITXT_COMPRESSION_NONE;
    }
    const std::vector<unsigned char> idat = compress_rows(samples);
    std::FILE* file = std::fopen(path.c_str(), "wb");
    if (!file) throw std::runtime_error("cannot open '" + path + "' for writing: " + std::strerror(errno));
    PngJob job{file, width, height, bits, idat.data(), idat.size(), texts.data(), int(texts.size()), display.encoding(),
               {}};
    errno = 0;
    const bool wrote = run(job);
    const bool closed = std::fclose(file) == 0;
    if (!wrote) throw std::runtime_error(std::string("libpng: ") + job.error);
    if (!closed) throw std::runtime_error("cannot finish '" + path + "': " + std::strerror(errno));
}

}  // namespace whitted
