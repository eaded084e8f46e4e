// SPDX-License-Identifier: MIT
#pragma once

#include <memory>
#include <string>

namespace whitted {

/// Turns scene-linear RGB into display-referred RGB through OpenColorIO.
///
/// The config comes from `config_path` when given, else from $OCIO, else from the built-in
/// config (OCIO 2.1 ships none): scene_linear = linear Rec.709, an "sRGB" display with the
/// views "Standard" (the sRGB curve: gamma 2.4, offset 0.055) and "Raw".
class DisplayTransform {
public:
    /// Empty `display`/`view` mean the config's defaults. Throws std::runtime_error with a clear
    /// message for an unreadable config or unknown names (the message lists the known ones).
    DisplayTransform(const std::string& config_path, const std::string& display, const std::string& view);
    ~DisplayTransform();

    /// In place, `pixel_count` packed RGB float pixels; large buffers on all cores.
    void apply(float* rgb, size_t pixel_count) const;

    /// Where the config came from ("built-in", a path, or "$OCIO=path"), and what was picked.
    const std::string& config_source() const { return m_source; }
    const std::string& display() const { return m_display; }
    const std::string& view() const { return m_view; }

    /// The built-in config, serialised (docs and tests use it).
    static std::string builtin_config_text();

private:
    struct Impl;
    std::unique_ptr<Impl> m_impl;
    std::string m_source, m_display, m_view;
};

}  // namespace whitted
