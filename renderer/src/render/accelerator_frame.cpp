// SPDX-License-Identifier: MIT
// Embree's float frame and the reach Whitted renders: the shapes a float BVH cannot hold are
// refused, naming the object, and a far scene is moved near Embree's origin.
#include "render/accelerator_impl.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace whitted {

using namespace accel;

/// Embree keeps bounds and rays in float and stops the program (an assertion) on a ray whose
/// origin lies beyond about 1.8e19, or on bounds it cannot order; its rays start on the
/// shapes. So a finite shape reaching beyond ±max_reach is refused, naming the object.
void Accelerator::Impl::check_reach() {
    const auto reach = [](const Vec3& lo, const Vec3& hi) {
        return std::max(
            {std::fabs(lo.x), std::fabs(lo.y), std::fabs(lo.z), std::fabs(hi.x), std::fabs(hi.y), std::fabs(hi.z)});
    };
    double finite_reach = 0;  // of every finite shape, in world space
    const auto check = [&](uint32_t object, double reached) {
        finite_reach = std::max(finite_reach, reached);
        if (reached <= max_reach) return;  // NaN is refused too
        const SourceLocation where = object > 0 && object <= scene.objects.size() ? scene.objects[object - 1].where
                                                                                  : SourceLocation{scene.path, 0, 0};
        const char* kind =
            object > 0 && object <= scene.objects.size() ? to_string(scene.objects[object - 1].type) : "object";
        char distance[32];
        std::snprintf(distance, sizeof distance, "%g", reached);
        throw InputError(where, std::string(kind) + " reaches " + distance +
                                    " from the origin in world space; Whitted renders shapes within 1e15 of it");
    };
    Vec3 lo, hi;
    for (const Sphere& sphere : scene.spheres) world_bounds(sphere, lo, hi), check(sphere.object, reach(lo, hi));
    for (const Box& box : scene.boxes) world_bounds(box, lo, hi), check(box.object, reach(lo, hi));
    for (const Cone& cone : scene.cones) world_bounds(cone, lo, hi), check(cone.object, reach(lo, hi));
    for (const TriangleMesh& mesh : scene.meshes) {
        double reached = 0;
        for (uint32_t i = 0; i < mesh.vertex_count(); ++i) {
            const Vec3 v = mesh.vertex(i);
            reached = std::max({reached, std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)});
        }
        check(mesh.object, reached);
    }
    for (const Instance& instance : scene.instances) {
        const Prototype& prototype = scene.prototypes[instance.prototype];
        double reached = 0;
        for (int corner = 0; corner < 8; ++corner) {
            const Vec3 p = instance.object_to_world.apply_point({corner & 1 ? prototype.hi.x : prototype.lo.x,
                                                                 corner & 2 ? prototype.hi.y : prototype.lo.y,
                                                                 corner & 4 ? prototype.hi.z : prototype.lo.z});
            reached = std::max({reached, std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)});
        }
        check(instance.object, reached);
    }
    // An instance is traced in its prototype's own space: Embree takes each ray there, in
    // float, and stops the program on an origin beyond about 1.8e18 there too. Rays start at
    // the camera and on the finite shapes (a plane's far hits aside), so a bound on where
    // they start, taken into the prototype's space, bounds its origins: a prototype shrunk
    // by 1e-20 under a camera 5 away gave origins of 5e20. Such an instance is refused.
    const Camera& camera = scene.camera;
    const auto largest = [](const Vec3& v) { return std::max({std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)}); };
    const double origins = std::max(finite_reach, largest(camera.eye) + largest(camera.right) + largest(camera.up));
    // A ray starting beyond that (on a plane's far hit, or one from there) is taken up to the
    // finite shapes before it is traced (intersect, occluded): the rule holds for it too.
    finite_shapes_reach = finite_reach;
    rule_origins = origins;
    const auto transformed = [](const auto& shape) { return bool(shape.object_to_world); };
    rule_applies = !scene.instances.empty() || std::any_of(scene.spheres.begin(), scene.spheres.end(), transformed) ||
                   std::any_of(scene.boxes.begin(), scene.boxes.end(), transformed) ||
                   std::any_of(scene.cones.begin(), scene.cones.end(), transformed);
    // How far from the origin of an object's own space the rays start there.
    const auto origins_in_own_space = [&](const Transform& to_world) {
        const double shrink = largest(to_world.inverse_vector({1, 0, 0})) +
                              largest(to_world.inverse_vector({0, 1, 0})) + largest(to_world.inverse_vector({0, 0, 1}));
        return shrink * origins + largest(to_world.inverse_point({0, 0, 0}));
    };
    // A sphere, box or cone with a transform is intersected in its own space too, in double:
    // where rays start beyond 1e17 there, a double no longer places a hit on a shape of size 1
    // (its spacing is 16 at 1e17), so a box flattened by 1e-30 under a camera 5 away, or a
    // sphere of radius 1e30 scaled by 1e-30, drew something else than POV-Ray (48 % and 80 %
    // of the pixels alike). The instances' rule (below) refuses them, naming the object.
    const auto check_own_space = [&](const SharedTransform& to_world, const Vec3& own_lo, const Vec3& own_hi,
                                     uint32_t object) {
        if (!to_world) return;
        const SourceLocation where = object > 0 && object <= scene.objects.size() ? scene.objects[object - 1].where
                                                                                  : SourceLocation{scene.path, 0, 0};
        const std::string kind =
            object > 0 && object <= scene.objects.size() ? to_string(scene.objects[object - 1].type) : "object";
        char figure[32];
        const double own_reach = std::max(largest(own_lo), largest(own_hi));
        if (!(own_reach <= max_reach)) {
            std::snprintf(figure, sizeof figure, "%g", own_reach);
            throw InputError(where, kind + " reaches " + figure +
                                        " from the origin of its own space (before its transform); Whitted "
                                        "renders shapes within 1e15 of it (give the shape its size in its own "
                                        "numbers, not through the transform)");
        }
        const double in_own_space = origins_in_own_space(*to_world);
        if (!(in_own_space <= max_instance_origin)) {
            std::snprintf(figure, sizeof figure, "%g", in_own_space);
            throw InputError(where, kind + ": its transform shrinks or flattens it so far that rays reach " + figure +
                                        " in its own space; Whitted keeps them within 1e17 (give the shape "
                                        "its size in its own numbers, not through the transform)");
        }
    };
    for (const Sphere& sphere : scene.spheres)
        check_own_space(sphere.object_to_world, sphere.center - Vec3(sphere.radius),
                        sphere.center + Vec3(sphere.radius), sphere.object);
    for (const Box& box : scene.boxes) check_own_space(box.object_to_world, box.min, box.max, box.object);
    for (const Cone& cone : scene.cones) {
        Cone own = cone;
        own.object_to_world = nullptr;
        world_bounds(own, lo, hi);
        check_own_space(cone.object_to_world, lo, hi, cone.object);
    }
    for (const Instance& instance : scene.instances) {
        const Prototype& prototype = scene.prototypes[instance.prototype];
        const Transform& to_world = instance.object_to_world;
        const double in_prototype = origins_in_own_space(to_world);
        // The other way: a prototype of ±1e-20 enlarged by 1e20 aborted in Embree too (its rays'
        // directions shrink by as much in its space), while 1e19 rendered.
        const double grow = largest(to_world.apply_vector({1, 0, 0})) + largest(to_world.apply_vector({0, 1, 0})) +
                            largest(to_world.apply_vector({0, 0, 1}));
        const double prototype_reach = std::max(largest(prototype.lo), largest(prototype.hi));
        const SourceLocation where = instance.object > 0 && instance.object <= scene.objects.size()
                                         ? scene.objects[instance.object - 1].where
                                         : SourceLocation{scene.path, 0, 0};
        char figure[32];
        if (!(prototype_reach <= max_reach)) {
            std::snprintf(figure, sizeof figure, "%g", prototype_reach);
            throw InputError(where, std::string("instance: its prototype reaches ") + figure +
                                        " from the origin of its own space; Whitted renders prototypes within "
                                        "1e15 of it (scale its triangles down and the instance up)");
        }
        if (!(grow <= max_instance_origin)) {
            std::snprintf(figure, sizeof figure, "%g", grow);
            throw InputError(where, std::string("instance: its transform enlarges the prototype ") + figure +
                                        " times; Whitted renders instances enlarged up to 1e17 times (scale the "
                                        "prototype's triangles up instead)");
        }
        if (!(in_prototype <= max_instance_origin)) {
            std::snprintf(figure, sizeof figure, "%g", in_prototype);
            throw InputError(where, std::string("instance: its transform shrinks the prototype so far that rays "
                                                "reach ") +
                                        figure +
                                        " in the prototype's own space; Whitted keeps them within 1e17 (scale "
                                        "the prototype's triangles down instead)");
        }
    }
}

