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

bool intersect_box(const Box& box, const Ray& world_ray, double t_min, double t_max, ShapeHit& hit, Intersection rule) {
    const Ray ray = to_object_space(transform_of(box.object_to_world), world_ray);
    // The slab test, axis by axis in the order x, y, z. With POV-Ray's constants: a direction
    // component within 1e-10 of 0 is parallel to its slab; crossings within 1e-6 of each other
    // are one crossing (the t already held is kept, the face may change, steeper_face); the
    // span starts at t = 0, and an exit before 1e-6 is no hit. Exactly, all three are 0: they
    // are distances in t, which scaling the scene scales, so they would make its image depend on
    // its size.
    const bool povray = rule == Intersection::povray;
    const double parallel = povray ? 1e-10 : 0.0, close = povray ? 1e-6 : 0.0, depth_tolerance = povray ? 1e-6 : 0.0;
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
        } else if (povray && t_exit <= t_out + tie && steeper_face(axis, face_out, ray.direction)) {
            face_out = exit_face, tie_out = true;
        }
        if (t_entry >= t_in + tie) {
            if (t_entry > t_out) return false;
            t_in = t_entry, face_in = entry_face, tie_in = false;
        } else if (povray && t_entry >= t_in - tie && axis > 0 && steeper_face(axis, face_in, ray.direction)) {
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

/// A mesh2 triangle as POV-Ray sets it up when it reads the mesh: the plane with its normal
/// (p3 − p1) × (p2 − p1) scaled by the reciprocal of its length, the distance −n·p1 rounded to
/// float and the normal then rounded to float too; the normal's largest axis (ties going to
/// the later axis); and p1, p2 swapped where needed so that the edge tests see the corners
/// turning one way (`swapped`). Each operation is written out in POV-Ray's order, so that the
/// roundings are the same.
struct Mesh2Triangle {
    Vec3 p1, p2, p3;       ///< after the swap
    bool swapped = false;  ///< p1 and p2 are the face's second and first vertex
    Vec3 stored_normal;    ///< float
    double distance = 0;   ///< float
    int axis = 2;
    bool degenerate = false;

    Mesh2Triangle(const Vec3& v1, const Vec3& v2, const Vec3& v3) : p1(v1), p2(v2), p3(v3) {
        const Vec3 a = v2 - v1, b = v3 - v1;
        Vec3 n{b.y * a.z - b.z * a.y, b.z * a.x - b.x * a.z, b.x * a.y - b.y * a.x};
        const double n_length = std::sqrt(n.x * n.x + n.y * n.y + n.z * n.z);
        if (n_length == 0) {
            degenerate = true;  // POV-Ray drops the triangle
            return;
        }
        const double inverse = 1.0 / n_length;
        n.x *= inverse;
        n.y *= inverse;
        n.z *= inverse;
        distance = -float_rounded(n.x * v1.x + n.y * v1.y + n.z * v1.z);
        stored_normal = {float_rounded(n.x), float_rounded(n.y), float_rounded(n.z)};
        const double x = std::fabs(n.x), y = std::fabs(n.y), z = std::fabs(n.z);
        axis = x > y ? (x > z ? 0 : 2) : (y > z ? 1 : 2);
        const int i = projected_i(), j = projected_j();
        if ((p2[i] - p3[i]) * (p2[j] - p1[j]) < (p2[j] - p3[j]) * (p2[i] - p1[i])) {
            std::swap(p1, p2);
            swapped = true;
        }
    }
    /// The two axes of the projection along `axis`, in POV-Ray's order.
    int projected_i() const { return axis == 0 ? 1 : 0; }
    int projected_j() const { return axis == 2 ? 1 : 2; }
};

}  // namespace

bool intersect_mesh2_triangle(const Vec3& p1_in, const Vec3& p2_in, const Vec3& p3_in, const Vec3& origin,
                              const Vec3& direction, double& depth, bool& inside) {
    const Mesh2Triangle triangle(p1_in, p2_in, p3_in);
    if (triangle.degenerate) return false;
    const Vec3 &n = triangle.stored_normal, &p1 = triangle.p1, &p2 = triangle.p2, &p3 = triangle.p3;
    const double normal_dot_direction = n.x * direction.x + n.y * direction.y + n.z * direction.z;
    if (std::fabs(normal_dot_direction) < 1e-10) return false;
    const double normal_dot_origin = n.x * origin.x + n.y * origin.y + n.z * origin.z;
    depth = -(triangle.distance + normal_dot_origin) / normal_dot_direction;
    if (depth < 1e-6 || depth > 1e7) return false;
    const int i = triangle.projected_i(), j = triangle.projected_j();
    const double s = origin[i] + depth * direction[i], t = origin[j] + depth * direction[j];
    inside = !((p2[i] - s) * (p2[j] - p1[j]) < (p2[j] - t) * (p2[i] - p1[i])) &&
             !((p3[i] - s) * (p3[j] - p2[j]) < (p3[j] - t) * (p3[i] - p2[i])) &&
             !((p1[i] - s) * (p1[j] - p3[j]) < (p1[j] - t) * (p1[i] - p3[i]));
    return true;
}

