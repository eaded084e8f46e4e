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
bool intersect_box(const Box& box, const Ray& ray, double t_min, double t_max, ShapeHit& hit);
bool intersect_plane(const Plane& plane, const Ray& ray, double t_min, double t_max, ShapeHit& hit);
/// Möller–Trumbore; the normal is (v1 − v0) × (v2 − v0).
bool intersect_triangle(const Vec3& v0, const Vec3& v1, const Vec3& v2, const Ray& ray, double t_min, double t_max,
                        ShapeHit& hit);
/// Where the ray's line meets the triangle's plane, with the barycentric weights clamped onto
/// the triangle (so the shading normal is interpolated from inside it), whatever t is: for a
/// hit that a float test found just over an edge that the double test rejects. False only when
/// the ray is parallel to the plane (or the triangle is degenerate).
bool hit_triangle_plane(const Vec3& v0, const Vec3& v1, const Vec3& v2, const Ray& ray, ShapeHit& hit);

/// World-space bounds of a sphere or box (its object-space box pushed through the transform).
void world_bounds(const Sphere& sphere, Vec3& lo, Vec3& hi);
void world_bounds(const Box& box, Vec3& lo, Vec3& hi);
/// World-space bounds of the axis-aligned box [lo, hi] of an object's space under `to_world`
/// (the extremes of its eight corners).
void world_bounds(const Transform& to_world, const Vec3& lo, const Vec3& hi, Vec3& out_lo, Vec3& out_hi);

}  // namespace whitted