/// The frame: centred on the bounds of the scene's finite shapes when they lie further from
/// the origin than their half extent (the shifted coordinates then keep at least one more
/// bit), otherwise the world's; widen_triangles writes Embree's corners in it. Where the shifted
/// coordinates still reach M, Embree's float distances may be off by some ulp(M), 2^-23 M
/// each: once 16 of them exceed a quarter of the smallest minimum distance (surface_t_min,
/// 1e-4), that is from M ≈ 13 on, the range of each triangle candidate is decided in double
/// (EmbreeFrame::exact_range). Below that Embree's range decision stands: it cannot move a
/// hit across 1e-4 or the shadow window's 1e-3, and the filter's call per candidate cost the
/// 100k-triangle anchor 35 % (docs/validation.md, "Far from the origin").
EmbreeFrame Accelerator::Impl::choose_frame() const {
    constexpr double inf = std::numeric_limits<double>::infinity();
    Vec3 lo(inf), hi(-inf);
    for (const TriangleMesh& mesh : scene.meshes)
        for (uint32_t i = 0; i < mesh.vertex_count(); ++i) {
            lo = min(lo, mesh.vertex(i));
            hi = max(hi, mesh.vertex(i));
        }
    for (const Sphere& sphere : scene.spheres) {
        Vec3 a, b;
        world_bounds(sphere, a, b);
        lo = min(lo, a), hi = max(hi, b);
    }
    for (const Box& box : scene.boxes) {
        Vec3 a, b;
        world_bounds(box, a, b);
        lo = min(lo, a), hi = max(hi, b);
    }
    for (const Cone& cone : scene.cones) {
        Vec3 a, b;
        world_bounds(cone, a, b);
        lo = min(lo, a), hi = max(hi, b);
    }
    // An instance's float errors come from Embree's world-space ray (the frame's reach) and
    // from its prototype-space triangles, which the transform scales (at most by the largest
    // absolute row sum of its linear part).
    double local_reach = 0;
    for (const Instance& instance : scene.instances) {
        const Prototype& prototype = scene.prototypes[instance.prototype];
        for (int corner = 0; corner < 8; ++corner) {
            const Vec3 p = instance.object_to_world.apply_point({corner & 1 ? prototype.hi.x : prototype.lo.x,
                                                                 corner & 2 ? prototype.hi.y : prototype.lo.y,
                                                                 corner & 4 ? prototype.hi.z : prototype.lo.z});
            lo = min(lo, p), hi = max(hi, p);
        }
        const auto& m = instance.object_to_world.rows();
        double norm = 0;
        for (int row = 0; row < 3; ++row)
            norm = std::max(norm, std::fabs(m[4 * row]) + std::fabs(m[4 * row + 1]) + std::fabs(m[4 * row + 2]));
        local_reach = std::max({local_reach, norm * std::max({std::fabs(prototype.lo.x), std::fabs(prototype.lo.y),
                                                              std::fabs(prototype.lo.z), std::fabs(prototype.hi.x),
                                                              std::fabs(prototype.hi.y), std::fabs(prototype.hi.z)})});
    }
    EmbreeFrame chosen;
    if (!(lo.x <= hi.x)) return chosen;  // no finite shape: Embree has nothing to find
    const Vec3 centre = (lo + hi) * 0.5, half = (hi - lo) * 0.5;
    const double far = std::max({std::fabs(centre.x), std::fabs(centre.y), std::fabs(centre.z)});
    const double size = std::max({half.x, half.y, half.z});
    if (std::isfinite(far) && far > size) chosen.offset = centre;
    const Vec3 a = lo - chosen.offset, b = hi - chosen.offset;
    const double reach = std::max(
        {std::fabs(a.x), std::fabs(a.y), std::fabs(a.z), std::fabs(b.x), std::fabs(b.y), std::fabs(b.z), local_reach});
    chosen.exact_range = !(16 * std::ldexp(reach, -23) < ray_limits::surface_t_min / 4);
    // Camera rays start at the eye, or across the image plane for an orthographic camera.
    const Camera& camera = scene.camera;
    const auto magnitude = [](const Vec3& v) { return Vec3(std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)); };
    const Vec3 screen = (magnitude(camera.right) + magnitude(camera.up)) * 0.5;
    const Vec3 all_lo = min(a, camera.eye - chosen.offset - screen),
               all_hi = max(b, camera.eye - chosen.offset + screen);
    chosen.reach = std::max({reach, std::fabs(all_lo.x), std::fabs(all_lo.y), std::fabs(all_lo.z), std::fabs(all_hi.x),
                             std::fabs(all_hi.y), std::fabs(all_hi.z)});
    chosen.span = length(all_hi - all_lo);
    return chosen;
}
/// Whether `ray` starts where check_reach's rule does not reach: only a plane's far hits (up to
/// RaySpans::far_t_max = 1e16 from the eye, and further after bounces between planes) and the
/// rays from them start there. Embree takes such an origin in float, and an instance or a
/// transformed shape takes it into its own space, however much it shrinks there: the shadow ray
/// from a floor's hit 1e11 away gave Embree an origin of 1e19 in the space of an instance scaled
/// by 1e-8 (an abort).
bool Accelerator::Impl::starts_afar(const Ray& ray) const {
    return rule_applies &&
           std::max({std::fabs(ray.origin.x), std::fabs(ray.origin.y), std::fabs(ray.origin.z)}) > rule_origins;
}

