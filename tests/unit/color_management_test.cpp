// SPDX-License-Identifier: MIT
// The built-in colour config against closed-form values: the sRGB display's Standard view is
// the IEC 61966-2-1 curve (12.92·x up to 0.0031308, then 1.055·x^(1/2.4) − 0.055), exactly:
// computed in double and rounded to float once, for every value; Gamma 2.2 and BT.1886 are
// x^(1/2.2) and x^(1/2.4), Display P3 is the sRGB curve after the published Rec.709 → P3-D65
// matrix, every Raw view is the identity; each is recognised as what it is (the encoding the
// files declare), unknown names are refused with a message listing what exists, and the same
// config written out and read by OpenColorIO has the same names and encodings and, above the
// sRGB curve's linear toe, values within OpenColorIO's float arithmetic of the exact ones.

#include "output/color_management.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace whitted {
namespace {

using ::testing::HasSubstr;

// $OCIO would replace the built-in config; these tests are about the built-in one.
class BuiltinConfig : public ::testing::Test {
protected:
    void SetUp() override { ::unsetenv("OCIO"); }
};

double srgb_encode(double x) {
    return x <= 0.0031308 ? 12.92 * x : 1.055 * std::pow(x, 1 / 2.4) - 0.055;
}

TEST_F(BuiltinConfig, DefaultsAreSrgbStandard) {
    const DisplayTransform transform("", "", "");
    EXPECT_EQ(transform.config_source(), "built-in");
    EXPECT_EQ(transform.display(), "sRGB");
    EXPECT_EQ(transform.view(), "Standard");
}

TEST_F(BuiltinConfig, StandardViewIsTheSrgbCurve) {
    const DisplayTransform transform("", "", "");
    std::vector<float> rgb = {0.18f, 1.0f, 0.0f, 0.5f, 0.05f, 0.002f};
    const std::vector<float> linear = rgb;
    transform.apply(rgb.data(), rgb.size() / 3);
    EXPECT_NEAR(rgb[0], 0.46136, 1e-4);  // mid grey
    EXPECT_NEAR(rgb[1], 1.0, 1e-6);
    EXPECT_NEAR(rgb[2], 0.0, 1e-6);
    for (size_t k = 0; k < rgb.size(); ++k) EXPECT_NEAR(rgb[k], srgb_encode(linear[k]), 1e-4) << "value " << linear[k];
    EXPECT_NEAR(srgb_encode(0.18), 0.46136, 1e-5);  // the reference formula agrees with the number
}

// Bit for bit: every 97th float from 2^-40 to 16 (3.8 million, and the toe's break with its
// neighbours and white), through each Standard view of a Rec.709 display, is the formula in
// double rounded to float; a value at or below 0, or NaN, is code 0.
TEST_F(BuiltinConfig, StandardViewsAreTheFormulasRoundedOnce) {
    const std::pair<const char*, double (*)(double)> displays[] = {
        {"sRGB", srgb_encode},
        {"Gamma 2.2", [](double x) { return std::pow(x, 1 / 2.2); }},
        {"BT.1886", [](double x) { return std::pow(x, 1 / 2.4); }}};
    std::vector<float> values;
    // Positive floats are ordered as their bit patterns are.
    uint32_t bits = 0;
    const float first = std::ldexp(1.0f, -40), last = 16.0f;
    std::memcpy(&bits, &first, sizeof bits);
    for (float x = first; x < last; bits += 97, std::memcpy(&x, &bits, sizeof x)) values.push_back(x);
    for (const float x : {0.0031308f, std::nextafter(0.0031308f, 0.0f), std::nextafter(0.0031308f, 1.0f), 1.0f})
        values.push_back(x);
    while (values.size() % 3) values.push_back(0.5f);
    for (const auto& [display, formula] : displays) {
        std::vector<float> rgb = values;
        DisplayTransform("", display, "Standard").apply(rgb.data(), rgb.size() / 3);
        size_t differ = 0;
        for (size_t i = 0; i < values.size(); ++i)
            if (rgb[i] != float(formula(double(values[i]))) && ++differ <= 5)
                ADD_FAILURE() << display << " at " << values[i] << ": " << rgb[i] << " against "
                              << float(formula(double(values[i])));
        EXPECT_EQ(differ, 0u) << display << ", of " << values.size() << " values";
        // Runs of equal pixels (a background) between others: each pixel its own formula's.
        std::vector<float> runs;
        for (const float v : {0.25f, 0.25f, 0.25f, 0.002f, 0.25f, 0.25f, 0.7f, 0.7f})
            runs.insert(runs.end(), {v, v * 0.5f, 0.001f});
        const std::vector<float> linear_runs = runs;
        DisplayTransform("", display, "Standard").apply(runs.data(), runs.size() / 3);
        for (size_t i = 0; i < runs.size(); ++i)
            EXPECT_EQ(runs[i], float(formula(double(linear_runs[i])))) << display << " run value " << i;
        std::vector<float> dark = {0.0f, -0.0f, -1e-3f, -1.0f, NAN, -INFINITY};
        DisplayTransform("", display, "Standard").apply(dark.data(), 2);
        for (const float v : dark) EXPECT_EQ(v, 0.0f) << display;
    }
}

TEST_F(BuiltinConfig, RawViewIsIdentity) {
    const DisplayTransform transform("", "sRGB", "Raw");
    std::vector<float> rgb = {0.18f, 0.5f, 0.9f, 0.0f, 0.001f, 0.75f};
    const std::vector<float> linear = rgb;
    transform.apply(rgb.data(), rgb.size() / 3);
    for (size_t k = 0; k < rgb.size(); ++k) EXPECT_FLOAT_EQ(rgb[k], linear[k]);
}

TEST_F(BuiltinConfig, UnknownDisplayListsDisplays) {
    try {
        const DisplayTransform transform("", "P3-D65", "");
        FAIL() << "an unknown display was accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_THAT(std::string(e.what()), HasSubstr("'P3-D65'"));
        EXPECT_THAT(std::string(e.what()), HasSubstr("displays: sRGB, Gamma 2.2, BT.1886, Display P3"));
    }
}

TEST_F(BuiltinConfig, UnknownViewListsViews) {
    try {
        const DisplayTransform transform("", "sRGB", "Filmic");
        FAIL() << "an unknown view was accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_THAT(std::string(e.what()), HasSubstr("'Filmic'"));
        EXPECT_THAT(std::string(e.what()), HasSubstr("Standard"));
        EXPECT_THAT(std::string(e.what()), HasSubstr("Raw"));
    }
}

TEST_F(BuiltinConfig, PowerLawDisplays) {
    for (const auto& [display, gamma] : {std::pair<const char*, double>{"Gamma 2.2", 2.2}, {"BT.1886", 2.4}}) {
        const DisplayTransform transform("", display, "Standard");
        std::vector<float> rgb = {0.18f, 1.0f, 0.0f, 0.5f, 0.05f, 0.002f};
        const std::vector<float> linear = rgb;
        transform.apply(rgb.data(), rgb.size() / 3);
        for (size_t k = 0; k < rgb.size(); ++k)
            EXPECT_NEAR(rgb[k], std::pow(double(linear[k]), 1 / gamma), 1e-4) << display << " at " << linear[k];
        EXPECT_EQ(transform.encoding().primaries, DisplayEncoding::Primaries::rec709) << display;
    }
    EXPECT_EQ(DisplayTransform("", "Gamma 2.2", "").encoding().transfer, DisplayEncoding::Transfer::gamma22);
    EXPECT_EQ(DisplayTransform("", "BT.1886", "").encoding().transfer, DisplayEncoding::Transfer::gamma24);
}

TEST_F(BuiltinConfig, DisplayP3IsTheSrgbCurveOnP3Primaries) {
    // Rec.709 → P3-D65 (both D65, so no adaptation), as commonly published to seven places.
    const double to_p3[3][3] = {
        {0.8224621, 0.1775380, 0.0000000}, {0.0331941, 0.9668058, 0.0000000}, {0.0170827, 0.0723974, 0.9105199}};
    const DisplayTransform transform("", "Display P3", "Standard");
    const float colours[][3] = {{0.5f, 0.2f, 0.1f}, {0.0f, 0.0f, 0.8f}, {0.18f, 0.18f, 0.18f}, {1.0f, 0.0f, 0.0f}};
    for (const auto& c : colours) {
        std::vector<float> rgb(c, c + 3);
        transform.apply(rgb.data(), 1);
        for (int k = 0; k < 3; ++k) {
            const double p3 = to_p3[k][0] * double(c[0]) + to_p3[k][1] * double(c[1]) + to_p3[k][2] * double(c[2]);
            EXPECT_NEAR(rgb[size_t(k)], srgb_encode(p3), 2e-4) << "channel " << k << " of " << c[0] << "," << c[1];
        }
    }
    EXPECT_EQ(transform.encoding().transfer, DisplayEncoding::Transfer::srgb);
    EXPECT_EQ(transform.encoding().primaries, DisplayEncoding::Primaries::display_p3);
}

TEST_F(BuiltinConfig, EveryRawViewIsIdentityAndDeclaredLinear) {
    for (const char* display : {"sRGB", "Gamma 2.2", "BT.1886", "Display P3"}) {
        const DisplayTransform transform("", display, "Raw");
        std::vector<float> rgb = {0.18f, 0.5f, 0.9f, 0.0f, 0.001f, 0.75f};
        const std::vector<float> linear = rgb;
        transform.apply(rgb.data(), rgb.size() / 3);
        for (size_t k = 0; k < rgb.size(); ++k) EXPECT_FLOAT_EQ(rgb[k], linear[k]) << display;
        EXPECT_EQ(transform.encoding().transfer, DisplayEncoding::Transfer::linear) << display;
        EXPECT_EQ(transform.encoding().primaries, DisplayEncoding::Primaries::rec709) << display;
        EXPECT_EQ(transform.colorspace(), "Raw");
    }
}

// The built-in config as OpenColorIO reads it back: every display and view has the same names,
// colour space and encoding; the values agree to within 4 float ulps above the sRGB curve's
// linear toe. (In the toe OpenColorIO's ExponentWithLinearTransform meets the power segment at
// a tangent, slope 12.9232 from 0.00303993, where IEC 61966-2-1 and the program use 12.92 up to
// 0.0031308: 0.02 % apart there.)
TEST_F(BuiltinConfig, WrittenConfigLoadsWithTheSameNamesAndValues) {
    const std::string path = ::testing::TempDir() + "whitted-builtin-test.ocio";
    {
        std::FILE* file = std::fopen(path.c_str(), "w");
        ASSERT_NE(file, nullptr);
        const std::string text = DisplayTransform::builtin_config_text();
        ASSERT_EQ(std::fwrite(text.data(), 1, text.size(), file), text.size());
        std::fclose(file);
    }
    for (const char* display : {"sRGB", "Gamma 2.2", "BT.1886", "Display P3"}) {
        for (const char* view : {"Standard", "Raw"}) {
            const DisplayTransform builtin("", display, view), loaded(path, display, view);
            std::vector<float> a = {0.18f, 0.5f, 0.9f, 0.02f, 0.7f, 0.3f, 0.004f, 1.0f, 0.0035f}, b = a;
            builtin.apply(a.data(), 3);
            loaded.apply(b.data(), 3);
            for (size_t k = 0; k < a.size(); ++k) {
                const float ulp = std::nextafter(std::fabs(a[k]), INFINITY) - std::fabs(a[k]);
                EXPECT_NEAR(a[k], b[k], 4 * ulp) << display << "/" << view << " value " << k;
            }
            EXPECT_EQ(builtin.config_source(), "built-in");
            EXPECT_EQ(loaded.config_source(), path);
            EXPECT_EQ(loaded.config_name(), builtin.config_name());
            EXPECT_EQ(loaded.display(), builtin.display());
            EXPECT_EQ(loaded.view(), builtin.view());
            EXPECT_EQ(loaded.colorspace(), builtin.colorspace()) << display << "/" << view;
            EXPECT_EQ(loaded.encoding().transfer, builtin.encoding().transfer) << display << "/" << view;
            EXPECT_EQ(loaded.encoding().primaries, builtin.encoding().primaries) << display << "/" << view;
        }
    }
    const DisplayTransform defaults("", "", ""), loaded_defaults(path, "", "");
    EXPECT_EQ(loaded_defaults.display(), defaults.display());
    EXPECT_EQ(loaded_defaults.view(), defaults.view());
    for (const auto& [display, view] : {std::pair<const char*, const char*>{"P3-D65", ""}, {"sRGB", "Filmic"}}) {
        std::string from_builtin, from_file;
        try {
            const DisplayTransform transform("", display, view);
        } catch (const std::invalid_argument& e) {
            from_builtin = e.what();
        }
        try {
            const DisplayTransform transform(path, display, view);
        } catch (const std::invalid_argument& e) {
            from_file = e.what();
        }
        EXPECT_FALSE(from_builtin.empty()) << display << "/" << view;
        // The same words, but for where the config came from.
        const auto without_source = [](std::string text, const std::string& source) {
            const size_t at = text.find(source);
            return at == std::string::npos ? text : text.erase(at, source.size());
        };
        EXPECT_EQ(without_source(from_builtin, "built-in"), without_source(from_file, path));
    }
    std::remove(path.c_str());
}

// A config file, or $OCIO set since, is read again each time (it may have changed); the
// built-in config gives the same values every time.
TEST_F(BuiltinConfig, AConfigFileIsReadEachTime) {
    const std::string path = ::testing::TempDir() + "whitted-reread-test.ocio";
    const auto write_config = [&](const std::string& first_display) {
        std::string text = DisplayTransform::builtin_config_text();
        const std::string active = "active_displays: [sRGB, Gamma 2.2, BT.1886, Display P3]";
        const size_t at = text.find(active);
        ASSERT_NE(at, std::string::npos) << text;
        text.replace(at, active.size(),
                     "active_displays: [" + first_display + (first_display == "sRGB" ? ", Gamma 2.2" : ", sRGB") +
                         ", BT.1886, Display P3]");
        std::FILE* file = std::fopen(path.c_str(), "w");
        ASSERT_NE(file, nullptr);
        ASSERT_EQ(std::fwrite(text.data(), 1, text.size(), file), text.size());
        std::fclose(file);
    };
    const DisplayTransform first("", "", ""), again("", "", "");
    EXPECT_EQ(again.display(), "sRGB");
    std::vector<float> a = {0.18f, 0.5f, 0.002f}, b = a;
    first.apply(a.data(), 1);
    again.apply(b.data(), 1);
    for (size_t k = 0; k < a.size(); ++k) EXPECT_EQ(a[k], b[k]);

    write_config("sRGB");
    EXPECT_EQ(DisplayTransform(path, "", "").display(), "sRGB");
    write_config("Gamma 2.2");
    EXPECT_EQ(DisplayTransform(path, "", "").display(), "Gamma 2.2");
    ::setenv("OCIO", path.c_str(), 1);
    const DisplayTransform from_env("", "", "");
    ::unsetenv("OCIO");
    EXPECT_EQ(from_env.config_source(), "$OCIO=" + path);
    EXPECT_EQ(from_env.display(), "Gamma 2.2");
    EXPECT_EQ(DisplayTransform("", "", "").display(), "sRGB");
    std::remove(path.c_str());
}

TEST_F(BuiltinConfig, UnreadableConfigIsAUsageError) {
    EXPECT_THROW(DisplayTransform("/etc/passwd", "", ""), std::invalid_argument);
    EXPECT_THROW(DisplayTransform("/nonexistent/config.ocio", "", ""), std::invalid_argument);
    EXPECT_THROW(DisplayTransform("/", "", ""), std::invalid_argument);
}

}  // namespace
}  // namespace whitted
