// SPDX-License-Identifier: MIT
// The pass rule of `whitted check` and `whitted compare` on closed-form images: every rule
// (share, cap, finite, size, channels) fails on its own, the worst pixels come out in order, and
// files that are not complete images are refused before anything is allocated or read.

#include "reference/compare.h"

#include "test_support.h"

#include <OpenImageIO/imageio.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <zlib.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace whitted::reference {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::IsEmpty;
using ::testing::StartsWith;

constexpr double code = 1.0 / 65535.0;

/// A 96x72 image (the POV-Ray tier's size) of one grey value.
Image constant(float value, int width = 96, int height = 72) {
    Image image;
    image.width = width;
    image.height = height;
    image.rgb.assign(size_t(width) * size_t(height) * 3, value);
    return image;
}

void set(Image& image, int x, int y, int channel, float value) {
    image.rgb[3 * (size_t(y) * size_t(image.width) + size_t(x)) + size_t(channel)] = value;
}

std::vector<std::string> rule_names(const std::vector<std::string>& failures) {
    std::vector<std::string> names;
    for (const auto& failure : failures) names.push_back(failure.substr(0, failure.find(' ')));
    return names;
}

TEST(PassRule, IdenticalImagesPass) {
    const Image a = constant(0.5f);
    const ImageComparison c = compare_images(a, a, PassRule().tolerance);
    EXPECT_EQ(c.max_error, 0.0);
    EXPECT_EQ(c.pixels_within, c.pixels);
    EXPECT_THAT(failed_rules(c, PassRule()), IsEmpty());
}

// The hole the cap closes: 6 of 6912 pixels (0.087 %, under the 0.1 % the share allows) off by
// a thousand codes passed the share rule alone.
TEST(PassRule, AFewPixelsFarOffFailTheCapOnly) {
    const Image ours = constant(0.5f);
    Image theirs = ours;
    for (int i = 0; i < 6; ++i) set(theirs, 10 + i, 20, 1, float(0.5 + 1000 * code));
    const ImageComparison c = compare_images(ours, theirs, PassRule().tolerance);
    EXPECT_EQ(c.pixels - c.pixels_within, 6u);
    EXPECT_GE(c.fraction_within(), PassRule().required_fraction);
    EXPECT_NEAR(c.max_error, 1000 * code, 1e-7);
    const auto failures = failed_rules(c, PassRule());
    EXPECT_THAT(rule_names(failures), ElementsAre("cap"));
    EXPECT_THAT(failures[0], HasSubstr("> 64"));
}

TEST(PassRule, TheCapIsInclusiveAndSettable) {
    const Image ours = constant(0.25f);
    Image theirs = ours;
    set(theirs, 0, 0, 2, float(0.25 + 60 * code));
    const ImageComparison c = compare_images(ours, theirs, PassRule().tolerance);
    EXPECT_THAT(failed_rules(c, PassRule()), IsEmpty()) << "60 codes is under the default cap of 64";
    PassRule strict;
    strict.max_error = 50 * code;
    EXPECT_THAT(rule_names(failed_rules(c, strict)), ElementsAre("cap"));
    PassRule exact;
    exact.max_error = c.max_error;
    EXPECT_THAT(failed_rules(c, exact), IsEmpty()) << "an error equal to the cap is within it";
}

TEST(PassRule, ManyPixelsSlightlyOffFailTheShareOnly) {
    const Image ours = constant(0.5f);
    Image theirs = ours;
    // 3 codes on every tenth row: 10 % of the pixels beyond 2 codes, none beyond the cap.
    for (int y = 0; y < 72; y += 10)
        for (int x = 0; x < 96; ++x) set(theirs, x, y, 0, float(0.5 + 3 * code));
    const ImageComparison c = compare_images(ours, theirs, PassRule().tolerance);
    EXPECT_NEAR(c.fraction_within(), 1.0 - 8.0 / 72.0, 1e-12);
    EXPECT_THAT(rule_names(failed_rules(c, PassRule())), ElementsAre("share"));
}

