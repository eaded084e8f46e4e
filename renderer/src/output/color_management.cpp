// SPDX-License-Identifier: MIT
// DisplayTransform's side in the program: OpenColorIO itself is reached through the plug-in
// lib/libwhitted_ocio.so (ocio_display.cpp; ocio_plugin.h says why).
#include "output/color_management.h"

#include "core/plugin.h"
#include "output/ocio_plugin.h"

#include <cstdlib>
#include <map>
#include <mutex>
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

/// The built-in config is chosen when no config file is named and $OCIO is unset or empty.
bool uses_builtin_config(const std::string& config_path) {
    const char* env = std::getenv("OCIO");
    return config_path.empty() && (!env || !*env);
}

/// What the plug-in made of the built-in config for a (display, view) request. That config
/// cannot change while the process runs, and a render makes its display transform twice (when
/// it checks its options, before any work, and again when it writes), a Python session once
/// per image: building it again cost about 0.4 ms of CPU each time (docs/performance.md,
/// "Start-up"). A config file is read again every time: it may have changed. Never destroyed:
/// its processors belong to OpenColorIO, whose own statics may be gone at exit.
struct BuiltinTransforms {
    std::mutex mutex;
    std::map<std::pair<std::string, std::string>, DisplayTransformParts> made;
};

BuiltinTransforms& builtin_transforms() {
    static auto* transforms = new BuiltinTransforms;
    return *transforms;
}

DisplayTransformParts make_parts(const std::string& config_path, const std::string& display, const std::string& view) {
    const bool builtin = uses_builtin_config(config_path);
    if (builtin) {
        BuiltinTransforms& transforms = builtin_transforms();
        const std::lock_guard lock(transforms.mutex);
        if (const auto it = transforms.made.find({display, view}); it != transforms.made.end()) return it->second;
    }
    DisplayTransformParts parts;
    reinterpret_cast<MakeDisplayTransformFunction>(ocio_symbol("whitted_ocio_display_transform"))(config_path, display,
                                                                                                  view, parts);
    if (builtin) {
        BuiltinTransforms& transforms = builtin_transforms();
        const std::lock_guard lock(transforms.mutex);
        transforms.made.emplace(std::make_pair(display, view), parts);
    }
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
