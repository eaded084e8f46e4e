// SPDX-License-Identifier: MIT
#pragma once

#include "whitted/image.h"

#include <string>
#include <utility>
#include <vector>

/// The writers that need a library a default PNG render does not (OpenEXR, libtiff, libjpeg)
/// are plug-ins, lib/libwhitted_exr.so, libwhitted_tiff.so and libwhitted_jpeg.so, loaded the
/// first time their format is asked for (core/plugin.h says where they are looked for).
/// Linked into the program, those libraries and theirs (libtiff alone brings seven: WebP,
/// zstd, LZMA, LERC, JBIG, libdeflate) cost every run their loading and relocation
/// (docs/performance.md, "Start-up").
///
/// Each plug-in exports one C function of the writer's C++ signature: the plug-ins are built
/// with the program by the same compiler, so the types and exceptions cross as they are.
#define WHITTED_PLUGIN_EXPORT __attribute__((visibility("default")))

namespace whitted {

using ImageMetadata = std::vector<std::pair<std::string, std::string>>;

using WriteExrFunction = void (*)(const std::string& path, const Image& image, bool half,
                                  const std::string& compression, const ImageMetadata& metadata);
using WriteTiffFunction = void (*)(const std::string& path, int width, int height, const float* rgb, int bits,
                                   const ImageMetadata& metadata, const std::vector<unsigned char>& icc_profile);
using WriteJpegFunction = void (*)(const std::string& path, int width, int height, const float* rgb,
                                   const ImageMetadata& metadata, const std::vector<unsigned char>& icc_profile);

/// The writer of the plug-in for the file's extension (.exr, .tif/.tiff, .jpg/.jpeg), loaded
/// on first use; nullptr for a format written by the program itself (PNG). Throws
/// std::invalid_argument (a usage error, found before rendering) naming the plug-in and the
/// format when the plug-in cannot be loaded.
void* format_writer(const std::string& lower_extension);

}  // namespace whitted
