// SPDX-License-Identifier: MIT
#pragma once

// The Cornell CS4620 course's XML scene files (docs/course-format.md) → the same plain
// SceneDescription a Whitted scene file gives, with the course's conventions written out as
// Whitted scene keys (render.convention: course, ambient 0, ...), so that converting a course
// file to Whitted's YAML and rendering that gives the same pixels.

#include "scene/description.h"

#include <string>

namespace whitted {

/// Whether `path` names a course XML scene (by its extension, `.xml`).
bool is_course_xml_path(const std::string& path);

/// Reads a course XML scene. Throws InputError naming FILE:LINE:COL for malformed XML, unknown
/// elements or attributes, bad numbers and unknown shader references.
SceneDescription parse_course_xml_file(const std::string& path);
SceneDescription parse_course_xml_text(const std::string& text, const std::string& path);

}  // namespace whitted