TEST(PassRule, OneNaNFailsWhereverItIs) {
    const Image theirs = constant(0.5f);
    Image ours = theirs;
    set(ours, 95, 71, 1, std::numeric_limits<float>::quiet_NaN());
    const ImageComparison c = compare_images(ours, theirs, PassRule().tolerance);
    EXPECT_EQ(c.nonfinite_ours, 1u);
    EXPECT_EQ(c.nonfinite_theirs, 0u);
    EXPECT_TRUE(std::isinf(c.max_error));
    ASSERT_FALSE(c.worst.empty());
    EXPECT_EQ(c.worst[0].x, 95);
    EXPECT_EQ(c.worst[0].y, 71);
    EXPECT_THAT(rule_names(failed_rules(c, PassRule())), ElementsAre("cap", "finite"));
}

// inf − inf is NaN, not 0: the same infinity in both images must not look like agreement.
TEST(PassRule, InfinityInBothImagesStillFails) {
    Image ours = constant(0.5f);
    set(ours, 3, 4, 0, std::numeric_limits<float>::infinity());
    const Image theirs = ours;
    const ImageComparison c = compare_images(ours, theirs, PassRule().tolerance);
    EXPECT_EQ(c.nonfinite_ours, 1u);
    EXPECT_EQ(c.nonfinite_theirs, 1u);
    const auto failures = failed_rules(c, PassRule(), "ours", "theirs");
    EXPECT_THAT(rule_names(failures), ElementsAre("cap", "finite"));
    EXPECT_THAT(failures[1], HasSubstr("1 NaN/Inf value(s) in ours, 1 in theirs"));
}

TEST(PassRule, ShapesMustMatch) {
    EXPECT_THAT(shape_mismatches({96, 72, 3}, {96, 72, 3}), IsEmpty());
    EXPECT_THAT(shape_mismatches({96, 72, 3}, {95, 72, 3}), ElementsAre("size (96x72 vs 95x72)"));
    // The colour is compared: RGB against RGBA, or against an EXR with render layers, is no mismatch.
    EXPECT_THAT(shape_mismatches({96, 72, 3}, {96, 72, 4}), IsEmpty());
    EXPECT_THAT(shape_mismatches({96, 72, 40}, {96, 72, 3}), IsEmpty());
    EXPECT_THAT(shape_mismatches({96, 72, 3}, {96, 72, 1}), ElementsAre("channels (3 vs 1: colour against grey)"));
    EXPECT_THROW(compare_images(constant(0, 96, 72), constant(0, 72, 96), code), std::invalid_argument);
}

TEST(PassRule, WorstPixelsLargestFirstTiesInReadingOrder) {
    const Image ours = constant(0.5f, 8, 8);
    Image theirs = ours;
    // Errors of 10, 30, 30, 20 codes; the two 30s in reading order: (5, 1) before (2, 6).
    set(theirs, 1, 0, 0, float(0.5 + 10 * code));
    set(theirs, 5, 1, 1, float(0.5 - 30 * code));
    set(theirs, 2, 6, 2, float(0.5 + 30 * code));
    set(theirs, 7, 7, 0, float(0.5 + 20 * code));
    const ImageComparison c = compare_images(ours, theirs, code, 3);
    ASSERT_EQ(c.worst.size(), 3u);
    EXPECT_EQ(c.worst[0].x, 5);
    EXPECT_EQ(c.worst[0].y, 1);
    EXPECT_EQ(c.worst[1].x, 2);
    EXPECT_EQ(c.worst[1].y, 6);
    EXPECT_EQ(c.worst[2].x, 7);
    EXPECT_EQ(c.worst[2].y, 7);
    EXPECT_NEAR(c.worst[2].error, 20 * code, 1e-7);
    EXPECT_EQ(c.worst[0].theirs[1], float(0.5 - 30 * code));
    EXPECT_EQ(compare_images(ours, theirs, code, 10).worst.size(), 10u) << "as many as asked, when there are";
}

TEST(PassRule, VerdictSaysWhichRuleFailed) {
    EXPECT_EQ(verdict_text("s.yaml", "F", {}), "PASS s.yaml: F");
    EXPECT_EQ(verdict_text("s.yaml", "F", {"cap (x)", "finite (y)"}), "FAIL s.yaml: F; failed: cap (x), finite (y)");
    EXPECT_EQ(verdict_text("a vs b", "", {"size (1x1 vs 2x2)"}), "FAIL a vs b: failed: size (1x1 vs 2x2)");
    const Image a = constant(0.5f);
    EXPECT_EQ(verdict_figures(compare_images(a, a, PassRule().tolerance), PassRule()),
              "100.000% of pixels within 2/65535 (99.9% required), max 0.0 codes (cap 64)");
}

