// SPDX-License-Identifier: MIT
#include "output/image_output.h"

#include "core/plugin.h"
#include "output/atomic_files.h"
#include "output/color_management.h"
#include "output/format_plugins.h"
#include "output/icc_profile.h"
#include "output/png_file.h"

#include <unistd.h>
#include <climits>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>

namespace whitted {
namespace {

std::string lower_extension(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
    return ext;
}

/// Removes the temporary file unless it was moved into place.
class TemporaryFile {
public:
    explicit TemporaryFile(const std::string& target) : m_path(temporary_path(target)) {}
    ~TemporaryFile() {
        if (!m_committed) std::remove(m_path.c_str());
    }
    const std::string& path() const { return m_path; }
    void commit(const std::string& target) {
        move_into_place(m_path, target);
        m_committed = true;
    }

private:
    std::string m_path;
    bool m_committed = false;
};

}  // namespace

OutputKind output_kind(const std::string& path) {
    const std::string ext = lower_extension(path);
    if (ext == ".exr") return OutputKind::linear_exr;
    if (ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".tif" || ext == ".tiff")
        return OutputKind::display_referred;
    throw std::invalid_argument("cannot write '" + path + "': unknown image type '" + ext +
                                "'; use .exr (linear), .png, .jpg or .tif (display-referred)");
}

void* format_writer(const std::string& ext) {
    struct Plugin {
        const char* file;
        const char* symbol;
        const char* needed_for;
    };
    Plugin plugin{};
    if (ext == ".exr")
        plugin = {"libwhitted_exr.so", "whitted_write_exr", "the OpenEXR writer, needed to write .exr files"};
    else if (ext == ".tif" || ext == ".tiff")
        plugin = {"libwhitted_tiff.so", "whitted_write_tiff", "the TIFF writer, needed to write .tif files"};
    else if (ext == ".jpg" || ext == ".jpeg")
        plugin = {"libwhitted_jpeg.so", "whitted_write_jpeg", "the JPEG writer, needed to write .jpg files"};
    else
        return nullptr;
    try {
        return plugin_symbol(plugin.file, plugin.symbol, plugin.needed_for);
    } catch (const std::runtime_error& e) {
        throw std::invalid_argument(e.what());
    }
}

void check_output_path(const std::string& path) {
    output_kind(path);
    const std::filesystem::path p(path);
    const std::filesystem::path dir = p.parent_path().empty() ? "." : p.parent_path();
    check_can_write(p);
    // Found here rather than when the finished image cannot be named, after the render.
    const long name_max = ::pathconf(dir.c_str(), _PC_NAME_MAX);
    const size_t longest = name_max > 0 ? size_t(name_max) : size_t(NAME_MAX);
    if (p.filename().string().size() > longest)
        throw std::invalid_argument("cannot write '" + path + "': the file name is " +
                                    std::to_string(p.filename().string().size()) +
                                    " bytes long; this filesystem allows " + std::to_string(longest));
}

namespace {

bool is_jpeg(const std::string& ext) {
    return ext == ".jpg" || ext == ".jpeg";
}
bool is_tiff(const std::string& ext) {
    return ext == ".tif" || ext == ".tiff";
}

/// The checks of check_output_options that need no config.
void check_format_options(const std::string& path, const OutputOptions& options) {
    const std::string ext = lower_extension(path);
    format_writer(ext);  // the plug-in writing the format is there and loads
    if (output_kind(path) == OutputKind::linear_exr) {
        const auto refuse = [&](const std::string& option) {
            throw std::invalid_argument(option + " cannot apply to '" + path +
                                        "': an EXR holds the scene-linear floats, before any display transform; "
                                        "write a .png, .jpg or .tif for a display-referred image");
        };
        if (options.bit_depth) refuse("--bit-depth");  // --half picks the EXR's precision
        if (!options.ocio_config.empty()) refuse("--ocio-config");
        if (!options.display.empty()) refuse("--display");
        if (!options.view.empty()) refuse("--view");
        return;
    }
    const auto refuse = [&](const std::string& option) {
        throw std::invalid_argument(option + " cannot apply to '" + path + "': it is for .exr files only");
    };
    if (options.half) refuse("--half");
    if (!options.exr_compression.empty()) refuse("--exr-compression");
    if (!options.layers_from.empty())
        throw std::invalid_argument("render layers (" + options.layers_from + ") cannot apply to '" + path +
                                    "': they are written as channels of an EXR only; write a .exr, or give "
                                    "--layers none");
    if (is_jpeg(ext) && options.bit_depth != 0 && options.bit_depth != 8)
        throw std::invalid_argument("--bit-depth " + std::to_string(options.bit_depth) + " cannot apply to '" + path +
                                    "': JPEG files hold 8 bits per channel; write a .png or .tif for 16 bits");
    if (options.bit_depth != 0 && options.bit_depth != 8 && options.bit_depth != 16)
        throw std::invalid_argument("--bit-depth must be 8 or 16");
}

/// The config as a file records it: never a path of this machine beyond the file's name.
std::string config_label(const DisplayTransform& display) {
    const std::string& source = display.config_source();
    if (source == "built-in") return "built-in (" + display.config_name() + ")";
    const bool from_env = source.rfind("$OCIO=", 0) == 0;
    const std::string file = std::filesystem::path(from_env ? source.substr(6) : source).filename().string();
    return file + (from_env ? " (from $OCIO)" : "") +
           (display.config_name().empty() ? "" : ", " + display.config_name());
}

}  // namespace

void check_output_options(const std::string& path, const OutputOptions& options) {
    check_format_options(path, options);
    if (output_kind(path) == OutputKind::display_referred)
        DisplayTransform(options.ocio_config, options.display, options.view);  // loads the config, finds the names
}

namespace {

/// write_image's work, into `temp_path`.
void write_to(const std::string& temp_path, const Image& image, const std::string& path, const OutputOptions& options,
              std::vector<std::pair<std::string, std::string>> metadata) {
    const OutputKind kind = output_kind(path);
    const std::string ext = lower_extension(path);
    if (kind == OutputKind::linear_exr) {
        metadata.push_back({"whitted:colorspace", "Linear Rec.709 (sRGB)"});
        metadata.insert(metadata.end(), options.metadata.begin(), options.metadata.end());
        const auto write_exr = reinterpret_cast<WriteExrFunction>(format_writer(ext));
        write_exr(temp_path, image, options.half, options.exr_compression, metadata);
    } else {
        const DisplayTransform display(options.ocio_config, options.display, options.view);
        const int bits = options.bit_depth ? options.bit_depth : (is_tiff(ext) ? 16 : 8);
        metadata.push_back({"whitted:colorspace", display.colorspace()});
        metadata.push_back({"whitted:encoding", display.encoding().description()});
        metadata.push_back({"whitted:ocio_config", config_label(display)});
        metadata.push_back({"whitted:display", display.display()});
        metadata.push_back({"whitted:view", display.view()});
        metadata.insert(metadata.end(), options.metadata.begin(), options.metadata.end());
        if (ext == ".png") {
            write_png(temp_path, image, display, bits, metadata);
        } else {
            std::vector<float> pixels = image.rgb;
            display.apply(pixels.data(), pixels.size() / 3);
            const std::vector<unsigned char> profile =
                icc_profile(display.encoding(), "Whitted: " + display.display() + " / " + display.view() + " (" +
                                                    display.colorspace() + ")");
            if (is_jpeg(ext))
                reinterpret_cast<WriteJpegFunction>(format_writer(ext))(temp_path, image.width, image.height,
                                                                        pixels.data(), metadata, profile);
            else
                reinterpret_cast<WriteTiffFunction>(format_writer(ext))(temp_path, image.width, image.height,
                                                                        pixels.data(), bits, metadata, profile);
        }
    }
}

}  // namespace

void write_image(const Image& image, const std::string& path, const OutputOptions& options) {
    check_format_options(path, options);
    std::vector<std::pair<std::string, std::string>> metadata{{"Software", "Whitted " WHITTED_VERSION}};

    TemporaryFile temporary(path);
    // Every writer's failure as one message naming the file (the temporary is removed by
    // `temporary`; the existing file is untouched).
    try {
        write_to(temporary.path(), image, path, options, metadata);
    } catch (const std::invalid_argument&) {
        throw;
    } catch (const std::exception& e) {
        throw std::runtime_error("cannot write '" + path + "': " + e.what());
    }
    temporary.commit(path);
}

}  // namespace whitted
