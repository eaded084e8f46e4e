// SPDX-License-Identifier: MIT
#pragma once

#include "output/color_management.h"
#include "output/format_plugins.h"

#include <string>

/// OpenColorIO (with yaml-cpp, pystring and Imath, which it brings) is the
/// dearest library the program would load at start-up, about as dear as Embree and TBB together
/// (docs/performance.md, "Start-up"), and an EXR render, `whitted --version`, a scene check and
/// a file written with the built-in config (builtin_config.h) need none of it. So
/// DisplayTransform's OpenColorIO side is a plug-in, lib/libwhitted_ocio.so, loaded the first
/// time a config file is read or the built-in config is written out or listed (core/plugin.h
/// says where it is looked for). Like the writers' plug-ins (format_plugins.h) it exports C
/// functions of C++ signatures: it is built with the program by the same compiler, so the types
/// and exceptions cross as they are.
namespace whitted {

/// whitted_ocio_display_transform: throws as DisplayTransform's constructor documents.
using MakeDisplayTransformFunction = void (*)(const std::string& config_path, const std::string& display,
                                              const std::string& view, DisplayTransformParts& parts);
/// whitted_ocio_builtin_config_text.
using BuiltinConfigTextFunction = void (*)(std::string& text);
/// whitted_ocio_describe_config.
using DescribeConfigFunction = void (*)(const std::string& config_path, std::string& text);

}  // namespace whitted
