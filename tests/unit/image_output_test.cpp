// SPDX-License-Identifier: MIT
// Writing images: an EXR holds the linear floats exactly, a PNG the rounded display codes and
// the metadata, a finished image replaces an existing one, and a failed write leaves the old
// file as it was and no temporary file behind.

#include "output/image_output.h"

#include "test_support.h"
#include "whitted/version.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfStandardAttributes.h>

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace whitted {
namespace {

Image ramp(int width, int height, float scale) {
    Image image;
    image.width = width;
    image.height = height;
    image.rgb.resize(size_t(width) * height * 3);
    for (size_t i = 0; i < image.rgb.size(); ++i) image.rgb[i] = scale * float(i) / 7.0f;
    return image;
}

std::vector<float> read_exr_rgb(const std::string& path) {
    Imf::InputFile file(path.c_str());
    const Imath::Box2i window = file.header().dataWindow();
    const int width = window.max.x - window.min.x + 1, height = window.max.y - window.min.y + 1;
    std::vector<float> rgb(size_t(width) * height * 3);
    Imf::FrameBuffer frame;
    const char* names[] = {"R", "G", "B"};
    for (int c = 0; c < 3; ++c)
        frame.insert(names[c], Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(rgb.data() + c), 3 * sizeof(float),
                                          3 * sizeof(float) * size_t(width)));
    file.setFrameBuffer(frame);
    file.readPixels(window.min.y, window.max.y);
    return rgb;
}

std::vector<std::string> entries(const std::filesystem::path& directory) {
    std::vector<std::string> names;
    for (const auto& entry : std::filesystem::directory_iterator(directory))
        names.push_back(entry.path().filename().string());
    return names;
}

std::string bytes_of(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    return bytes.str();
}

TEST(ImageOutput, ExrHoldsTheLinearFloatsExactly) {
    const test::ScratchDirectory directory;
    const std::string path = (directory.path() / "new.exr").string();
    const Image image = ramp(5, 3, 1.0f);
    write_image(image, path, {});
    EXPECT_EQ(read_exr_rgb(path), image.rgb);
    EXPECT_EQ(entries(directory.path()), std::vector<std::string>{"new.exr"});
}

/// Writes `image` as a PNG through the Raw view (the identity) and reads it back with
/// OpenImageIO, which does not share the writer's code: the spec, and every value as a 16-bit
/// code (OpenImageIO widens an 8-bit code c to c·257).
std::vector<uint16_t> raw_png_codes(const Image& image, const std::string& path, int bits, OIIO::ImageSpec& spec,
                                    const std::vector<std::pair<std::string, std::string>>& metadata = {}) {
    OutputOptions options;
    options.bit_depth = bits;
    options.display = "sRGB";
    options.view = "Raw";
    options.metadata = metadata;
    write_image(image, path, options);
    auto in = OIIO::ImageInput::open(path);
    if (!in) {
        ADD_FAILURE() << OIIO::geterror();
        return {};
    }
    spec = in->spec();
    std::vector<uint16_t> codes(image.rgb.size());
    if (!in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT16, codes.data())) ADD_FAILURE() << in->geterror();
    return codes;
}

/// round(clamp(v, 0, 1) · max), NaN as 0, widened to 16 bits as OpenImageIO reads it.
uint16_t expected_code(float value, int bits) {
    const double v = std::isnan(value) ? 0.0 : std::min(std::max(double(value), 0.0), 1.0);
    const double code = std::floor(v * (bits == 16 ? 65535.0 : 255.0) + 0.5);
    return uint16_t(bits == 16 ? code : code * 257);
}

// The file must hold each value's nearest code (0.7f is 178 in 8 bits, not 179) and the
// metadata, a UTF-8 value included (an iTXt chunk).
TEST(ImageOutput, PngHoldsTheRoundedDisplayCodes) {
    Image image;
    image.width = 2;
    image.height = 2;
    image.rgb = {-1.0f,    0.0f,   0.5f / 255, 0.49f / 255, 0.25f,
                 0.5f,     0.999f, 1.0f,       7.0f,        std::numeric_limits<float>::quiet_NaN(),
                 1.0f / 3, 0.7f};
    const test::ScratchDirectory directory;
    for (const int bits : {8, 16}) {
        OIIO::ImageSpec spec;
        const std::vector<uint16_t> codes =
            raw_png_codes(image, (directory.path() / ("raw" + std::to_string(bits) + ".png")).string(), bits, spec,
                          {{"whitted:scene", "/tmp/sc\xc3\xa8ne.yaml"}});
        ASSERT_EQ(codes.size(), image.rgb.size());
        EXPECT_EQ(spec.width, 2);
        EXPECT_EQ(spec.height, 2);
        EXPECT_EQ(spec.nchannels, 3);
        EXPECT_EQ(spec.format, bits == 16 ? OIIO::TypeDesc::UINT16 : OIIO::TypeDesc::UINT8);
        EXPECT_EQ(spec.get_string_attribute("Software"), "Whitted " WHITTED_VERSION_STRING);
        EXPECT_EQ(spec.get_string_attribute("whitted:scene"), "/tmp/sc\xc3\xa8ne.yaml");
        for (size_t i = 0; i < codes.size(); ++i)
            EXPECT_EQ(codes[i], expected_code(image.rgb[i], bits)) << bits << " bits, value " << image.rgb[i];
    }
}

