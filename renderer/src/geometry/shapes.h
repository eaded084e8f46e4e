// SPDX-License-Identifier: MIT
#pragma once

// Ray–shape intersection in double precision. Each function finds the nearest hit with
// t_min < t < t_max and returns its distance and outward (not yet ray-facing) normal.

#include "core/ray.h"
#include "scene/scene.h"

#include <cmath>

namespace whitted {

struct ShapeHit {
    double t = 0;
    Vec3 normal;  ///< outward geometric normal, world space, not necessarily unit
    /// Triangles: the barycentric weight of vertex 1; cones: the hit's distance along the axis
    /// from the base.
    double u = 0;
    double v = 0;  ///< triangles: barycentric weight of vertex 2
    /// Boxes: the face is not the one the ray crosses at `t` but a steeper one within 1e-6,
    /// chosen by POV-Ray's edge rule (intersect_box); the accelerator lets another box's plain
    /// hit at the very same t win over it, as POV-Ray's order of testing does.
    bool edge_tie = false;
};

/// The ray in a shape's own space: the direction is not renormalised, so t means the same
/// distance along the world ray in both spaces.
Ray to_object_space(const Transform& to_world, const Ray& ray);

/// The sphere test on a ray already in the sphere's own space. Called for every lane of every
/// candidate in a packet, so it rejects a miss with the fewest operations (no division, no sqrt).
inline bool sphere_hit(const Sphere& sphere, const Vec3& origin, const Vec3& direction, double t_min, double t_max,
                       double& t) {
    // Closest approach along the ray, then half the chord. The squared distance of the centre
    // from the ray is taken from the perpendicular vector itself, not as |oc|² − along²/a: for a
    // small sphere far away those two are nearly equal and their difference loses every digit
    // of r² (a sphere of radius 1e-3 at 1e5 gets about none right). Scaled by a so that the sign
    // decides a miss before any division: a·oc − along·d = a·(perpendicular vector).
    const Vec3 to_center = sphere.center - origin;
    const double along = dot(to_center, direction);
    const double a = dot(direction, direction);
    const Vec3 scaled_perpendicular = to_center * a - direction * along;
    // a²·r² − |a·perpendicular|² = a²·(r² − distance²) = a³·half_chord² (t units).
    const double scaled_half_chord2 =
        a * a * sphere.radius * sphere.radius - dot(scaled_perpendicular, scaled_perpendicular);
    if (scaled_half_chord2 < 0) return false;
    const double closest = along / a;
    const double half_chord = std::sqrt(scaled_half_chord2 / a) / a;
    t = closest - half_chord;
    if (!(t > t_min)) t = closest + half_chord;  // the ray starts inside (or past the near side)
    return t > t_min && t < t_max;
}

/// intersect_sphere and sphere_blocks for a sphere with an object_to_world transform.
bool intersect_transformed_sphere(const Sphere& sphere, const Ray& ray, double t_min, double t_max, ShapeHit& hit);
bool transformed_sphere_blocks(const Sphere& sphere, const Ray& ray, double t_min, double t_max);

/// Here, not in shapes.cpp, so that the callers testing many spheres per ray (the accelerator's
/// callbacks) inline it.
inline bool intersect_sphere(const Sphere& sphere, const Ray& ray, double t_min, double t_max, ShapeHit& hit) {
    if (sphere.object_to_world) return intersect_transformed_sphere(sphere, ray, t_min, t_max, hit);
    double t;
    if (!sphere_hit(sphere, ray.origin, ray.direction, t_min, t_max, t)) return false;
    hit.t = t;
    hit.normal = (ray.at(t) - sphere.center) / sphere.radius;
    return true;
}

/// Whether intersect_sphere finds a hit, decided by the same arithmetic, without the normal: a
/// shadow ray needs only that.
inline bool sphere_blocks(const Sphere& sphere, const Ray& ray, double t_min, double t_max) {
    if (sphere.object_to_world) return transformed_sphere_blocks(sphere, ray, t_min, t_max);
    double t;
    return sphere_hit(sphere, ray.origin, ray.direction, t_min, t_max, t);
}

/// The slab test, exact: no tolerance but t_min; a ray through an edge or corner gets the face
/// of the last axis it crosses there. (POV-Ray's, for `whitted check`: compat/povray/box.h.)
bool intersect_box(const Box& box, const Ray& ray, double t_min, double t_max, ShapeHit& hit);
/// The side as a quadric in the cone's own frame (the axis and the plane across it), then the
/// caps as discs unless the cone is open; the nearest hit. Exact in double: no tolerance but
/// t_min. The side's normal is the gradient of |p⊥| − r(s), scaled by r(s); hit.u is s, the
/// hit's distance along the axis from the base in the cone's own space (0 and height on the caps).
bool intersect_cone(const Cone& cone, const Ray& ray, double t_min, double t_max, ShapeHit& hit);
bool intersect_plane(const Plane& plane, const Ray& ray, double t_min, double t_max, ShapeHit& hit);
/// Möller–Trumbore; the normal is (v1 − v0) × (v2 − v0). `edge_margin` widens the triangle by
/// that much in barycentric terms (u, v ≥ −margin, u + v ≤ 1 + margin): with a small margin a
/// ray along an edge that two triangles share meets at least one of them despite double's
/// rounding, which the exact test alone does not promise.
bool intersect_triangle(const Vec3& v0, const Vec3& v1, const Vec3& v2, const Ray& ray, double t_min, double t_max,
                        ShapeHit& hit, double edge_margin = 0);

/// Whether triangle `prim` is shaded smooth, with its vertex normals blended, rather than flat
/// with its face normal: its mesh has vertex normals and its three are not one normal (under
/// render.convention: course they are blended always, as the course's ray tracer does).
bool shaded_smooth(const TriangleMesh& mesh, uint32_t prim, Convention convention);
/// The smooth shading normal at a hit on triangle `prim` with barycentric weights u, v
/// (ShapeHit): the unit vertex normals blended by weight, n0 (1 − u − v) + n1 u + n2 v, and made
/// unit length, as the lecture and POV-Ray's mesh2 do. False where the triangle is shaded flat
/// (shaded_smooth) or the blend has length 0: its face normal then shades it.
bool blended_normal(const TriangleMesh& mesh, uint32_t prim, double u, double v, Convention convention, Vec3& out);
/// The material of triangle `prim`: its own where the mesh has one per triangle, else the mesh's.
uint32_t triangle_material(const TriangleMesh& mesh, uint32_t prim);
/// The same for a prototype's triangle placed by `instance`, whose material, if it has one,
/// overrides the prototype's.
uint32_t triangle_material(const Instance& instance, const TriangleMesh& mesh, uint32_t prim);

/// World-space bounds of a sphere, box or cone (its object-space box pushed through the transform).
void world_bounds(const Sphere& sphere, Vec3& lo, Vec3& hi);
void world_bounds(const Box& box, Vec3& lo, Vec3& hi);
void world_bounds(const Cone& cone, Vec3& lo, Vec3& hi);
/// World-space bounds of the part of a cone between s_begin and s_end along its axis
/// (0 ≤ s_begin ≤ s_end ≤ height): the frustum's two end discs.
void world_bounds(const Cone& cone, double s_begin, double s_end, Vec3& lo, Vec3& hi);
/// World-space bounds of the axis-aligned box [lo, hi] of an object's space under `to_world`
/// (the extremes of its eight corners).
void world_bounds(const Transform& to_world, const Vec3& lo, const Vec3& hi, Vec3& out_lo, Vec3& out_hi);

}  // namespace whitted
