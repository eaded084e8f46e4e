// SPDX-License-Identifier: MIT
#include "whitted/output/image_output.h"

#include "whitted/output/color_management.h"

#include <OpenImageIO/imageio.h>

#include <unistd.h>

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

/// Removes the temporary file unless it was handed over by rename.
class TemporaryFile {
public:
    explicit TemporaryFile(const std::string& target) {
        const std::filesystem::path t(target);
        const std::filesystem::path dir = t.parent_path().empty() ? "." : t.parent_path();
        m_path = (dir / ("." + t.filename().string() + ".whitted-" + std::to_string(::getpid()) + ".tmp" +
                         t.extension().string()))
                     .string();
    }
    ~TemporaryFile() {
        if (!m_committed) std::remove(m_path.c_str());
    }
    const std::string& path() const { return m_path; }
    void commit(const std::string& target) {
        if (std::rename(m_path.c_str(), target.c_str()) != 0)
            throw std::runtime_error("cannot move the finished image to '" + target + "': " + std::strerror(errno));
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

void check_output_path(const std::string& path) {
    output_kind(path);
    const std::filesystem::path p(path);
    const std::filesystem::path dir = p.parent_path().empty() ? "." : p.parent_path();
    std::error_code error;
    if (!std::filesystem::is_directory(dir, error))
        throw std::invalid_argument("cannot write '" + path + "': directory '" + dir.string() + "' does not exist");
    if (::access(dir.c_str(), W_OK) != 0)
        throw std::invalid_argument("cannot write '" + path + "': directory '" + dir.string() + "' is not writable");
    if (std::filesystem::is_directory(p, error))
        throw std::invalid_argument("cannot write '" + path + "': it is a directory");
}

void write_image(const Image& image, const std::string& path, const OutputOptions& options) {
    const OutputKind kind = output_kind(path);
    const std::string ext = lower_extension(path);
    std::vector<float> pixels = image.rgb;
    OIIO::TypeDesc type = OIIO::TypeDesc::FLOAT;
    std::string colorspace = "Linear Rec.709 (sRGB)";
    if (kind == OutputKind::linear_exr) {
        if (options.half) type = OIIO::TypeDesc::HALF;
    } else {
        const DisplayTransform display(options.ocio_config, options.display, options.view);
        display.apply(pixels.data(), pixels.size() / 3);
        const bool is_tiff = ext == ".tif" || ext == ".tiff";
        int bits = options.bit_depth ? options.bit_depth : (is_tiff ? 16 : 8);
        if ((ext == ".jpg" || ext == ".jpeg") && bits != 8)
            throw std::invalid_argument("JPEG files hold 8 bits per channel only");
        type = bits == 16 ? OIIO::TypeDesc::UINT16 : OIIO::TypeDesc::UINT8;
        colorspace = display.display() + " / " + display.view() + " (" + display.config_source() + ")";
    }

    OIIO::ImageSpec spec(image.width, image.height, 3, type);
    spec.attribute("Software", "Whitted");
    spec.attribute("whitted:colorspace", colorspace);
    if (kind == OutputKind::linear_exr) spec.attribute("compression", "zip");
    for (const auto& [key, value] : options.metadata) spec.attribute(key, value);

    TemporaryFile temporary(path);
    auto out = OIIO::ImageOutput::create(path);
    if (!out) throw std::runtime_error("cannot write '" + path + "': " + OIIO::geterror());
    if (!out->open(temporary.path(), spec)) throw std::runtime_error("cannot write '" + path + "': " + out->geterror());
    const bool wrote = out->write_image(OIIO::TypeDesc::FLOAT, pixels.data());
    const bool closed = out->close();
    if (!wrote || !closed) throw std::runtime_error("cannot write '" + path + "': " + out->geterror());
    temporary.commit(path);
}

}  // namespace whitted