/// `ray` (starting afar) from where it enters the cube that holds every finite shape: its origin
/// moved along it by `skipped`, its range shortened by as much. False when it does not meet the
/// cube within its range: no finite shape can be on it. The new origin is put inside the cube
/// (its rounding, an ulp of the far origin, is the ray's own uncertainty), so the rule bounds it.
bool Accelerator::Impl::toward_finite_shapes(const Ray& ray, Ray& near, double& skipped) const {
    const double cube = finite_shapes_reach;
    double enter = 0, leave = ray.t_max;
    const double origin[3] = {ray.origin.x, ray.origin.y, ray.origin.z};
    const double direction[3] = {ray.direction.x, ray.direction.y, ray.direction.z};
    for (int axis = 0; axis < 3; ++axis) {
        if (direction[axis] == 0) {
            if (!(std::fabs(origin[axis]) <= cube)) return false;
            continue;
        }
        double a = (-cube - origin[axis]) / direction[axis], b = (cube - origin[axis]) / direction[axis];
        if (a > b) std::swap(a, b);
        enter = std::max(enter, a);
        leave = std::min(leave, b);
    }
    if (!(enter <= leave) || !(leave > ray.t_min)) return false;
    // A little before the cube, so that a shape on its face is still ahead of `near`.
    const double margin = 1e-6 * cube, outer = cube + 2 * margin;
    skipped = std::max(0.0, enter - margin);
    const Vec3 at = ray.at(skipped);
    near.origin =
        Vec3(std::clamp(at.x, -outer, outer), std::clamp(at.y, -outer, outer), std::clamp(at.z, -outer, outer));
    near.direction = ray.direction;
    near.t_min = std::max(ray.t_min - enter, 0.0);
    near.t_max = ray.t_max - enter;
    return true;
}

}  // namespace whitted
