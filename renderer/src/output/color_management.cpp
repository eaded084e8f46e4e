// SPDX-License-Identifier: MIT
// DisplayTransform's side in the program: the built-in config is computed here
// (builtin_config.cpp); OpenColorIO, for a config file, is reached through the plug-in
// lib/libwhitted_ocio.so (ocio_display.cpp; ocio_plugin.h says why).
#include "output/color_management.h"

#include "core/plugin.h"
#include "output/builtin_config.h"
#include "output/ocio_plugin.h"

#include <cstdlib>
#include <stdexcept>
#include <utility>

namespace whitted {
namespace {

/// The plug-in's function `name`; a plug-in that cannot be loaded is reported as a usage error
/// before any work, as the writers' plug-ins are (format_writer).
void* ocio_symbol(const char* name) {
    try {
        return plugin_symbol("libwhitted_ocio.so", name,
                             "OpenColorIO, needed to read a colour config file (--ocio-config or $OCIO) and to "
                             "write or list the built-in config");
    } catch (const std::runtime_error& e) {
        throw std::invalid_argument(e.what());
    }
}

/// The built-in config is chosen when no config file is named and $OCIO is unset or empty.
bool uses_builtin_config(const std::string& config_path) {
    const char* env = std::getenv("OCIO");
    return config_path.empty() && (!env || !*env);
}

DisplayTransformParts make_parts(const std::string& config_path, const std::string& display, const std::string& view) {
    if (uses_builtin_config(config_path)) return builtin_display_transform(display, view);
    DisplayTransformParts parts;
    reinterpret_cast<MakeDisplayTransformFunction>(ocio_symbol("whitted_ocio_display_transform"))(config_path, display,
                                                                                                  view, parts);
    return parts;
}

}  // namespace

DisplayTransform::DisplayTransform(const std::string& config_path, const std::string& display,
                                   const std::string& view) {
    DisplayTransformParts parts = make_parts(config_path, display, view);
    m_apply = std::move(parts.apply);
    m_source = std::move(parts.source);
    m_config_name = std::move(parts.config_name);
    m_display = std::move(parts.display);
    m_view = std::move(parts.view);
    m_colorspace = std::move(parts.colorspace);
    m_encoding = parts.encoding;
}

DisplayTransform::~DisplayTransform() = default;

void DisplayTransform::apply(float* rgb, size_t pixel_count) const {
    m_apply(rgb, pixel_count);
}

std::string DisplayTransform::builtin_config_text() {
    std::string text;
    reinterpret_cast<BuiltinConfigTextFunction>(ocio_symbol("whitted_ocio_builtin_config_text"))(text);
    return text;
}

std::string DisplayTransform::describe_config(const std::string& config_path) {
    std::string text;
    reinterpret_cast<DescribeConfigFunction>(ocio_symbol("whitted_ocio_describe_config"))(config_path, text);
    return text;
}

}  // namespace whitted
