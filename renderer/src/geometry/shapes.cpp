// SPDX-License-Identifier: MIT
#include "geometry/shapes.h"

#include <cmath>
#include <limits>

namespace whitted {

namespace {

/// Vertex `index`'s normal as the mesh stores it (float), in double.
Vec3 vertex_normal(const TriangleMesh& mesh, uint32_t index) {
    const float* n = &mesh.normals[3 * size_t(index)];
    return {n[0], n[1], n[2]};
}

/// Whether the normals n0, n1, n2 of a triangle are one normal, within rounding.
bool one_normal(const Vec3& n0, const Vec3& n1, const Vec3& n2) {
    const Vec3 d1 = n0 - n1, d2 = n0 - n2;
    return dot(d1, d1) <= 1e-10 && dot(d2, d2) <= 1e-10;
}

}  // namespace

bool shaded_smooth(const TriangleMesh& mesh, uint32_t prim, Convention convention) {
    if (mesh.normals.empty()) return false;
    const uint32_t* index = &mesh.indices[3 * size_t(prim)];
    return convention == Convention::course ||
           !one_normal(vertex_normal(mesh, index[0]), vertex_normal(mesh, index[1]), vertex_normal(mesh, index[2]));
}

bool blended_normal(const TriangleMesh& mesh, uint32_t prim, double u, double v, Convention convention, Vec3& out) {
    if (mesh.normals.empty()) return false;
    const uint32_t* index = &mesh.indices[3 * size_t(prim)];
    const Vec3 n0 = vertex_normal(mesh, index[0]), n1 = vertex_normal(mesh, index[1]),
               n2 = vertex_normal(mesh, index[2]);
    if (convention != Convention::course && one_normal(n0, n1, n2)) return false;
    const Vec3 blended = n0 * (1.0 - u - v) + n1 * u + n2 * v;
    const double len = length(blended);
    if (!(len > 0)) return false;
    out = blended / len;
    return true;
}

uint32_t triangle_material(const TriangleMesh& mesh, uint32_t prim) {
    return mesh.triangle_materials.empty() ? mesh.material : mesh.triangle_materials[prim];
}

uint32_t triangle_material(const Instance& instance, const TriangleMesh& mesh, uint32_t prim) {
    return instance.material != Instance::no_material ? instance.material : triangle_material(mesh, prim);
}

Ray to_object_space(const Transform& to_world, const Ray& ray) {
    if (to_world.is_identity()) return ray;
    return {to_world.inverse_point(ray.origin), to_world.inverse_vector(ray.direction), ray.t_min, ray.t_max};
}

bool intersect_transformed_sphere(const Sphere& sphere, const Ray& world_ray, double t_min, double t_max,
                                  ShapeHit& hit) {
    const Ray ray = to_object_space(*sphere.object_to_world, world_ray);
    double t;
    if (!sphere_hit(sphere, ray.origin, ray.direction, t_min, t_max, t)) return false;
    hit.t = t;
    hit.normal = sphere.object_to_world->apply_normal((ray.at(t) - sphere.center) / sphere.radius);
    return true;
}

bool transformed_sphere_blocks(const Sphere& sphere, const Ray& world_ray, double t_min, double t_max) {
    const Ray ray = to_object_space(*sphere.object_to_world, world_ray);
    double t;
    return sphere_hit(sphere, ray.origin, ray.direction, t_min, t_max, t);
}

bool intersect_box(const Box& box, const Ray& world_ray, double t_min, double t_max, ShapeHit& hit) {
    const Ray ray = to_object_space(transform_of(box.object_to_world), world_ray);
    // The slab test, axis by axis in the order x, y, z, with no tolerance: the span is where
    // the ray is inside all three slabs; where two crossings are at one t (an edge), the later
    // axis's face is the one reported. (POV-Ray's own, with its constants and edge rule, is
    // compat/povray/box.h.)
    double t_in = -std::numeric_limits<double>::infinity(), t_out = std::numeric_limits<double>::infinity();
    int face_in = -1, face_out = -1;  // 2·axis + (0 for the min face, 1 for the max face); -1 none
    for (int axis = 0; axis < 3; ++axis) {
        const double o = ray.origin[axis], d = ray.direction[axis];
        const double lo = box.min[axis], hi = box.max[axis];
        if (d == 0) {
            if (o < lo || o > hi) return false;  // parallel to this slab and outside it
            continue;
        }
        const bool backwards = d < 0;  // then the ray leaves through the min face
        const double t_exit = ((backwards ? lo : hi) - o) / d;
        const double t_entry = ((backwards ? hi : lo) - o) / d;
        if (t_exit <= t_out) t_out = t_exit, face_out = 2 * axis + (backwards ? 0 : 1);
        if (t_entry >= t_in) t_in = t_entry, face_in = 2 * axis + (backwards ? 1 : 0);
        if (t_in > t_out) return false;
    }
    int face;
    if (t_in > 0 && face_in >= 0 && t_in > t_min && t_in < t_max) {
        hit.t = t_in, face = face_in;
    } else if (t_out >= 0 && face_out >= 0 && t_out > t_min && t_out < t_max) {  // the ray starts inside
        hit.t = t_out, face = face_out;
    } else {
        return false;
    }
    hit.edge_tie = false;
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
                        ShapeHit& hit, double edge_margin) {
    const Vec3 e1 = v1 - v0, e2 = v2 - v0;
    const Vec3 p = cross(ray.direction, e2);
    const double det = dot(e1, p);
    if (det == 0 || !std::isfinite(det)) return false;
    const double inv_det = 1.0 / det;
    const Vec3 s = ray.origin - v0;
    const double u = dot(s, p) * inv_det;
    if (!(u >= -edge_margin && u <= 1 + edge_margin)) return false;
    const Vec3 q = cross(s, e1);
    const double v = dot(ray.direction, q) * inv_det;
    if (!(v >= -edge_margin && u + v <= 1 + edge_margin)) return false;
    const double t = dot(e2, q) * inv_det;
    if (!(t > t_min && t < t_max)) return false;
    hit.t = t;
    hit.u = u;
    hit.v = v;
    hit.normal = cross(e1, e2);
    return true;
}

namespace {

/// The cone test on a ray already in the cone's own space. With the origin o and direction d
/// split along the axis (o_s, d_s) and across it (o⊥, d⊥), a point at t is on the side where
/// |o⊥ + t d⊥| = r0 + k (o_s + t d_s), k = (r1 − r0)/h: the quadratic
/// (d⊥·d⊥ − k² d_s²) t² + 2 (o⊥·d⊥ − k ρ d_s) t + (o⊥·o⊥ − ρ²) = 0, ρ = r0 + k o_s, whose
/// roots count where 0 ≤ s ≤ h. The roots are taken in the form that loses no digits to
/// cancellation (q = −(b + sign(b)·√disc), t = q/a and c/q).
bool cone_hit(const Cone& cone, const Vec3& origin, const Vec3& direction, double t_min, double t_max, double& t,
              Vec3& normal, double& along) {
    const Vec3& w = cone.axis;
    const Vec3 from_base = origin - cone.base;
    const double o_s = dot(from_base, w), d_s = dot(direction, w);
    const Vec3 o_across = from_base - w * o_s, d_across = direction - w * d_s;
    const double k = (cone.cap_radius - cone.base_radius) / cone.height;
    const double rho = cone.base_radius + k * o_s;
    const double a = dot(d_across, d_across) - k * k * d_s * d_s;
    const double half_b = dot(o_across, d_across) - k * rho * d_s;
    const double c = dot(o_across, o_across) - rho * rho;
    bool found = false;
    const auto consider_side = [&](double root) {
        if (!(root > t_min && root < t_max) || (found && root >= t)) return;
        const double s = o_s + root * d_s;
        if (!(s >= 0 && s <= cone.height)) return;
        t = root, along = s, found = true;
        // The gradient of |p⊥| − r(s), times r(s) = |p⊥| on the surface: no division.
        const Vec3 across = o_across + d_across * root;
        normal = across - w * (k * (cone.base_radius + k * s));
        // The point of a cone to a point: no gradient there; the axis, outward.
        if (normal.x == 0 && normal.y == 0 && normal.z == 0) normal = w * (s > cone.height / 2 ? 1.0 : -1.0);
    };
    if (a != 0) {
        const double disc = half_b * half_b - a * c;
        if (disc >= 0) {
            const double q = -(half_b + std::copysign(std::sqrt(disc), half_b));
            consider_side(q / a);
            if (q != 0) consider_side(c / q);
        }
    } else if (half_b != 0) {  // along the slant of the cone (or the axis of a cylinder: no root)
        consider_side(-c / (2 * half_b));
    }
    if (!cone.open && d_s != 0) {
        const auto consider_cap = [&](double s, double radius, double sign) {
            const double root = (s - o_s) / d_s;
            if (!(root > t_min && root < t_max) || (found && root >= t)) return;
            const Vec3 across = o_across + d_across * root;
            if (!(dot(across, across) <= radius * radius)) return;
            t = root, along = s, found = true;
            normal = w * sign;
        };
        consider_cap(0, cone.base_radius, -1);
        consider_cap(cone.height, cone.cap_radius, 1);
    }
    return found;
}

}  // namespace

bool intersect_cone(const Cone& cone, const Ray& world_ray, double t_min, double t_max, ShapeHit& hit) {
    double t, along;
    Vec3 normal;
    if (!cone.object_to_world) {
        if (!cone_hit(cone, world_ray.origin, world_ray.direction, t_min, t_max, t, normal, along)) return false;
        hit.t = t;
        hit.u = along;
        hit.normal = normal;
        return true;
    }
    const Ray ray = to_object_space(*cone.object_to_world, world_ray);
    if (!cone_hit(cone, ray.origin, ray.direction, t_min, t_max, t, normal, along)) return false;
    hit.t = t;
    hit.u = along;
    hit.normal = cone.object_to_world->apply_normal(normal);
    return true;
}

void world_bounds(const Transform& to_world, const Vec3& lo, const Vec3& hi, Vec3& out_lo, Vec3& out_hi) {
    if (to_world.is_identity()) {
        out_lo = lo, out_hi = hi;
        return;
    }
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

void world_bounds(const Cone& cone, Vec3& lo, Vec3& hi) {
    world_bounds(cone, 0.0, cone.height, lo, hi);
}

void world_bounds(const Cone& cone, double s_begin, double s_end, Vec3& lo, Vec3& hi) {
    // Each end is a disc across the axis: along a coordinate axis e it reaches r·√(1 − (w·e)²).
    const Vec3& w = cone.axis;
    const Vec3 reach{std::sqrt(std::max(0.0, 1 - w.x * w.x)), std::sqrt(std::max(0.0, 1 - w.y * w.y)),
                     std::sqrt(std::max(0.0, 1 - w.z * w.z))};
    // The whole cone's ends exactly as given; a part's ends on the line between them.
    const auto radius_at = [&](double s) {
        if (s == 0) return cone.base_radius;
        if (s == cone.height) return cone.cap_radius;
        return cone.base_radius + (cone.cap_radius - cone.base_radius) * (s / cone.height);
    };
    const Vec3 begin = s_begin == 0 ? cone.base : cone.base + w * s_begin;
    const Vec3 end = cone.base + w * s_end;
    const double r_begin = radius_at(s_begin), r_end = radius_at(s_end);
    lo = min(begin - reach * r_begin, end - reach * r_end);
    hi = max(begin + reach * r_begin, end + reach * r_end);
    if (cone.object_to_world) world_bounds(*cone.object_to_world, Vec3(lo), Vec3(hi), lo, hi);
}

}  // namespace whitted
