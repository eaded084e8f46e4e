// SPDX-License-Identifier: MIT
#pragma once

#include "core/vec3.h"
#include "scene/description.h"

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace whitted {

/// std::allocator, except that a vector's `resize(n)` or `vector(n)` leaves new numbers
/// unwritten: the OBJ reader sizes its arrays from a first count and writes every element from
/// the thread that reads that run of lines, so the pages are first touched there, on every core,
/// not zeroed first on one (tens of megabytes of page faults for a million-triangle mesh).
template <class T>
struct UninitializedAllocator : std::allocator<T> {
    template <class U>
    struct rebind {
        using other = UninitializedAllocator<U>;
    };
    UninitializedAllocator() = default;
    template <class U>
    UninitializedAllocator(const UninitializedAllocator<U>&) noexcept {}  // NOLINT: as std::allocator's
    template <class U>
    void construct(U* p) noexcept {
        ::new (static_cast<void*>(p)) U;
    }
    template <class U, class... Args>
    void construct(U* p, Args&&... args) {
        ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
    }
};

/// Numbers a reader writes one by one into an array sized beforehand (UninitializedAllocator).
using FloatArray = std::vector<float, UninitializedAllocator<float>>;

/// A triangle mesh as read from a Wavefront OBJ file (and its MTL), in the file's own space.
/// Vertices are unique (position, normal) pairs so that per-vertex normals index like positions.
struct MeshData {
    FloatArray positions;                        ///< 3 per vertex
    FloatArray normals;                          ///< 3 per vertex, or empty
    std::vector<uint32_t> indices;               ///< 3 per triangle
    std::vector<int32_t> triangle_material;      ///< index into materials per triangle, −1 = none
    std::vector<MaterialDescription> materials;  ///< from the MTL: Ka→ka, Kd→kd, Ks→ks, Ns→p, illum 3→km=Ks
    /// What the loader did that the file did not ask for (faces given the default material),
    /// each "FILE:LINE:COL: text". The caller prints them (print_mesh_warnings) where they say
    /// something true of the render: not for a prototype whose every instance gives a material.
    std::vector<std::string> warnings;
};

/// Writes each of `mesh.warnings` to stderr as "whitted: warning: ...".
void print_mesh_warnings(const MeshData& mesh);

/// The name MeshData::materials gives the material of faces that have none (docs/scene-format.md
/// §3.6): Kd 0.6 grey, nothing else, as an MTL material with only `Kd 0.6 0.6 0.6`.
inline const char* const default_obj_material_name = "(default: no usemtl)";

/// Loads an OBJ file. Throws InputError naming the file (and line where the loader says) for
/// missing files, bad indices and empty meshes.
/// `parts`: how many runs of lines are read at once (0: one per core for files of several
/// megabytes); the result, and any error, is the same whatever it is.
/// `need_materials`: whether the mesh's materials come from its MTL files (the scene gives the
/// object no `material`). Then MTL errors and a `usemtl` of a material no MTL file defines are
/// errors, and faces without a material get the default one (with a warning). Otherwise no
/// MTL file is read and triangle_material is −1 throughout.
MeshData load_obj_mesh(const std::string& path, const SourceLocation& referenced_at, int parts = 0,
                       bool need_materials = true);

/// Whether no corner of the polygon turns against the others, seen in the polygon's own plane
/// (Newell's normal): then the fan from its first corner covers it exactly.
bool is_convex_polygon(const std::vector<Vec3>& corners);

/// Cuts a polygon (corners in order, planar or nearly so) into corners.size() − 2 triangles
/// that cover it, as corner numbers, 3 per triangle, each wound like the polygon. A convex
/// polygon gets the fan from its first corner; any other simple polygon is cut by ear clipping
/// in its own plane; collinear and repeated corners give triangles of no area.
std::vector<uint32_t> triangulate_polygon(const std::vector<Vec3>& corners);

}  // namespace whitted
