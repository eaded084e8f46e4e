// SPDX-License-Identifier: MIT
#pragma once

// Eric Haines' Neutral File Format (NFF), the format of the Standard Procedural Databases
// (docs/nff.md) → the same plain SceneDescription a Whitted scene file gives. Each NFF entity
// becomes the Whitted object that means the same: `s` a sphere, `c` an open cylinder or cone,
// `p` and `pp` triangulated polygons gathered into inline meshes (flat, or smooth with the
// patch's vertex normals), `f` a named material, `l` a point light, `v` the camera and image.

#include "scene/description.h"

#include <string>
#include <string_view>

namespace whitted {

/// Whether `path` names an NFF scene (by its extension, `.nff`, in any case).
bool is_nff_path(const std::string& path);

/// Reads an NFF scene. Throws InputError naming FILE:LINE:COL for unknown entities, missing or
/// malformed numbers, polygons of fewer than three corners and everything beyond the limits of
/// docs/nff.md; values that Whitted's own scene format would refuse are left to the validator,
/// which names the NFF token they came from. With a `sink`, each object goes there as soon as it
/// is complete (a mesh when its fill ends) and `objects` stays empty (description.h, ObjectSink).
SceneDescription parse_nff_file(const std::string& path, const ObjectSink* sink = nullptr);
SceneDescription parse_nff_text(std::string_view text, const std::string& path, const ObjectSink* sink = nullptr);

}  // namespace whitted
