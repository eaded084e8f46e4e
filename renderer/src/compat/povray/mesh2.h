// SPDX-License-Identifier: MIT
#pragma once

// POV-Ray 3.7's mesh2: its single-precision triangle test and smooth normal, and the vertex
// normals as it holds them. `render.intersection: povray` (what `whitted check` renders with)
// decides mesh hits this way, so that both renderers agree where a ray grazes a triangle or
// runs along an edge; the exact rule uses intersect_triangle (geometry/shapes.h). Facts from
// POV-Ray's source (triangle.cpp, mesh.cpp, parse.cpp); the code is Whitted's own.

#include "core/vec3.h"
#include "geometry/shapes.h"
#include "scene/scene.h"

#include <vector>

namespace whitted {

/// POV-Ray's own test for a triangle of a mesh2, so that Whitted decides triangle hits as it
/// does (docs/pov-model.md §3). p1, p2, p3 are the triangle's float vertices in the mesh2's
/// space, in the order of its face; origin and direction are the ray there (POV-Ray's own ray:
/// the direction unit length). The plane is kept in single precision, its unit normal and its
/// distance from the origin each rounded to float; the ray meets that plane at `depth` (along
/// `direction`), which must be at least 1e-6 and at most 1e7, else false. `inside`: whether the
/// point there lies inside the triangle as seen along the normal's largest axis, by POV-Ray's
/// three edge tests in double. A ray within 1e-10 of parallel to the plane (in that float
/// normal) never meets it. For a ray at a grazing angle θ the float plane moves the point along
/// the ray by up to about ulp(distance) / θ: at 1e-4 rad and coordinates near 5, by 5e-3.
bool intersect_mesh2_triangle(const Vec3& p1, const Vec3& p2, const Vec3& p3, const Vec3& origin, const Vec3& direction,
                              double& depth, bool& inside);
/// POV-Ray's smooth normal for a mesh2 triangle (vertices p1, p2, p3 and their unit float
/// normals n1, n2, n3, in the face's order) at `point`, before it is made unit length: the
/// barycentric blend of the lecture, computed POV-Ray's way (a float vector across the edge
/// p2 p3 gives the weight u of that edge, the largest axis of p3 − p2 the position v along it,
/// and n1 + u (n2 − n1 + v (n3 − n2)); n1 itself where u < 1e-10), so that a mirror ray
/// leaving at a grazing angle leaves as POV-Ray's does.
Vec3 mesh2_smooth_normal(const Vec3& p1, const Vec3& p2, const Vec3& p3, const Vec3& n1, const Vec3& n2, const Vec3& n3,
                         const Vec3& point);

/// Triangle `prim` of `mesh` tested as POV-Ray tests the converter's mesh2 (render.intersection:
/// povray): intersect_mesh2_triangle on the float offsets from the mesh's origin, with the ray
/// moved by −origin in double (the mesh2's `translate`), hit where it lies inside and within
/// (ray.t_min, ray.t_max). For a prototype's triangle (`instanced`) the ray is in the
/// prototype's space with the world's t, and POV-Ray makes its direction unit length first.
/// It differs from the exact test where a ray grazes a triangle (the single-precision plane
/// moves the hit along the ray by up to 5e-3, past the shadow window) or passes within about
/// 1e-9 of an edge (the float planes of two neighbours can leave a crack between them, or
/// overlap): docs/pov-model.md §3, "Mesh triangles". hit.normal is (v1 − v0) × (v2 − v0); u and
/// v are 0, POV-Ray's smooth normal being computed from the point (MeshAsPovray::smooth_normal).
bool intersect_mesh2(const TriangleMesh& mesh, uint32_t prim, const Ray& ray, bool instanced, ShapeHit& hit);

/// Whether a mesh is decided as POV-Ray decides it (the accelerator's hit_triangle_in_double)
/// and, if so, its vertex normals as POV-Ray holds them: made unit length again as they are
/// read, then stored as floats (POV-Ray's parse.cpp). Computed once, not at each hit.
struct MeshAsPovray {
    bool decided = false;
    std::vector<float> normals;  ///< 3 per vertex; empty unless decided and the mesh has normals

    MeshAsPovray(const TriangleMesh& mesh, Intersection rule);

    /// POV-Ray's smooth normal of triangle `prim` at `point`, the hit in the mesh's space, from
    /// the normals as held here (mesh2_smooth_normal), made unit length. False where the
    /// triangle is shaded flat (shaded_smooth) or the blend has length 0. Only for a mesh
    /// `decided`.
    bool smooth_normal(const TriangleMesh& mesh, uint32_t prim, const Vec3& point, Convention convention,
                       Vec3& out) const;
};

}  // namespace whitted
