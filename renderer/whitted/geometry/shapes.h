// SPDX-License-Identifier: MIT
#pragma once

// Ray–shape intersection in double precision. Each function finds the nearest hit with
// t_min < t < t_max and returns its distance and outward (not yet ray-facing) normal.

#include "whitted/core/ray.h"
#include "whitted/scene/scene.h"

namespace whitted {

struct ShapeHit {
    double t = 0;
    Vec3 normal;   ///< outward geometric normal, world space, not necessarily unit
    double u = 0;  ///< triangles: barycentric weight of vertex 1
    double v = 0;  ///< triangles: barycentric weight of vertex 2
    /// Boxes: the face is not the one the ray crosses at `t` but a steeper one within 1e-6,
    /// chosen by POV-Ray's edge rule (intersect_box); the accelerator lets another box's plain
    /// hit at the very same t win over it, as POV-Ray's order of testing does.
    bool edge_tie = false;
};

bool intersect_sphere(const Sphere& sphere, const Ray& ray, double t_min, double t_max, ShapeHit& hit);
/// The slab test. `rule` exact: no tolerance but t_min; a ray through an edge or corner gets the
/// face of the last axis it crosses there. `rule` povray: POV-Ray 3.7's constants and edge rule
/// (docs/pov-model.md §3, "Box edges"), for `whitted check`.
bool intersect_box(const Box& box, const Ray& ray, double t_min, double t_max, ShapeHit& hit,
                   Intersection rule = Intersection::exact);
/// The side as a quadric in the cone's own frame (the axis and the plane across it), then the
/// caps as discs unless the cone is open; the nearest hit. Exact in double: no tolerance but
/// t_min. The side's normal is the gradient of |p⊥| − r(s), scaled by r(s).
bool intersect_cone(const Cone& cone, const Ray& ray, double t_min, double t_max, ShapeHit& hit);
bool intersect_plane(const Plane& plane, const Ray& ray, double t_min, double t_max, ShapeHit& hit);
/// Möller–Trumbore; the normal is (v1 − v0) × (v2 − v0). `edge_margin` widens the triangle by
/// that much in barycentric terms (u, v ≥ −margin, u + v ≤ 1 + margin): with a small margin a
/// ray along an edge that two triangles share meets at least one of them despite double's
/// rounding, which the exact test alone does not promise.
bool intersect_triangle(const Vec3& v0, const Vec3& v1, const Vec3& v2, const Ray& ray, double t_min, double t_max,
                        ShapeHit& hit, double edge_margin = 0);
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

/// World-space bounds of a sphere, box or cone (its object-space box pushed through the transform).
void world_bounds(const Sphere& sphere, Vec3& lo, Vec3& hi);
void world_bounds(const Box& box, Vec3& lo, Vec3& hi);
void world_bounds(const Cone& cone, Vec3& lo, Vec3& hi);
/// World-space bounds of the axis-aligned box [lo, hi] of an object's space under `to_world`
/// (the extremes of its eight corners).
void world_bounds(const Transform& to_world, const Vec3& lo, const Vec3& hi, Vec3& out_lo, Vec3& out_hi);

}  // namespace whitted
