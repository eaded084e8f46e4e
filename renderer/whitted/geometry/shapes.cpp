// SPDX-License-Identifier: MIT
#include "whitted/geometry/shapes.h"

#include <cmath>
#include <limits>

namespace whitted {
namespace {

/// Ray in the shape's own space: the direction is not renormalised, so t means the same
/// distance along the world ray in both spaces.
Ray to_object_space(const Transform& to_world, const Ray& ray) {
    if (to_world.is_identity()) return ray;
    return {to_world.inverse_point(ray.origin), to_world.inverse_vector(ray.direction), ray.t_min, ray.t_max};
}

}  // namespace

namespace {

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

}  // namespace

bool intersect_sphere(const Sphere& sphere, const Ray& world_ray, double t_min, double t_max, ShapeHit& hit) {
    double t;
    if (!sphere.object_to_world) {
        if (!sphere_hit(sphere, world_ray.origin, world_ray.direction, t_min, t_max, t)) return false;
        hit.t = t;
        hit.normal = (world_ray.at(t) - sphere.center) / sphere.radius;
        return true;
    }
    const Ray ray = to_object_space(*sphere.object_to_world, world_ray);
    if (!sphere_hit(sphere, ray.origin, ray.direction, t_min, t_max, t)) return false;
    hit.t = t;
    hit.normal = sphere.object_to_world->apply_normal((ray.at(t) - sphere.center) / sphere.radius);
    return true;
}

namespace {

/// Which face a box hit is on, as 2·axis + (0 for the min face, 1 for the max face); -1 none.
using BoxFace = int;

/// Near an edge, the face a box hit is reported on follows POV-Ray 3.7's rule (docs/pov-model.md
/// §3, "Box edges"), so that both renderers shade an edge pixel with the same normal: when a
/// later axis's crossing is within 1e-6 (in t) of the crossing found so far, that axis's face
/// takes over if the ray runs more steeply along it. For y the steepness is weighed against x;
/// for z against the axis of the face held so far.
bool steeper_face(int axis, BoxFace held, const Vec3& direction) {
    const double along = std::fabs(direction[axis]);
    if (axis == 1) return along > std::fabs(direction.x);
    if (held < 0) return false;
    return along > std::fabs(direction[held / 2]);
}

}  // namespace

bool intersect_box(const Box& box, const Ray& world_ray, double t_min, double t_max, ShapeHit& hit) {
    const Ray ray = to_object_space(transform_of(box.object_to_world), world_ray);
    // The slab test, axis by axis in the order x, y, z, with POV-Ray's constants: a direction
    // component within 1e-10 of 0 is parallel to its slab; crossings within 1e-6 of each other
    // are one crossing (the t already held is kept, the face may change, steeper_face); the
    // span starts at t = 0, and an exit before 1e-6 is no hit.
    constexpr double parallel = 1e-10, close = 1e-6, depth_tolerance = 1e-6;
    double t_in = 0, t_out = std::numeric_limits<double>::infinity();
    BoxFace face_in = -1, face_out = -1;
    bool tie_in = false, tie_out = false;  // the face was switched by the edge rule
    for (int axis = 0; axis < 3; ++axis) {
        const double o = ray.origin[axis], d = ray.direction[axis];
        const double lo = box.min[axis], hi = box.max[axis];
        if (std::fabs(d) <= parallel) {
            if (o < lo || o > hi) return false;  // parallel to this slab and outside it
            continue;
        }
        const bool backwards = d < 0;  // then the ray leaves through the min face
        const double t_exit = ((backwards ? lo : hi) - o) / d;
        const double t_entry = ((backwards ? hi : lo) - o) / d;
        const BoxFace exit_face = 2 * axis + (backwards ? 0 : 1), entry_face = 2 * axis + (backwards ? 1 : 0);
        if (t_exit < t_in) return false;
        const double tie = axis == 0 ? 0.0 : close;  // the first axis has nothing to tie with
        if (t_exit <= t_out - tie) {
            t_out = t_exit, face_out = exit_face, tie_out = false;
        } else if (t_exit <= t_out + tie && steeper_face(axis, face_out, ray.direction)) {
            face_out = exit_face, tie_out = true;
        }
        if (t_entry >= t_in + tie) {
            if (t_entry > t_out) return false;
            t_in = t_entry, face_in = entry_face, tie_in = false;
        } else if (t_entry >= t_in - tie && axis > 0 && steeper_face(axis, face_in, ray.direction)) {
            face_in = entry_face, tie_in = true;
        }
    }
    if (t_out < depth_tolerance) return false;
    BoxFace face;
    if (t_in > depth_tolerance && face_in >= 0 && t_in > t_min && t_in < t_max) {
        hit.t = t_in, face = face_in, hit.edge_tie = tie_in;
    } else if (face_out >= 0 && t_out > t_min && t_out < t_max) {  // the ray starts inside
        hit.t = t_out, face = face_out, hit.edge_tie = tie_out;
    } else {
        return false;
    }
    Vec3 object_normal;
    object_normal[face / 2] = face % 2 ? 1 : -1;
    hit.normal = box.object_to_world ? box.object_to_world->apply_normal(object_normal) : object_normal;
    return true;
}

bool intersect_plane(const Plane& plane, const Ray& ray, double t_min, double t_max, ShapeHit& hit) {
    const double facing = dot(plane.normal, ray.direction);
    if (std::fabs(facing) < 1e-12) return false;  // parallel: no single hit
    const double t = dot(plane.normal, plane.point - ray.origin) / facing;
    if (!(t > t_min && t < t_max)) return false;
    hit.t = t;
    hit.normal = plane.normal;
    return true;
}

bool intersect_triangle(const Vec3& v0, const Vec3& v1, const Vec3& v2, const Ray& ray, double t_min, double t_max,
                        ShapeHit& hit) {
    const Vec3 e1 = v1 - v0, e2 = v2 - v0;
    const Vec3 p = cross(ray.direction, e2);
    const double det = dot(e1, p);
    if (det == 0 || !std::isfinite(det)) return false;
    const double inv_det = 1.0 / det;
    const Vec3 s = ray.origin - v0;
    const double u = dot(s, p) * inv_det;
    if (u < 0 || u > 1) return false;
    const Vec3 q = cross(s, e1);
    const double v = dot(ray.direction, q) * inv_det;
    if (v < 0 || u + v > 1) return false;
    const double t = dot(e2, q) * inv_det;
    if (!(t > t_min && t < t_max)) return false;
    hit.t = t;
    hit.u = u;
    hit.v = v;
    hit.normal = cross(e1, e2);
    return true;
}

bool hit_triangle_plane(const Vec3& v0, const Vec3& v1, const Vec3& v2, const Ray& ray, ShapeHit& hit) {
    // The same quantities as intersect_triangle, without its edge and distance tests.
    const Vec3 e1 = v1 - v0, e2 = v2 - v0;
    const Vec3 p = cross(ray.direction, e2);
    const double det = dot(e1, p);
    if (det == 0 || !std::isfinite(det)) return false;
    const double inv_det = 1.0 / det;
    const Vec3 s = ray.origin - v0;
    const Vec3 q = cross(s, e1);
    const double t = dot(e2, q) * inv_det;
    if (!std::isfinite(t)) return false;
    double u = std::max(0.0, dot(s, p) * inv_det), v = std::max(0.0, dot(ray.direction, q) * inv_det);
    if (u + v > 1) {
        const double sum = u + v;
        u /= sum;
        v /= sum;
    }
    hit.t = t;
    hit.u = u;
    hit.v = v;
    hit.normal = cross(e1, e2);
    return true;
}

void world_bounds(const Transform& to_world, const Vec3& lo, const Vec3& hi, Vec3& out_lo, Vec3& out_hi) {
    constexpr double inf = std::numeric_limits<double>::infinity();
    out_lo = Vec3(inf);
    out_hi = Vec3(-inf);
    for (int corner = 0; corner < 8; ++corner) {
        const Vec3 p{(corner & 1) ? hi.x : lo.x, (corner & 2) ? hi.y : lo.y, (corner & 4) ? hi.z : lo.z};
        const Vec3 w = to_world.apply_point(p);
        out_lo = min(out_lo, w);
        out_hi = max(out_hi, w);
    }
}

void world_bounds(const Sphere& sphere, Vec3& lo, Vec3& hi) {
    lo = sphere.center - Vec3(sphere.radius);
    hi = sphere.center + Vec3(sphere.radius);
    // Embree asks once per sphere while building: the eight corners only when there is a transform.
    if (sphere.object_to_world) world_bounds(*sphere.object_to_world, Vec3(lo), Vec3(hi), lo, hi);
}

void world_bounds(const Box& box, Vec3& lo, Vec3& hi) {
    world_bounds(transform_of(box.object_to_world), box.min, box.max, lo, hi);
}

}  // namespace whitted
