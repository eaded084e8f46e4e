// SPDX-License-Identifier: MIT
#include "compat/povray/box.h"

#include <cmath>
#include <limits>

namespace whitted {
namespace {

/// A direction component within this of 0 is parallel to its slab.
constexpr double parallel = 1e-10;
/// Crossings within this (in t) of each other are one crossing.
constexpr double close = 1e-6;
/// The span starts at t = 0, and an exit before this is no hit.
constexpr double depth_tolerance = 1e-6;

/// Whether a later axis's face takes over near an edge, `held` being the face held so far
/// (2·axis + 0 for the min face, 1 for the max face; −1 none): when the ray runs more steeply
/// along it. For y the steepness is weighed against x; for z against the held face's axis.
bool steeper_face(int axis, int held, const Vec3& direction) {
    const double along = std::fabs(direction[axis]);
    if (axis == 1) return along > std::fabs(direction.x);
    if (held < 0) return false;
    return along > std::fabs(direction[held / 2]);
}

}  // namespace

bool intersect_box_as_povray(const Box& box, const Ray& world_ray, double t_min, double t_max, ShapeHit& hit) {
    const Ray ray = to_object_space(transform_of(box.object_to_world), world_ray);
    // The slab test, axis by axis in the order x, y, z, with POV-Ray's constants (a direction
    // component within `parallel` of 0 is parallel to its slab; crossings within `close` of each
    // other are one crossing: the t already held is kept, the face may change, steeper_face; the
    // span starts at t = 0, and an exit before `depth_tolerance` is no hit). They are distances
    // in t, which scaling a scene scales: the exact test (geometry/shapes.h) has none.
    double t_in = 0, t_out = std::numeric_limits<double>::infinity();
    int face_in = -1, face_out = -1;       // 2·axis + (0 for the min face, 1 for the max face); -1 none
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
        const int exit_face = 2 * axis + (backwards ? 0 : 1), entry_face = 2 * axis + (backwards ? 1 : 0);
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
    int face;
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

}  // namespace whitted