// --- Files -------------------------------------------------------------------------------

void append_chunk(std::string& png, const char* type, const std::string& data) {
    const uint32_t length = uint32_t(data.size());
    for (int shift = 24; shift >= 0; shift -= 8) png += char((length >> shift) & 0xff);
    const std::string body = std::string(type, 4) + data;
    png += body;
    const uint32_t crc = uint32_t(::crc32(0, reinterpret_cast<const Bytef*>(body.data()), uInt(body.size())));
    for (int shift = 24; shift >= 0; shift -= 8) png += char((crc >> shift) & 0xff);
}

/// A valid PNG header claiming `width` x `height`, 16-bit RGB, with one tiny IDAT and IEND.
std::string png_claiming(uint32_t width, uint32_t height) {
    std::string png("\x89PNG\r\n\x1a\n", 8);
    std::string ihdr;
    for (const uint32_t v : {width, height})
        for (int shift = 24; shift >= 0; shift -= 8) ihdr += char((v >> shift) & 0xff);
    ihdr += std::string("\x10\x02\x00\x00\x00", 5);  // 16 bits, RGB, deflate, no filter, no interlace
    append_chunk(png, "IHDR", ihdr);
    append_chunk(png, "IDAT", std::string("\x78\x9c\x03\x00\x00\x00\x00\x01", 8));
    append_chunk(png, "IEND", "");
    return png;
}

void write_png(const std::string& path, const Image& image) {
    auto out = OIIO::ImageOutput::create(path);
    ASSERT_TRUE(out);
    const OIIO::ImageSpec spec(image.width, image.height, 3, OIIO::TypeDesc::UINT16);
    ASSERT_TRUE(out->open(path, spec));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, image.rgb.data()));
    ASSERT_TRUE(out->close());
}

std::string error_reading(const std::string& path) {
    try {
        read_linear_image(path);
    } catch (const std::runtime_error& e) {
        return e.what();
    }
    return "(no error)";
}

TEST(ImageFiles, ACompletePngReadsBack) {
    const test::ScratchDirectory directory;
    const std::string path = (directory.path() / "ok.png").string();
    write_png(path, constant(float(1234 * code), 9, 5));
    const ImageShape shape = read_image_shape(path);
    EXPECT_EQ(shape.width, 9);
    EXPECT_EQ(shape.height, 5);
    EXPECT_EQ(shape.channels, 3);
    EXPECT_FLOAT_EQ(read_linear_image(path).rgb[7], float(1234 * code));
}

TEST(ImageFiles, TruncatedPngIsUnreadable) {
    const test::ScratchDirectory directory;
    const std::string path = (directory.path() / "whole.png").string();
    write_png(path, constant(0.5f, 96, 72));
    std::ifstream in(path, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    for (const size_t keep : {bytes.size() - 1, bytes.size() - 12, bytes.size() / 2, size_t(40)}) {
        const std::string cut = directory.write("cut.png", bytes.substr(0, keep));
        EXPECT_THAT(error_reading(cut), HasSubstr("truncated")) << "kept " << keep << " of " << bytes.size();
    }
}

TEST(ImageFiles, HugeHeaderIsRefusedBeforeAllocating) {
    const test::ScratchDirectory directory;
    const std::string path = directory.write("huge.png", png_claiming(65535, 65535));
    EXPECT_THAT(error_reading(path), HasSubstr("is 65535x65535; the limit is 65536 per side and 268435456 pixels"));
}

TEST(ImageFiles, DevicesFifosAndDirectoriesAreRefused) {
    const test::ScratchDirectory directory;
    EXPECT_THAT(error_reading("/dev/zero"), HasSubstr("'/dev/zero': it is a character device"));
    const std::string fifo = (directory.path() / "fifo.png").string();
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    EXPECT_THAT(error_reading(fifo), HasSubstr("it is a fifo"));  // and returns: it is never opened
    EXPECT_THAT(error_reading(directory.path().string()), HasSubstr("it is a directory"));
    EXPECT_THAT(error_reading((directory.path() / "missing.png").string()), StartsWith("cannot read"));
}

}  // namespace
}  // namespace whitted::reference
