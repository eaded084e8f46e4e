// SPDX-License-Identifier: MIT
#pragma once

// SceneDescription → a Whitted scene file (format v1, YAML). Every value is written, defaults
// included, with the shortest decimal that reads back as the same double, so that the file
// parses to the same description and renders the same pixels; `whitted convert course.xml
// scene.yaml` uses it to turn a course scene into Whitted's own format.

#include "scene/description.h"

#include <string>

namespace whitted::yaml {

/// The scene as YAML text. `output_path`: where the text will be written; mesh file paths are
/// written relative to its folder.
std::string scene_to_yaml(const SceneDescription& scene, const std::string& output_path);

/// Writes the file atomically (complete or not at all).
void write_yaml_file(const SceneDescription& scene, const std::string& path);

}  // namespace whitted::yaml
