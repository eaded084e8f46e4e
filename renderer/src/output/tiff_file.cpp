// SPDX-License-Identifier: MIT
// TIFF through libtiff directly rather than the OpenImageIO plug-in: loading OpenImageIO took
// most of a 640x480 TIFF's 0.6-1 s write, and its messages came over several lines. libtiff
// reports errors through a handler per file (TIFFOpenExt), kept here for the exception.

#include "output/tiff_file.h"

#include "output/format_plugins.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tiffio.h>

#include <algorithm>
#include <cerrno>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <stdexcept>

namespace whitted {
namespace {

struct Errors {
    std::string first;  ///< the first message: later ones follow from it
};

extern "C" int on_tiff_error(TIFF*, void* user_data, const char* module, const char* format, va_list args) {
    auto* errors = static_cast<Errors*>(user_data);
    if (errors->first.empty()) {
        char message[512];
        std::vsnprintf(message, sizeof message, format, args);
        errors->first = std::string(module ? module : "libtiff") + ": " + message;
    }
    return 1;  // handled: libtiff's global handler would print it to stderr
}

extern "C" int on_tiff_warning(TIFF*, void*, const char*, const char*, va_list) {
    return 1;
}

}  // namespace

void write_tiff(const std::string& path, int width, int height, const float* rgb, int bits,
                const std::vector<std::pair<std::string, std::string>>& metadata,
                const std::vector<unsigned char>& icc_profile) {
    if (bits != 8 && bits != 16) throw std::invalid_argument("TIFF files are written with 8 or 16 bits per channel");
    const size_t samples_per_row = 3 * size_t(width);
    const size_t row_bytes = samples_per_row * size_t(bits / 8);
    std::vector<unsigned char> rows(row_bytes * size_t(height));
    const double scale = bits == 16 ? 65535.0 : 255.0;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, samples_per_row * size_t(height), 65536),
                      [&](const tbb::blocked_range<size_t>& range) {
                          for (size_t i = range.begin(); i != range.end(); ++i) {
                              const float v = rgb[i] > 0 ? std::min(rgb[i], 1.0f) : 0.0f;  // NaN fails `> 0`
                              const auto code = static_cast<uint32_t>(double(v) * scale + 0.5);
                              if (bits == 16) {
                                  const auto value = static_cast<uint16_t>(code);
                                  std::memcpy(rows.data() + 2 * i, &value, 2);  // libtiff takes native order
                              } else {
                                  rows[i] = static_cast<unsigned char>(code);
                              }
                          }
                      });
    std::string description, software;
    for (const auto& [key, value] : metadata) {
        if (key == "Software")
            software = value;
        else
            description += key + ": " + value + "\n";
    }

    Errors errors;
    TIFFOpenOptions* options = TIFFOpenOptionsAlloc();
    TIFFOpenOptionsSetErrorHandlerExtR(options, on_tiff_error, &errors);
    TIFFOpenOptionsSetWarningHandlerExtR(options, on_tiff_warning, nullptr);
    errno = 0;
    TIFF* tiff = TIFFOpenExt(path.c_str(), "w", options);
    TIFFOpenOptionsFree(options);
    if (!tiff)
        throw std::runtime_error("cannot open '" + path +
                                 "' for writing: " + (errno ? std::strerror(errno) : errors.first.c_str()));
    TIFFSetField(tiff, TIFFTAG_IMAGEWIDTH, uint32_t(width));
    TIFFSetField(tiff, TIFFTAG_IMAGELENGTH, uint32_t(height));
    TIFFSetField(tiff, TIFFTAG_SAMPLESPERPIXEL, uint16_t(3));
    TIFFSetField(tiff, TIFFTAG_BITSPERSAMPLE, uint16_t(bits));
    TIFFSetField(tiff, TIFFTAG_PHOTOMETRIC, PHOTOMETRIC_RGB);
    TIFFSetField(tiff, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
    TIFFSetField(tiff, TIFFTAG_ORIENTATION, ORIENTATION_TOPLEFT);
    // Deflate at level 1 with the horizontal predictor: a third of the bytes of an uncompressed
    // file for a few milliseconds (OpenImageIO's default, zip at level 6, was several times
    // slower for a few per cent fewer bytes).
    TIFFSetField(tiff, TIFFTAG_COMPRESSION, COMPRESSION_ADOBE_DEFLATE);
    TIFFSetField(tiff, TIFFTAG_PREDICTOR, PREDICTOR_HORIZONTAL);
    TIFFSetField(tiff, TIFFTAG_ZIPQUALITY, 1);
    TIFFSetField(tiff, TIFFTAG_ROWSPERSTRIP, TIFFDefaultStripSize(tiff, 0));
    if (!software.empty()) TIFFSetField(tiff, TIFFTAG_SOFTWARE, software.c_str());
    if (!description.empty()) TIFFSetField(tiff, TIFFTAG_IMAGEDESCRIPTION, description.c_str());
    if (!icc_profile.empty()) TIFFSetField(tiff, TIFFTAG_ICCPROFILE, uint32_t(icc_profile.size()), icc_profile.data());
    bool wrote = true;
    errno = 0;
    std::vector<unsigned char> row(row_bytes);  // libtiff's predictor changes the row it is given
    for (int y = 0; y < height && wrote; ++y) {
        std::memcpy(row.data(), rows.data() + size_t(y) * row_bytes, row_bytes);
        wrote = TIFFWriteScanline(tiff, row.data(), uint32_t(y), 0) == 1;
    }
    wrote = wrote && TIFFFlush(tiff) == 1;  // TIFFClose reports nothing
    const int reason = errno;
    TIFFClose(tiff);
    if (!wrote)
        throw std::runtime_error((errors.first.empty() ? std::string("libtiff: write failed") : errors.first) +
                                 (reason ? std::string(" (") + std::strerror(reason) + ")" : ""));
}

}  // namespace whitted

extern "C" WHITTED_PLUGIN_EXPORT void whitted_write_tiff(const std::string& path, int width, int height,
                                                         const float* rgb, int bits,
                                                         const whitted::ImageMetadata& metadata,
                                                         const std::vector<unsigned char>& icc_profile) {
    whitted::write_tiff(path, width, height, rgb, bits, metadata, icc_profile);
}
