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

void bounds_of_transformed_box(const Transform& to_world, const Vec3& lo, const Vec3& hi, Vec3& out_lo, Vec3& out_hi) {
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

bool intersect_box(const Box& box, const Ray& world_ray, double t_min, double t_max, ShapeHit& hit) {
    const Ray ray = to_object_space(transform_of(box.object_to_world), world_ray);
    double t_near = -std::numeric_limits<double>::infinity();
    double t_far = std::numeric_limits<double>::infinity();
    int near_axis = -1, far_axis = -1;
    double near_sign = 0, far_sign = 0;
    for (int axis = 0; axis < 3; ++axis) {
        const double o = ray.origin[axis], d = ray.direction[axis];
        const double lo = box.min[axis], hi = box.max[axis];
        if (d == 0) {
            if (o < lo || o > hi) return false;  // parallel to this slab and outside it
            continue;
        }
        double t0 = (lo - o) / d, t1 = (hi - o) / d;
        double sign0 = -1, sign1 = 1;  // outward normal of the face each t belongs to
        if (t0 > t1) std::swap(t0, t1), std::swap(sign0, sign1);
        if (t0 > t_near) t_near = t0, near_axis = axis, near_sign = sign0;
        if (t1 < t_far) t_far = t1, far_axis = axis, far_sign = sign1;
        if (t_near > t_far) return false;
    }
    Vec3 object_normal;
    if (t_near > t_min && t_near < t_max && near_axis >= 0) {
        hit.t = t_near;
        object_normal[near_axis] = near_sign;
    } else if (t_far > t_min && t_far < t_max && far_axis >= 0) {  // the ray starts inside
        hit.t = t_far;
        object_normal[far_axis] = far_sign;
    } else {
        return false;
    }
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

void world_bounds(const Sphere& sphere, Vec3& lo, Vec3& hi) {
    lo = sphere.center - Vec3(sphere.radius);
    hi = sphere.center + Vec3(sphere.radius);
    // Embree asks once per sphere while building: the eight corners only when there is a transform.
    if (sphere.object_to_world) bounds_of_transformed_box(*sphere.object_to_world, Vec3(lo), Vec3(hi), lo, hi);
}

void world_bounds(const Box& box, Vec3& lo, Vec3& hi) {
    bounds_of_transformed_box(transform_of(box.object_to_world), box.min, box.max, lo, hi);
}

}  // namespace whitted
