// SPDX-License-Identifier: MIT
// The built-in OpenColorIO config: the sRGB display's Standard view is the IEC 61966-2-1 curve
// (1.055·x^(1/2.4) − 0.055 above the linear toe), Raw is the identity, and unknown names are
// refused with a message listing what exists.

#include "whitted/output/color_management.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <stdexcept>
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
    } catch (const std::runtime_error& e) {
        EXPECT_THAT(std::string(e.what()), HasSubstr("'P3-D65'"));
        EXPECT_THAT(std::string(e.what()), HasSubstr("displays: sRGB"));
    }
}

TEST_F(BuiltinConfig, UnknownViewListsViews) {
    try {
        const DisplayTransform transform("", "sRGB", "Filmic");
        FAIL() << "an unknown view was accepted";
    } catch (const std::runtime_error& e) {
        EXPECT_THAT(std::string(e.what()), HasSubstr("'Filmic'"));
        EXPECT_THAT(std::string(e.what()), HasSubstr("Standard"));
        EXPECT_THAT(std::string(e.what()), HasSubstr("Raw"));
    }
}

}  // namespace
}  // namespace whitted
