// SPDX-License-Identifier: MIT
#pragma once

#include "whitted/core/vec3.h"
#include "whitted/scene/description.h"

#include <cstdint>
#include <string>
#include <vector>

namespace whitted {

/// A triangle mesh as read from a Wavefront OBJ file (and its MTL), in the file's own space.
/// Vertices are unique (position, normal) pairs so that per-vertex normals index like positions.
struct MeshData {
    std::vector<float> positions;                ///< 3 per vertex
    std::vector<float> normals;                  ///< 3 per vertex, or empty
    std::vector<uint32_t> indices;               ///< 3 per triangle
    std::vector<int32_t> triangle_material;      ///< index into materials per triangle, −1 = none
    std::vector<MaterialDescription> materials;  ///< from the MTL: Ka→ka, Kd→kd, Ks→ks, Ns→p, illum 3→km=Ks
};

/// Loads an OBJ file (polygons are fanned into triangles). Throws InputError naming the file
/// (and line where the loader says) for missing files, bad indices and empty meshes.
/// `parts`: how many runs of lines are read at once (0: one per core for files of several
/// megabytes); the result, and any error, is the same whatever it is.
MeshData load_obj_mesh(const std::string& path, const SourceLocation& referenced_at, int parts = 0);

}  // namespace whitted
