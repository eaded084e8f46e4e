// SPDX-License-Identifier: MIT
#pragma once

#include "scene/mesh_file.h"

#include <string>

namespace whitted {

/// Loads a mesh in the Cornell CS4620 course's `.msh` format (docs/course-format.md): the vertex
/// count, the triangle count, then the sections `vertices` (3 numbers per vertex), `triangles`
/// (3 zero-based indices each) and, optionally, `normals` (3 per vertex) and `texcoords` (2 per
/// vertex, read and ignored). Every mistake is an InputError at FILE.msh:LINE:COL.
MeshData load_msh_mesh(const std::string& path, const SourceLocation& referenced_at);

}  // namespace whitted