// The image data is deflated in bands of 64 rows on all cores and the parts joined: an image
// of several bands, with the "up" filter crossing band edges, must read back code for code.
TEST(ImageOutput, PngOfManyBandsReadsBackExactly) {
    Image image;
    image.width = 157;
    image.height = 203;  // four bands, the last one short
    image.rgb.resize(size_t(image.width) * image.height * 3);
    uint32_t state = 12345;
    for (float& v : image.rgb) {  // a fixed pseudo-random mix of smooth and noisy values
        state = state * 1664525u + 1013904223u;
        v = float(state >> 8) / float(1 << 24) * (&v - image.rgb.data() < 20000 ? 0.1f : 1.2f);
    }
    const test::ScratchDirectory directory;
    for (const int bits : {8, 16}) {
        OIIO::ImageSpec spec;
        const std::vector<uint16_t> codes =
            raw_png_codes(image, (directory.path() / ("bands" + std::to_string(bits) + ".png")).string(), bits, spec);
        ASSERT_EQ(codes.size(), image.rgb.size());
        size_t wrong = 0;
        for (size_t i = 0; i < codes.size(); ++i) wrong += codes[i] != expected_code(image.rgb[i], bits);
        EXPECT_EQ(wrong, 0u) << bits << " bits";
    }
}

// The finished image is swapped in for the old one (renameat2 RENAME_EXCHANGE) and the old one
// deleted: the path holds the new pixels and nothing else is left in the directory.
TEST(ImageOutput, FinishedImageReplacesAnExistingOne) {
    const test::ScratchDirectory directory;
    const std::string path = (directory.path() / "out.exr").string();
    write_image(ramp(4, 4, 1.0f), path, {});
    const Image second = ramp(6, 2, -3.0f);
    write_image(second, path, {});
    EXPECT_EQ(read_exr_rgb(path), second.rgb);
    EXPECT_EQ(entries(directory.path()), std::vector<std::string>{"out.exr"});
}

TEST(ImageOutput, FailedWriteLeavesTheOldFileAlone) {
    const test::ScratchDirectory directory;
    const std::string path = (directory.path() / "keep.exr").string();
    write_image(ramp(4, 4, 1.0f), path, {});
    const std::string before = bytes_of(path);
    OutputOptions bad;
    bad.exr_compression = "lzma";  // not an EXR compression: refused
    EXPECT_THROW(write_image(ramp(8, 8, 2.0f), path, bad), std::invalid_argument);
    EXPECT_EQ(bytes_of(path), before);
    EXPECT_EQ(entries(directory.path()), std::vector<std::string>{"keep.exr"});
}

TEST(ImageOutput, ExrDeclaresRec709Chromaticities) {
    const test::ScratchDirectory directory;
    const std::string path = (directory.path() / "c.exr").string();
    write_image(ramp(2, 2, 1.0f), path, {});
    Imf::InputFile file(path.c_str());
    ASSERT_TRUE(Imf::hasChromaticities(file.header()));
    const Imf::Chromaticities& c = Imf::chromaticities(file.header());
    EXPECT_FLOAT_EQ(c.red.x, 0.64f);
    EXPECT_FLOAT_EQ(c.red.y, 0.33f);
    EXPECT_FLOAT_EQ(c.green.x, 0.30f);
    EXPECT_FLOAT_EQ(c.blue.y, 0.06f);
    EXPECT_FLOAT_EQ(c.white.x, 0.3127f);
    EXPECT_FLOAT_EQ(c.white.y, 0.3290f);
}

// Each option that cannot apply to the format is refused before anything is rendered.
TEST(ImageOutput, OptionsThatCannotApplyAreRefused) {
    ::unsetenv("OCIO");  // the built-in config's displays
    const auto refused = [](const std::string& path, const OutputOptions& options) {
        try {
            check_output_options(path, options);
            return std::string();
        } catch (const std::invalid_argument& e) {
            return std::string(e.what());
        }
    };
    OutputOptions deep;
    deep.bit_depth = 16;
    EXPECT_NE(refused("a.jpg", deep).find("--bit-depth 16"), std::string::npos);
    EXPECT_NE(refused("a.exr", deep).find("--bit-depth"), std::string::npos);
    EXPECT_EQ(refused("a.png", deep), "");
    EXPECT_EQ(refused("a.tif", deep), "");
    OutputOptions half;
    half.half = true;
    EXPECT_NE(refused("a.png", half).find("--half"), std::string::npos);
    EXPECT_EQ(refused("a.exr", half), "");
    OutputOptions zip;
    zip.exr_compression = "zip";
    EXPECT_NE(refused("a.tif", zip).find("--exr-compression"), std::string::npos);
    OutputOptions raw;
    raw.view = "Raw";
    EXPECT_NE(refused("a.exr", raw).find("--view"), std::string::npos);
    EXPECT_EQ(refused("a.png", raw), "");
    OutputOptions display;
    display.display = "Rec.2020";
    EXPECT_NE(refused("a.png", display).find("displays: sRGB, Gamma 2.2, BT.1886, Display P3"), std::string::npos);
    EXPECT_NE(refused("a.exr", display).find("--display"), std::string::npos);
}

}  // namespace
}  // namespace whitted
