// SPDX-License-Identifier: MIT
// DisplayTransform's side in the program: OpenColorIO itself is reached through the plug-in
// lib/libwhitted_ocio.so (ocio_display.cpp; ocio_plugin.h says why).
#include "output/color_management.h"

#include "core/plugin.h"
#include "output/ocio_plugin.h"

#include <stdexcept>
#include <utility>

namespace whitted {
namespace {

/// The plug-in's function `name`; a plug-in that cannot be loaded is reported as a usage error
/// before any work, as the writers' plug-ins are (format_writer).
void* ocio_symbol(const char* name) {
    try {
        return plugin_symbol("libwhitted_ocio.so", name,
                             "OpenColorIO's display transform, needed to write .png, .jpg and .tif files");
    } catch (const std::runtime_error& e) {
        throw std::invalid_argument(e.what());
    }
}

}  // namespace

DisplayTransform::DisplayTransform(const std::string& config_path, const std::string& display,
                                   const std::string& view) {
    DisplayTransformParts parts;
    reinterpret_cast<MakeDisplayTransformFunction>(ocio_symbol("whitted_ocio_display_transform"))(config_path, display,
                                                                                                  view, parts);
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
