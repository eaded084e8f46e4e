// SPDX-License-Identifier: MIT
#include "reference/file_colour.h"

#include "reference/compare.h"

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <stdexcept>
#include <vector>

namespace whitted::reference {
namespace {

enum class Transfer { unknown, linear, srgb, gamma };

struct Encoding {
    Transfer transfer = Transfer::unknown;
    double gamma = 1;
    bool p3 = false;
    bool primaries_known = true;
    std::string source;  ///< which metadata said so
};

bool contains(const std::string& text, const char* part) {
    return text.find(part) != std::string::npos;
}

/// Whitted's own words (DisplayEncoding::description in output/color_management.cpp).
Encoding from_whitted(const std::string& text, const std::string& source) {
    Encoding e;
    e.source = source;
    if (contains(text, "sRGB transfer"))
        e.transfer = Transfer::srgb;
    else if (contains(text, "gamma 2.2"))
        e.transfer = Transfer::gamma, e.gamma = 2.2;
    else if (contains(text, "gamma 2.4"))
        e.transfer = Transfer::gamma, e.gamma = 2.4;
    else if (contains(text, "linear"))
        e.transfer = Transfer::linear;
    e.p3 = contains(text, "P3-D65 primaries");
    e.primaries_known = e.p3 || contains(text, "Rec.709 primaries");
    return e;
}

/// The value of `key: ` on a line of a JPEG comment or TIFF description Whitted wrote.
std::string description_value(const std::string& description, const std::string& key) {
    const size_t at = description.find(key + ": ");
    if (at == std::string::npos) return "";
    const size_t start = at + key.size() + 2;
    return description.substr(start, description.find('\n', start) - start);
}

Encoding encoding_of(const OIIO::ImageSpec& spec, const std::string& format) {
    const std::string whitted = spec.get_string_attribute("whitted:encoding");
    if (!whitted.empty()) return from_whitted(whitted, "whitted:encoding");
    const std::string in_description =
        description_value(spec.get_string_attribute("ImageDescription"), "whitted:encoding");
    if (!in_description.empty()) return from_whitted(in_description, "whitted:encoding in the image description");
    Encoding e;
    if (spec.format.is_floating_point()) {
        e.transfer = Transfer::linear;
        e.source = format + " float values";
        // An EXR with other chromaticities than Rec.709 (someone else's ACEScg) is not ours to guess.
        const OIIO::ParamValue* c = spec.find_attribute("chromaticities", OIIO::TypeDesc(OIIO::TypeDesc::FLOAT, 8));
        if (c) {
            const float* v = static_cast<const float*>(c->data());
            const float rec709[8] = {0.64f, 0.33f, 0.30f, 0.60f, 0.15f, 0.06f, 0.3127f, 0.3290f};
            for (int i = 0; i < 8; ++i) e.primaries_known &= std::abs(v[i] - rec709[i]) < 1e-4f;
            e.source += ", Rec.709 chromaticities";
        } else {
            e.source += ", no chromaticities (taken as Rec.709)";
        }
        return e;
    }
    const std::string space = spec.get_string_attribute("oiio:ColorSpace");
    e.source = "OpenImageIO reports oiio:ColorSpace \"" + space + "\"";
    if (space == "linear" || space == "Linear") {
        e.transfer = Transfer::linear;
    } else if (space == "sRGB") {
        e.transfer = Transfer::srgb;
    } else if (space.rfind("Gamma", 0) == 0 || space.rfind("GammaCorrected", 0) == 0) {
        const double g = std::atof(space.substr(space.find_first_of("0123456789")).c_str());
        if (g > 0) e.transfer = Transfer::gamma, e.gamma = g;
    }
    return e;
}

double decode(const Encoding& e, double code) {
    switch (e.transfer) {
        case Transfer::srgb:
            return code <= 0.04045 ? code / 12.92 : std::pow((code + 0.055) / 1.055, 2.4);
        case Transfer::gamma:
            return std::pow(std::max(code, 0.0), e.gamma);
        case Transfer::linear:
        case Transfer::unknown:
            break;
    }
    return code;
}

}  // namespace

LinearImage read_as_linear_rec709(const std::string& path) {
    // What is not a regular image file, a truncated PNG and a header claiming more pixels than
    // the limits are refused here, before any pixel memory (read_image_shape).
    read_image_shape(path);
    OIIO::ImageSpec spec;
    std::string format;
    {
        auto in = OIIO::ImageInput::open(path);
        if (!in) throw std::runtime_error("cannot read '" + path + "': " + OIIO::geterror());
        spec = in->spec();
        format = in->format_name();
    }
    const Encoding e = encoding_of(spec, format);
    if (e.transfer == Transfer::unknown || !e.primaries_known)
        throw std::invalid_argument("cannot compare '" + path + "': its values are not known to be linear or a " +
                                    "plain transfer function of Rec.709 or P3 (" + e.source +
                                    "); write it with --view Raw or as an .exr");
    // The stored values as they are (RGB; a grey file's one channel repeated), then decoded.
    const Image stored = read_linear_image(path);
    LinearImage out;
    out.image.width = stored.width;
    out.image.height = stored.height;
    const size_t pixels = size_t(stored.width) * size_t(stored.height);
    out.image.rgb.resize(3 * pixels);
    // P3-D65 → Rec.709 (both D65), as commonly published.
    const double p3_to_709[3][3] = {
        {1.2249401, -0.2249404, 0.0}, {-0.0420569, 1.0420571, 0.0}, {-0.0196376, -0.0786361, 1.0982735}};
    for (size_t i = 0; i < pixels; ++i) {
        double linear[3];
        for (int ch = 0; ch < 3; ++ch) linear[ch] = decode(e, double(stored.rgb[3 * i + size_t(ch)]));
        for (int ch = 0; ch < 3; ++ch) {
            const double v =
                e.p3 ? p3_to_709[ch][0] * linear[0] + p3_to_709[ch][1] * linear[1] + p3_to_709[ch][2] * linear[2]
                     : linear[ch];
            out.image.rgb[3 * i + size_t(ch)] = float(v);
        }
    }
    const char* transfer = e.transfer == Transfer::linear ? "linear"
                           : e.transfer == Transfer::srgb ? "sRGB transfer"
                                                          : "gamma";
    out.meaning = std::string(transfer) +
                  (e.transfer == Transfer::gamma ? " " + std::to_string(e.gamma).substr(0, 3) : "") +
                  (e.p3 ? ", P3-D65 primaries" : ", Rec.709 primaries") + " (" + e.source + ")" +
                  (e.transfer == Transfer::linear && !e.p3 ? ": used as it is" : ": converted to linear Rec.709");
    return out;
}

}  // namespace whitted::reference