Vec3 mesh2_smooth_normal(const Vec3& p1_in, const Vec3& p2_in, const Vec3& p3_in, const Vec3& n1_in, const Vec3& n2_in,
                         const Vec3& n3_in, const Vec3& point) {
    const Mesh2Triangle triangle(p1_in, p2_in, p3_in);
    const Vec3 &p1 = triangle.p1, &p2 = triangle.p2, &p3 = triangle.p3;
    const Vec3& n1 = triangle.swapped ? n2_in : n1_in;
    const Vec3& n2 = triangle.swapped ? n1_in : n2_in;
    const Vec3& n3 = n3_in;
    // What POV-Ray keeps per triangle for it: the axis along which p3 − p2 is longest, and
    // `perp`, a float vector in the plane across the edge p2 p3, scaled so that its dot
    // product with a point minus p1 runs from 0 at p1 to 1 on that edge.
    const Vec3 p3_minus_p2 = p3 - p2;
    const double x = std::fabs(p3_minus_p2.x), y = std::fabs(p3_minus_p2.y), z = std::fabs(p3_minus_p2.z);
    const int v_axis = x > y ? (x > z ? 0 : 2) : (y > z ? 1 : 2);
    Vec3 edge = p2 - p3;
    const double edge_inverse = 1.0 / std::sqrt(edge.x * edge.x + edge.y * edge.y + edge.z * edge.z);
    edge = {edge.x * edge_inverse, edge.y * edge_inverse, edge.z * edge_inverse};
    const Vec3 p1_from_p3 = p1 - p3;
    const double projection = p1_from_p3.x * edge.x + p1_from_p3.y * edge.y + p1_from_p3.z * edge.z;
    edge = {edge.x * projection, edge.y * projection, edge.z * projection};
    // `perp` is a float vector, normalised and scaled in single precision. Each float
    // operation is done in double and rounded (float_rounded), which for +, ×, / and sqrt
    // gives the float result exactly.
    const auto r = float_rounded;
    double perp[3] = {r(edge.x - p1_from_p3.x), r(edge.y - p1_from_p3.y), r(edge.z - p1_from_p3.z)};
    const double perp_length = r(std::sqrt(r(r(r(perp[0] * perp[0]) + r(perp[1] * perp[1])) + r(perp[2] * perp[2]))));
    const double perp_inverse = r(1.0 / perp_length);
    for (double& c : perp) c = r(c * perp_inverse);
    const double u_denominator = p1_from_p3.x * perp[0] + p1_from_p3.y * perp[1] + p1_from_p3.z * perp[2];
    const double scale = r(1.0 / r(-u_denominator));
    for (double& c : perp) c = r(c * scale);
    // The normal at the point: n1 at p1, blended toward the edge p2 p3 by u, along it by v.
    const Vec3 from_p1 = point - p1;
    const double u = from_p1.x * perp[0] + from_p1.y * perp[1] + from_p1.z * perp[2];
    if (u < 1e-10) return n1;
    const double k1 = p1[v_axis], k2 = p2[v_axis], k3 = p3[v_axis];
    const double v = (from_p1[v_axis] / u + k1 - k2) / (k3 - k2);
    return {n1.x + u * (n2.x - n1.x + v * (n3.x - n2.x)), n1.y + u * (n2.y - n1.y + v * (n3.y - n2.y)),
            n1.z + u * (n2.z - n1.z + v * (n3.z - n2.z))};
}

namespace {

/// The cone test on a ray already in the cone's own space. With the origin o and direction d
/// split along the axis (o_s, d_s) and across it (o⊥, d⊥), a point at t is on the side where
/// |o⊥ + t d⊥| = r0 + k (o_s + t d_s), k = (r1 − r0)/h: the quadratic
/// (d⊥·d⊥ − k² d_s²) t² + 2 (o⊥·d⊥ − k ρ d_s) t + (o⊥·o⊥ − ρ²) = 0, ρ = r0 + k o_s, whose
/// roots count where 0 ≤ s ≤ h. The roots are taken in the form that loses no digits to
/// cancellation (q = −(b + sign(b)·√disc), t = q/a and c/q).
bool cone_hit(const Cone& cone, const Vec3& origin, const Vec3& direction, double t_min, double t_max, double& t,
              Vec3& normal) {
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
        t = root, found = true;
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
            t = root, found = true;
            normal = w * sign;
        };
        consider_cap(0, cone.base_radius, -1);
        consider_cap(cone.height, cone.cap_radius, 1);
    }
    return found;
}

}  // namespace

bool intersect_cone(const Cone& cone, const Ray& world_ray, double t_min, double t_max, ShapeHit& hit) {
    double t;
    Vec3 normal;
    if (!cone.object_to_world) {
        if (!cone_hit(cone, world_ray.origin, world_ray.direction, t_min, t_max, t, normal)) return false;
        hit.t = t;
        hit.normal = normal;
        return true;
    }
    const Ray ray = to_object_space(*cone.object_to_world, world_ray);
    if (!cone_hit(cone, ray.origin, ray.direction, t_min, t_max, t, normal)) return false;
    hit.t = t;
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
    // Each end is a disc across the axis: along a coordinate axis e it reaches r·√(1 − (w·e)²).
    const Vec3& w = cone.axis;
    const Vec3 reach{std::sqrt(std::max(0.0, 1 - w.x * w.x)), std::sqrt(std::max(0.0, 1 - w.y * w.y)),
                     std::sqrt(std::max(0.0, 1 - w.z * w.z))};
    const Vec3 cap = cone.base + w * cone.height;
    lo = min(cone.base - reach * cone.base_radius, cap - reach * cone.cap_radius);
    hi = max(cone.base + reach * cone.base_radius, cap + reach * cone.cap_radius);
    if (cone.object_to_world) world_bounds(*cone.object_to_world, Vec3(lo), Vec3(hi), lo, hi);
}

}  // namespace whitted
