// SPDX-License-Identifier: MIT
#pragma once

#include "whitted/image.h"

#include <string>
#include <utility>
#include <vector>

namespace whitted {

struct OutputOptions {
    bool half = false;            ///< EXR: half floats instead of full floats
    std::string exr_compression;  ///< EXR: none, zip, zips, piz or rle (all lossless); empty = none
    int bit_depth = 0;            ///< PNG/TIFF: 8 or 16; 0 = the format's default (PNG/JPEG 8, TIFF 16)
    std::string ocio_config;      ///< empty: $OCIO, else the built-in config
    std::string display, view;    ///< empty: the config's defaults
    std::vector<std::pair<std::string, std::string>> metadata;  ///< extra string attributes
    /// Where render layers were asked for ("--layers", or render.layers' file:line:col); empty
    /// when none were: layers go to EXR files only.
    std::string layers_from;
};

enum class OutputKind { linear_exr, display_referred };

/// Which kind of file the path's extension asks for; throws std::invalid_argument naming the
/// supported extensions when it is none of them.
OutputKind output_kind(const std::string& path);

/// Checks, before any rendering, that `path` can be written (directory exists and is writable,
/// extension known). Throws std::invalid_argument with the reason.
void check_output_path(const std::string& path);

/// Checks, before any rendering, that every option given applies to the format `path` names
/// (EXR: --half, --exr-compression, render layers; PNG/JPEG/TIFF: --bit-depth, --ocio-config, --display,
/// --view; JPEG 8 bits only) and that the config loads and has the display and view. Throws
/// std::invalid_argument naming the option and what would apply (a bad display or view lists
/// the config's).
void check_output_options(const std::string& path, const OutputOptions& options);

/// Writes the image: EXR linear; PNG/JPEG/TIFF through the OCIO display transform. The file is
/// written to a temporary name in the same directory and moved to `path` only when complete
/// (an existing file is swapped out atomically, then deleted), so a failure never leaves a
/// partial file or touches an existing one.
void write_image(const Image& image, const std::string& path, const OutputOptions& options);

}  // namespace whitted
