// SPDX-License-Identifier: MIT
#pragma once

#include <cstddef>
#include <functional>
#include <string>

namespace whitted {

/// What the code values of a display-referred file mean, as far as other programs can be told:
/// found by running the display transform on test values (DisplayTransform::encoding), so it
/// holds for any config, not only the built-in one.
struct DisplayEncoding {
    enum class Transfer { unknown, linear, srgb, gamma22, gamma24 };
    enum class Primaries { unknown, rec709, display_p3 };
    Transfer transfer = Transfer::unknown;
    Primaries primaries = Primaries::unknown;

    bool known() const { return transfer != Transfer::unknown && primaries != Primaries::unknown; }
    /// E.g. "sRGB transfer (IEC 61966-2-1), Rec.709 primaries, D65 white".
    std::string description() const;
};

/// Display-linear light → display code by `transfer` (the exact formulas: IEC 61966-2-1 for
/// sRGB, pure powers for the gammas; linear and unknown leave the value as it is).
double encode(DisplayEncoding::Transfer transfer, double linear);
/// The inverse of encode().
double decode(DisplayEncoding::Transfer transfer, double code);

/// What makes a DisplayTransform: from the built-in config (builtin_config.h) or from
/// OpenColorIO (the plug-in, ocio_plugin.h).
struct DisplayTransformParts {
    /// In place, packed RGB float pixels; large buffers on all cores.
    std::function<void(float* rgb, size_t pixel_count)> apply;
    std::string source, config_name, display, view, colorspace;
    DisplayEncoding encoding;
};

/// Turns scene-linear RGB into display-referred RGB.
///
/// The config comes from `config_path` when given, else from $OCIO, else it is the built-in
/// config (OCIO 2.1 ships none; docs/colour.md describes it): scene_linear = linear Rec.709,
/// displays sRGB, Gamma 2.2, BT.1886 and Display P3, each with the views Standard and Raw. The
/// built-in config's displays are closed-form and computed here exactly (builtin_config.h); a
/// config file goes through OpenColorIO, loaded (as the plug-in lib/libwhitted_ocio.so,
/// output/ocio_plugin.h) the first time one is made.
class DisplayTransform {
public:
    /// Empty `display`/`view` mean the config's defaults. Throws std::invalid_argument (a usage
    /// error) for an unreadable config or unknown names (the message lists the known ones), and
    /// std::runtime_error when OCIO cannot build the transform; std::invalid_argument naming the
    /// plug-in when a config file is to be read and the plug-in cannot be loaded.
    DisplayTransform(const std::string& config_path, const std::string& display, const std::string& view);
    ~DisplayTransform();

    /// In place, `pixel_count` packed RGB float pixels; large buffers on all cores.
    void apply(float* rgb, size_t pixel_count) const;

    /// Where the config came from ("built-in", a path, or "$OCIO=path"), and what was picked.
    const std::string& config_source() const { return m_source; }
    /// The config's name (its `name:`), empty when it has none.
    const std::string& config_name() const { return m_config_name; }
    const std::string& display() const { return m_display; }
    const std::string& view() const { return m_view; }
    /// The OCIO colour space of the file's values (the view's colour space).
    const std::string& colorspace() const { return m_colorspace; }
    const DisplayEncoding& encoding() const { return m_encoding; }

    /// The built-in config, serialised by OpenColorIO (`whitted colour --write-config`, docs and
    /// tests).
    static std::string builtin_config_text();
    /// Every display and view of a config (chosen as the constructor does) with the colour
    /// space each view writes and what that means: `whitted colour --list`.
    static std::string describe_config(const std::string& config_path);

private:
    std::function<void(float*, size_t)> m_apply;
    std::string m_source, m_config_name, m_display, m_view, m_colorspace;
    DisplayEncoding m_encoding;
};

}  // namespace whitted
