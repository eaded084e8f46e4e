// SPDX-License-Identifier: MIT
#include "output/exr_file.h"

#include "output/format_plugins.h"

#include <Imath/half.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStandardAttributes.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfThreading.h>

#include <stdexcept>
#include <thread>

namespace whitted {
namespace {

Imf::Compression exr_compression(const std::string& name) {
    if (name.empty() || name == "none") return Imf::NO_COMPRESSION;
    if (name == "zip") return Imf::ZIP_COMPRESSION;
    if (name == "zips") return Imf::ZIPS_COMPRESSION;
    if (name == "piz") return Imf::PIZ_COMPRESSION;
    if (name == "rle") return Imf::RLE_COMPRESSION;
    throw std::invalid_argument("unknown EXR compression '" + name + "'; use none, zip, zips, piz or rle");
}

}  // namespace

void write_exr(const std::string& temp_path, const Image& image, bool half, const std::string& compression_name,
               const std::vector<std::pair<std::string, std::string>>& metadata) {
    const Imf::Compression compression = exr_compression(compression_name);
    // OpenEXR directly (not through OpenImageIO) keeps EXR renders free of OpenImageIO's
    // start-up cost; ZIP blocks are compressed on all cores.
    Imf::setGlobalThreadCount(compression == Imf::NO_COMPRESSION ? 0 : int(std::thread::hardware_concurrency()));
    Imf::Header header(image.width, image.height);
    // Uncompressed by default: deflate (zip) on a 1280x960 float image took 0.3-0.4 s, as long as
    // rendering it, to save about a third of the bytes (docs/performance.md). --exr-compression
    // picks another lossless scheme.
    header.compression() = compression;
    header.zipCompressionLevel() = 1;
    const Imf::PixelType type = half ? Imf::HALF : Imf::FLOAT;
    for (const char* channel : {"R", "G", "B"}) header.channels().insert(channel, Imf::Channel(type));
    for (const auto& [key, value] : metadata) header.insert(key, Imf::StringAttribute(value));
    // The standard attribute readers look for (OpenEXR's Chromaticities: Rec.709 primaries, D65).
    Imf::addChromaticities(header, Imf::Chromaticities());
    std::vector<Imath::half> halves;
    const char* base = reinterpret_cast<const char*>(image.rgb.data());
    size_t element = sizeof(float);
    if (half) {
        halves.assign(image.rgb.begin(), image.rgb.end());
        base = reinterpret_cast<const char*>(halves.data());
        element = sizeof(Imath::half);
    }
    Imf::FrameBuffer frame;
    const char* names[] = {"R", "G", "B"};
    for (int c = 0; c < 3; ++c)
        frame.insert(names[c], Imf::Slice(type, const_cast<char*>(base + c * element), 3 * element,
                                          3 * element * size_t(image.width)));
    // Render layers: `layer.channel` names as Nuke and Blender read them (docs/layers.md). Data
    // layers (normals, positions, ids) stay 32-bit float even with --half: half holds integers
    // exactly only up to 2048.
    std::vector<std::vector<Imath::half>> layer_halves(image.layers.size());
    for (size_t l = 0; l < image.layers.size(); ++l) {
        const ImageLayer& layer = image.layers[l];
        const size_t channels = layer.channels.size();
        const Imf::PixelType layer_type = layer.data ? Imf::FLOAT : type;
        const char* layer_base = reinterpret_cast<const char*>(layer.values.data());
        size_t layer_element = sizeof(float);
        if (layer_type == Imf::HALF) {
            layer_halves[l].assign(layer.values.begin(), layer.values.end());
            layer_base = reinterpret_cast<const char*>(layer_halves[l].data());
            layer_element = sizeof(Imath::half);
        }
        for (size_t c = 0; c < channels; ++c) {
            header.channels().insert(layer.channels[c], Imf::Channel(layer_type));
            frame.insert(layer.channels[c],
                         Imf::Slice(layer_type, const_cast<char*>(layer_base + c * layer_element),
                                    channels * layer_element, channels * layer_element * size_t(image.width)));
        }
    }
    try {
        Imf::OutputFile file(temp_path.c_str(), header);
        file.setFrameBuffer(frame);
        file.writePixels(image.height);
    } catch (const std::exception& e) {
        throw std::runtime_error(std::string("OpenEXR: ") + e.what());
    }
}

}  // namespace whitted

extern "C" WHITTED_PLUGIN_EXPORT void whitted_write_exr(const std::string& path, const whitted::Image& image,
                                                        bool half_floats, const std::string& compression,
                                                        const whitted::ImageMetadata& metadata) {
    whitted::write_exr(path, image, half_floats, compression, metadata);
}
