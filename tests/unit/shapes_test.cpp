// SPDX-License-Identifier: MIT
// Ray–shape intersection in closed form: distances from elementary geometry, normals from the
// shapes' definitions (for a transformed sphere, the gradient of its implicit equation).

#include "geometry/shapes.h"
#include "compat/povray/box.h"
#include "compat/povray/mesh2.h"
#include "core/transform.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <utility>

namespace whitted {
/// The shape that lost its rounding: a Vec3 of three neighbouring values rounded, in a function
/// of its own that takes a reference. noipa keeps it so: inlined into the test, or reshaped by
/// GCC's interprocedural passes, it was vectorised otherwise and kept its rounding.
[[gnu::noipa]] Vec3 rounded_to_float(const Vec3& a);
Vec3 rounded_to_float(const Vec3& a) {
    return {float_rounded(a.x), float_rounded(a.y), float_rounded(a.z)};
}

namespace {

constexpr double t_min = 1e-4, t_max = 1e7;

Ray ray_from(const Vec3& origin, const Vec3& direction) {
    return {origin, normalize(direction), t_min, t_max};
}

void expect_vec_near(const Vec3& actual, const Vec3& expected, double tol) {
    EXPECT_NEAR(actual.x, expected.x, tol);
    EXPECT_NEAR(actual.y, expected.y, tol);
    EXPECT_NEAR(actual.z, expected.z, tol);
}

TEST(Sphere, HitFromOutsideHeadOn) {
    const Sphere sphere{nullptr, {1, 2, 3}, 2, 0};
    ShapeHit hit;
    ASSERT_TRUE(intersect_sphere(sphere, ray_from({1, 2, 10}, {0, 0, -1}), t_min, t_max, hit));
    EXPECT_NEAR(hit.t, 10.0 - 3.0 - 2.0, 1e-12);  // from z = 10 to the near pole at z = 3 + 2
    expect_vec_near(normalize(hit.normal), {0, 0, 1}, 1e-12);
}

// Aimed at the centre of a sphere at (5, 5, 0) from the origin: the near surface is r short of
// the centre's distance 5√2.
TEST(Sphere, HitFromOutsideOblique) {
    const Sphere sphere{nullptr, {5, 5, 0}, 1, 0};
    ShapeHit hit;
    ASSERT_TRUE(intersect_sphere(sphere, ray_from({0, 0, 0}, {1, 1, 0}), t_min, t_max, hit));
    EXPECT_NEAR(hit.t, 5 * std::sqrt(2.0) - 1, 1e-12);
    expect_vec_near(normalize(hit.normal), normalize(Vec3{-1, -1, 0}), 1e-12);
}

// From the centre the ray meets the far side at t = r, and the normal is still the outward one
// (turning it toward the ray is the shader's job).
TEST(Sphere, HitFromInsideReturnsFarSideWithOutwardNormal) {
    const Sphere sphere{nullptr, {0, 0, 0}, 3, 0};
    ShapeHit hit;
    ASSERT_TRUE(intersect_sphere(sphere, ray_from({0, 0, 0}, {0, 1, 0}), t_min, t_max, hit));
    EXPECT_NEAR(hit.t, 3.0, 1e-12);
    expect_vec_near(normalize(hit.normal), {0, 1, 0}, 1e-12);
    // Off-centre inside: from (0, 1, 0) upward the far side is 2 away.
    ASSERT_TRUE(intersect_sphere(sphere, ray_from({0, 1, 0}, {0, 1, 0}), t_min, t_max, hit));
    EXPECT_NEAR(hit.t, 2.0, 1e-12);
}

TEST(Sphere, MissesBehindBesideAndBeyondRange) {
    const Sphere sphere{nullptr, {0, 0, -5}, 1, 0};
    ShapeHit hit;
    EXPECT_FALSE(intersect_sphere(sphere, ray_from({0, 0, 0}, {0, 0, 1}), t_min, t_max, hit));      // behind
    EXPECT_FALSE(intersect_sphere(sphere, ray_from({1.01, 0, 0}, {0, 0, -1}), t_min, t_max, hit));  // beside
    EXPECT_FALSE(intersect_sphere(sphere, ray_from({0, 0, 0}, {0, 0, -1}), t_min, 3.9, hit));       // t_max < 4
    EXPECT_TRUE(intersect_sphere(sphere, ray_from({0, 0, 0}, {0, 0, -1}), t_min, 4.1, hit));
}

// A shadow ray's test (sphere_blocks) finds a hit exactly where intersect_sphere does: the
// same cases as above, then random spheres, plain and transformed, with each ray's span ending
// just short of, at, and just past the hit intersect_sphere reports (both exclude t_max itself),
// and starting inside.
TEST(Sphere, BlocksExactlyWhereItIsHit) {
    const Sphere near{nullptr, {0, 0, -5}, 1, 0};
    EXPECT_FALSE(sphere_blocks(near, ray_from({0, 0, 0}, {0, 0, 1}), t_min, t_max));
    EXPECT_FALSE(sphere_blocks(near, ray_from({1.01, 0, 0}, {0, 0, -1}), t_min, t_max));
    EXPECT_FALSE(sphere_blocks(near, ray_from({0, 0, 0}, {0, 0, -1}), t_min, 3.9));
    EXPECT_TRUE(sphere_blocks(near, ray_from({0, 0, 0}, {0, 0, -1}), t_min, 4.1));
    EXPECT_TRUE(sphere_blocks(near, ray_from({0, 0, -5}, {1, 2, 3}), t_min, 1.1));  // from the centre: r away

    std::mt19937_64 random(38);
    std::uniform_real_distribution<double> coordinate(-10, 10), radius(0.01, 5), scale(0.2, 3);
    int hits = 0, cases = 0;
    for (int i = 0; i < 20000; ++i) {
        Sphere sphere{nullptr, {coordinate(random), coordinate(random), coordinate(random)}, radius(random), 0};
        if (i % 3 == 0)
            sphere.object_to_world = std::make_shared<const Transform>(
                Transform::scale({scale(random), scale(random), scale(random)})
                    .then(Transform::translate({coordinate(random), coordinate(random), coordinate(random)})));
        // Aimed near the sphere's world centre, so about half the rays meet it.
        const Vec3 origin{coordinate(random), coordinate(random), coordinate(random)};
        const Vec3 centre = sphere.object_to_world ? sphere.object_to_world->apply_point(sphere.center) : sphere.center;
        const Vec3 aim = centre + Vec3{coordinate(random), coordinate(random), coordinate(random)} * 0.3;
        if (length(aim - origin) == 0) continue;
        const Ray ray = ray_from(origin, aim - origin);
        ShapeHit hit;
        const bool found = intersect_sphere(sphere, ray, t_min, t_max, hit);
        ASSERT_EQ(sphere_blocks(sphere, ray, t_min, t_max), found) << i;
        ++cases;
        if (!found) continue;
        ++hits;
        for (const double end : {std::nextafter(hit.t, 0.0), hit.t, std::nextafter(hit.t, t_max)}) {
            ShapeHit shorter;
            ASSERT_EQ(sphere_blocks(sphere, ray, t_min, end), intersect_sphere(sphere, ray, t_min, end, shorter))
                << i << " end " << end;
        }
        // From just past the hit: the far side, or nothing.
        const double start = std::nextafter(hit.t, t_max);
        ShapeHit beyond;
        ASSERT_EQ(sphere_blocks(sphere, ray, start, t_max), intersect_sphere(sphere, ray, start, t_max, beyond)) << i;
    }
    EXPECT_GT(hits, cases / 5);  // the sample meets the spheres often enough to mean something
    EXPECT_LT(hits, cases);
}

// The unit sphere scaled by (2, 1, 1) is the ellipsoid x²/4 + y² + z² = 1, whose normal is the
// gradient ∝ (x/4, y, z): the inverse transpose of the scale, not the scaled radius vector.
TEST(Sphere, NonUniformScaleUsesInverseTransposeNormal) {
    const Sphere sphere{
        std::make_shared<const Transform>(Transform::scale({2, 1, 1}).then(Transform::translate({0, 3, 0}))),
        {0, 0, 0},
        1,
        0};
    ShapeHit hit;
    // Along x = 1, y = 3 (object y = 0): 1/4 + z² = 1 gives z = √3/2 on the near side.
    ASSERT_TRUE(intersect_sphere(sphere, ray_from({1, 3, 10}, {0, 0, -1}), t_min, t_max, hit));
    const double z = std::sqrt(3.0) / 2;
    EXPECT_NEAR(hit.t, 10 - z, 1e-12);
    const Vec3 gradient_normal = normalize(Vec3{1.0 / 4, 0, z});
    expect_vec_near(normalize(hit.normal), gradient_normal, 1e-12);
    // The naive normal (hit − centre) would be (1, 0, √3/2) normalised: clearly different.
    EXPECT_GT(length(normalize(Vec3{1, 0, z}) - gradient_normal), 0.1);
}

TEST(Sphere, WorldBoundsOfScaledSphere) {
    const Sphere sphere{
        std::make_shared<const Transform>(Transform::scale({2, 1, 0.5}).then(Transform::translate({1, 1, 1}))),
        {0, 0, 0},
        1,
        0};
    Vec3 lo, hi;
    world_bounds(sphere, lo, hi);
    expect_vec_near(lo, {-1, 0, 0.5}, 1e-12);
    expect_vec_near(hi, {3, 2, 1.5}, 1e-12);
}

// A ray toward the centre from outside each of the six faces of a non-cubic box hits that face
// at (5 − half-extent) with that face's outward normal.
TEST(Box, EachFaceFromOutside) {
    const Box box{nullptr, {-1, -2, -3}, {1, 2, 3}, 0};
    const Vec3 half{1, 2, 3};
    for (int axis = 0; axis < 3; ++axis) {
        for (const double sign : {-1.0, 1.0}) {
            Vec3 outward;
            outward[axis] = sign;
            ShapeHit hit;
            ASSERT_TRUE(intersect_box(box, ray_from(outward * 5, -outward), t_min, t_max, hit))
                << "axis " << axis << " sign " << sign;
            EXPECT_NEAR(hit.t, 5 - half[axis], 1e-12) << "axis " << axis << " sign " << sign;
            expect_vec_near(hit.normal, outward, 0.0);
        }
    }
}

TEST(Box, FromInsideHitsTheExitFace) {
    const Box box{nullptr, {-1, -1, -1}, {1, 1, 1}, 0};
    ShapeHit hit;
    ASSERT_TRUE(intersect_box(box, ray_from({0.5, 0, 0}, {1, 0, 0}), t_min, t_max, hit));
    EXPECT_NEAR(hit.t, 0.5, 1e-12);
    expect_vec_near(hit.normal, {1, 0, 0}, 0.0);
    // From (0, 0, 0.5) down −z: the exit face is z = −1, 1.5 away, with normal −z.
    ASSERT_TRUE(intersect_box(box, ray_from({0, 0, 0.5}, {0, 0, -1}), t_min, t_max, hit));
    EXPECT_NEAR(hit.t, 1.5, 1e-12);
    expect_vec_near(hit.normal, {0, 0, -1}, 0.0);
}

TEST(Box, MissesParallelOutsideSlabAndBehind) {
    const Box box{nullptr, {-1, -1, -1}, {1, 1, 1}, 0};
    ShapeHit hit;
    EXPECT_FALSE(intersect_box(box, ray_from({0, 1.5, 5}, {0, 0, -1}), t_min, t_max, hit));  // above the y slab
    EXPECT_FALSE(intersect_box(box, ray_from({0, 0, 5}, {0, 0, 1}), t_min, t_max, hit));     // box behind
    EXPECT_FALSE(intersect_box(box, ray_from({3, 0, 6}, {-1, 0, -1}), t_min, t_max, hit));   // passes beside
}

// Near an edge the face follows POV-Ray's rule (docs/pov-model.md §3, "Box edges"): a ray that
// meets the −x face δ below the top edge, where the top face's crossing comes δ/|d.y| earlier,
// is reported on the −x face if that is more than 1e-6 away in t, and otherwise on the face the
// ray runs more steeply along (the top, for a steep ray; still −x for a shallow one), at the t
// of the crossing held first (x's). Closed form: the ray passes through (−1, 1 − δ, 0.25).
// This is render.intersection: povray (what `whitted check` renders with).
TEST(Box, NearAnEdgeTheFaceFollowsPovRaysRule) {
    const Box box{nullptr, {-1, -1, -1}, {1, 1, 1}, 0};
    const auto hit_at = [&](double dx, double dy, double delta, ShapeHit& hit) {
        const Vec3 d = normalize(Vec3{dx, -dy, 0});
        const Vec3 on_face{-1, 1 - delta, 0.25};
        return intersect_box_as_povray(box, ray_from(on_face - d * 4, d), t_min, t_max, hit);
    };
    ShapeHit hit;
    // Steep (|d.y| = 2|d.x|): crossings δ/|d.y| apart.
    ASSERT_TRUE(hit_at(1, 2, 1e-3, hit));  // 4.5e-4 apart: the face the ray really meets
    expect_vec_near(hit.normal, {-1, 0, 0}, 0.0);
    EXPECT_NEAR(hit.t, 4, 1e-12);
    ASSERT_TRUE(hit_at(1, 2, 1e-7, hit));  // 4.5e-8 apart: one crossing, the steeper face
    expect_vec_near(hit.normal, {0, 1, 0}, 0.0);
    EXPECT_NEAR(hit.t, 4, 1e-12);  // x's crossing, the one held first
    // Shallow (|d.y| = |d.x|/2): the −x face whatever δ.
    ASSERT_TRUE(hit_at(2, 1, 1e-7, hit));
    expect_vec_near(hit.normal, {-1, 0, 0}, 0.0);
    // For z the steepness is weighed against the face held so far: a ray down −z meeting the
    // +z face 1e-7 inside the +x edge is reported on +z if |d.z| > |d.x|.
    const Vec3 d = normalize(Vec3{-1, 0, -3});
    const Vec3 on_face{1 - 1e-7, 0.5, 1};
    ASSERT_TRUE(intersect_box_as_povray(box, ray_from(on_face - d * 4, d), t_min, t_max, hit));
    expect_vec_near(hit.normal, {0, 0, 1}, 0.0);
    EXPECT_NEAR(hit.t, 4 - 1e-7 * std::sqrt(10.0), 1e-9);  // x's crossing, held first
}

// The exact rule (the default): the face is the one the ray really crosses, however close to the
// edge, and a ray exactly through an edge gets the face of the later axis. Scaled by k, the box
// and the ray give the same faces and k times the distances: no constant in t.
TEST(Box, ExactlyTheFaceIsTheOneTheRayCrosses) {
    for (const double k : {1e-3, 0.37, 1.0, 47.0, 1e3}) {
        const Box box{nullptr, {-k, -k, -k}, {k, k, k}, 0};
        const auto hit_at = [&](double dx, double dy, double delta, ShapeHit& hit) {
            const Vec3 d = normalize(Vec3{dx, -dy, 0});
            const Vec3 on_face = Vec3{-1, 1 - delta, 0.25} * k;
            return intersect_box(box, {on_face - d * (4 * k), d, 0, 1e16}, 0, 1e16, hit);
        };
        ShapeHit hit;
        for (const double delta : {1e-3, 1e-7, 1e-12}) {
            ASSERT_TRUE(hit_at(1, 2, delta, hit)) << k;  // the −x face, δ below its top edge
            expect_vec_near(hit.normal, {-1, 0, 0}, 0.0);
            EXPECT_NEAR(hit.t, 4 * k, 1e-12 * k);
        }
        // Through the edge itself (δ = 0): the top face, y's crossing coming after x's.
        ASSERT_TRUE(hit_at(1, 1, 0, hit)) << k;
        expect_vec_near(hit.normal, {0, 1, 0}, 0.0);
        EXPECT_NEAR(hit.t, 4 * k, 1e-12 * k);
    }
}

// A box turned 90° about z: its object x face now faces world +y, with the normal carried along.
TEST(Box, RotatedBoxNormalFollowsTransform) {
    const Box box{std::make_shared<const Transform>(Transform::rotate({0, 0, 1}, 90)), {-1, -2, -3}, {1, 2, 3}, 0};
    ShapeHit hit;
    // World +y extent is the object x extent (1).
    ASSERT_TRUE(intersect_box(box, ray_from({0, 10, 0}, {0, -1, 0}), t_min, t_max, hit));
    EXPECT_NEAR(hit.t, 9.0, 1e-12);
    expect_vec_near(normalize(hit.normal), {0, 1, 0}, 1e-12);
    // World +x extent is the object y extent (2).
    ASSERT_TRUE(intersect_box(box, ray_from({10, 0, 0}, {-1, 0, 0}), t_min, t_max, hit));
    EXPECT_NEAR(hit.t, 8.0, 1e-12);
    expect_vec_near(normalize(hit.normal), {1, 0, 0}, 1e-12);
}

/// A cone along +z from the origin: radius r0 at z = 0, r1 at z = h.
Cone cone_along_z(double r0, double r1, double h, bool open = false) {
    Cone cone;
    cone.base = {0, 0, 0};
    cone.axis = {0, 0, 1};
    cone.height = h;
    cone.base_radius = r0;
    cone.cap_radius = r1;
    cone.open = open;
    return cone;
}

TEST(Cylinder, SideCapsAndInsideInClosedForm) {
    const Cone cylinder = cone_along_z(0.5, 0.5, 2);
    ShapeHit hit;
    // Across the axis at z = 1: the side at x = 0.5, 3 − 0.5 away, normal +x (times r).
    ASSERT_TRUE(intersect_cone(cylinder, ray_from({3, 0, 1}, {-1, 0, 0}), t_min, t_max, hit));
    EXPECT_DOUBLE_EQ(hit.t, 2.5);
    expect_vec_near(normalize(hit.normal), {1, 0, 0}, 1e-15);
    // Down the axis from above: the cap at z = 2, normal +z.
    ASSERT_TRUE(intersect_cone(cylinder, ray_from({0.1, 0.2, 5}, {0, 0, -1}), t_min, t_max, hit));
    EXPECT_DOUBLE_EQ(hit.t, 3);
    expect_vec_near(normalize(hit.normal), {0, 0, 1}, 0);
    // Up from below: the base disc, normal −z.
    ASSERT_TRUE(intersect_cone(cylinder, ray_from({0, 0, -1}, {0, 0, 1}), t_min, t_max, hit));
    EXPECT_DOUBLE_EQ(hit.t, 1);
    expect_vec_near(normalize(hit.normal), {0, 0, -1}, 0);
    // A slanted ray: x = 3 − 3s/5·..., solved by hand: from (3, 0, 0) toward (−1, 0, 0.25)·k.
    const Vec3 d = normalize(Vec3(-1, 0, 0.25));
    ASSERT_TRUE(intersect_cone(cylinder, ray_from({3, 0, 0}, d), t_min, t_max, hit));
    EXPECT_NEAR(hit.t, 2.5 / -d.x, 1e-14);
    // Beside it, and past its ends: no hit.
    EXPECT_FALSE(intersect_cone(cylinder, ray_from({3, 0.51, 1}, {-1, 0, 0}), t_min, t_max, hit));
    EXPECT_FALSE(intersect_cone(cylinder, ray_from({3, 0, 2.01}, {-1, 0, 0}), t_min, t_max, hit));
    EXPECT_FALSE(intersect_cone(cylinder, ray_from({0.6, 0, 5}, {0, 0, -1}), t_min, t_max, hit));
}

TEST(Cylinder, OpenEndsShowTheInsideWall) {
    const Cone open = cone_along_z(0.5, 0.5, 2, true);
    ShapeHit hit;
    // Down the axis: no cap, and the wall is parallel: nothing.
    EXPECT_FALSE(intersect_cone(open, ray_from({0, 0, 5}, {0, 0, -1}), t_min, t_max, hit));
    // Into the open top at an angle: the inner wall, on the far side (x = −0.5).
    const Vec3 d = normalize(Vec3(-1, 0, -1));
    ASSERT_TRUE(intersect_cone(open, ray_from({0.25, 0, 2.5}, d), t_min, t_max, hit));
    EXPECT_NEAR(hit.t, 0.75 / -d.x, 1e-14);
    expect_vec_near(normalize(hit.normal), {-1, 0, 0}, 1e-15);  // outward: Whitted turns it to the ray
    // Closed, the same ray meets the cap first.
    ASSERT_TRUE(intersect_cone(cone_along_z(0.5, 0.5, 2), ray_from({0.25, 0, 2.5}, d), t_min, t_max, hit));
    EXPECT_NEAR(hit.t, 0.5 / -d.z, 1e-14);
}

TEST(Cone, SlantedSideNormalAndPoint) {
    // Radius 1 at z = 0 to a point at z = 1: the side is x + z = 1 in the xz plane, normal (1, 0, 1)/√2.
    const Cone cone = cone_along_z(1, 0, 1);
    ShapeHit hit;
    ASSERT_TRUE(intersect_cone(cone, ray_from({3, 0, 0.5}, {-1, 0, 0}), t_min, t_max, hit));
    EXPECT_DOUBLE_EQ(hit.t, 2.5);
    expect_vec_near(normalize(hit.normal), normalize(Vec3(1, 0, 1)), 1e-15);
    // Straight down onto the point: the axis is the normal there.
    ASSERT_TRUE(intersect_cone(cone, ray_from({0, 0, 3}, {0, 0, -1}), t_min, t_max, hit));
    EXPECT_DOUBLE_EQ(hit.t, 2);
    expect_vec_near(normalize(hit.normal), {0, 0, 1}, 0);
    // A truncated cone wider at the top (cap_radius > base_radius): side at z = 1 is at r = 1.5.
    const Cone funnel = cone_along_z(0.5, 2.5, 2);
    ASSERT_TRUE(intersect_cone(funnel, ray_from({4, 0, 1}, {-1, 0, 0}), t_min, t_max, hit));
    EXPECT_DOUBLE_EQ(hit.t, 2.5);
    expect_vec_near(normalize(hit.normal), normalize(Vec3(1, 0, -1)), 1e-15);
    // The other nappe of the double cone (beyond the point) is not part of the cone.
    EXPECT_FALSE(intersect_cone(cone, ray_from({3, 0, 1.5}, {-1, 0, 0}), t_min, t_max, hit));
}

TEST(Cone, AnyAxisAndATransformGiveTheSameHits) {
    // The cylinder along z, turned to lie along x by a rotation, against one built along x.
    Cone along_x = cone_along_z(0.5, 0.5, 2);
    along_x.axis = {1, 0, 0};
    Cone turned = cone_along_z(0.5, 0.5, 2);
    turned.object_to_world = std::make_shared<const Transform>(Transform::rotate({0, 1, 0}, 90));
    ShapeHit a, b;
    ASSERT_TRUE(intersect_cone(along_x, ray_from({1, 3, 0.2}, {0, -1, 0}), t_min, t_max, a));
    ASSERT_TRUE(intersect_cone(turned, ray_from({1, 3, 0.2}, {0, -1, 0}), t_min, t_max, b));
    EXPECT_NEAR(a.t, 3 - std::sqrt(0.25 - 0.04), 1e-14);
    EXPECT_NEAR(b.t, a.t, 1e-14);
    expect_vec_near(normalize(b.normal), normalize(a.normal), 1e-14);
    // Bounds: the discs' extents, r·√(1 − w_i²) across each coordinate axis.
    Vec3 lo, hi;
    world_bounds(along_x, lo, hi);
    expect_vec_near(lo, {0, -0.5, -0.5}, 0);
    expect_vec_near(hi, {2, 0.5, 0.5}, 0);
}

TEST(Plane, HitAtClosedFormDistance) {
    const Plane plane{{0, -1, 0}, {0, 1, 0}, 0};
    ShapeHit hit;
    // From y = 1 at 45° down: 2 down and 2 across, t = 2√2.
    ASSERT_TRUE(intersect_plane(plane, ray_from({0, 1, 0}, {1, -1, 0}), t_min, t_max, hit));
    EXPECT_NEAR(hit.t, 2 * std::sqrt(2.0), 1e-12);
    expect_vec_near(hit.normal, {0, 1, 0}, 0.0);
    // From below, the same plane is hit on its back; the normal stays the plane's own.
    ASSERT_TRUE(intersect_plane(plane, ray_from({0, -4, 0}, {0, 1, 0}), t_min, t_max, hit));
    EXPECT_NEAR(hit.t, 3.0, 1e-12);
    expect_vec_near(hit.normal, {0, 1, 0}, 0.0);
}

TEST(Plane, ParallelAndBehindMiss) {
    const Plane plane{{0, -1, 0}, {0, 1, 0}, 0};
    ShapeHit hit;
    EXPECT_FALSE(intersect_plane(plane, ray_from({0, 1, 0}, {1, 0, 0}), t_min, t_max, hit));   // parallel above
    EXPECT_FALSE(intersect_plane(plane, ray_from({0, -1, 0}, {0, 0, 1}), t_min, t_max, hit));  // parallel, in it
    EXPECT_FALSE(intersect_plane(plane, ray_from({0, 1, 0}, {0, 1, 0}), t_min, t_max, hit));   // plane behind
}

// Barycentrics: the point (1 − u − v)·v0 + u·v1 + v·v2 must come back as (u, v).
TEST(Triangle, BarycentricsOfAKnownPoint) {
    const Vec3 v0{1, 0, 0}, v1{0, 2, 0}, v2{0, 0, 3};
    const double u = 0.3, v = 0.5;
    const Vec3 target = v0 * (1 - u - v) + v1 * u + v2 * v;
    const Vec3 direction = normalize(Vec3{-1, -2, -0.5});
    ShapeHit hit;
    ASSERT_TRUE(intersect_triangle(v0, v1, v2, {target - direction * 2.5, direction, t_min, t_max}, t_min, t_max, hit));
    EXPECT_NEAR(hit.t, 2.5, 1e-12);
    EXPECT_NEAR(hit.u, u, 1e-12);
    EXPECT_NEAR(hit.v, v, 1e-12);
    expect_vec_near(hit.normal, cross(v1 - v0, v2 - v0), 1e-12);
    EXPECT_GT(dot(hit.normal, Vec3{1, 1, 1}), 0);  // (v1 − v0) × (v2 − v0) points away from the origin here
}

TEST(Triangle, MissesOutsideEdgesAndWhenParallel) {
    const Vec3 v0{0, 0, 0}, v1{1, 0, 0}, v2{0, 1, 0};
    ShapeHit hit;
    EXPECT_FALSE(intersect_triangle(v0, v1, v2, ray_from({0.6, 0.6, 1}, {0, 0, -1}), t_min, t_max, hit));  // u+v>1
    EXPECT_FALSE(intersect_triangle(v0, v1, v2, ray_from({-0.1, 0.5, 1}, {0, 0, -1}), t_min, t_max, hit));
    EXPECT_FALSE(intersect_triangle(v0, v1, v2, ray_from({0.2, 0.2, 1}, {1, 0, 0}), t_min, t_max, hit));  // parallel
    EXPECT_FALSE(intersect_triangle(v0, v1, v2, ray_from({0.2, 0.2, 1}, {0, 0, 1}), t_min, t_max, hit));  // behind
    ASSERT_TRUE(intersect_triangle(v0, v1, v2, ray_from({0.2, 0.2, -1}, {0, 0, 1}), t_min, t_max, hit));  // back face
    EXPECT_NEAR(hit.t, 1.0, 1e-12);
}

// The margin of the exact test: a ray 1e-9 (in u + v) beyond the edge u + v = 1 misses with the
// margin of 1e-10 the renderer uses and hits with one of 1e-8; and a ray along the edge that two
// triangles share, at coordinates double cannot hold exactly, meets at least one of them.
TEST(Triangle, EdgeMarginIsBarycentric) {
    const Vec3 v0{0, 0, 0}, v1{1, 0, 0}, v2{0, 1, 0}, v3{1, 1, 0};
    ShapeHit hit;
    const Ray beyond = ray_from({0.5 + 5e-10, 0.5 + 5e-10, 1}, {0, 0, -1});
    EXPECT_FALSE(intersect_triangle(v0, v1, v2, beyond, t_min, t_max, hit, 1e-10));
    EXPECT_TRUE(intersect_triangle(v0, v1, v2, beyond, t_min, t_max, hit, 1e-8));
    for (int k = 1; k < 1000; ++k) {
        const double x = k / 1000.0 + 1.0 / 3e6;  // on the shared edge x + y = 1, rounded
        const Vec3 on_edge{x, 1 - x, 0};
        const Vec3 direction = normalize(Vec3{1e-3 * std::sin(k), 1e-3 * std::cos(k), -1});
        const Ray through{on_edge - direction * 2.5, direction, t_min, t_max};
        ShapeHit a, b;
        EXPECT_TRUE(intersect_triangle(v0, v1, v2, through, t_min, t_max, a, 1e-10) ||
                    intersect_triangle(v1, v3, v2, through, t_min, t_max, b, 1e-10))
            << "x = " << x;
    }
}

// POV-Ray's mesh2 triangle (docs/pov-model.md §3, "Mesh triangles"), in closed form: a triangle
// in the plane z = 0.5 met from z = 2 straight down at depth 1.5, inside at (0.25, 0.25) and
// outside at (0.8, 0.8) (the plane is still met: `inside` says which); the same for either
// winding (POV-Ray turns the corners one way before its edge tests); no hit behind the ray
// (depth below 1e-6), parallel to the plane or on a degenerate triangle.
TEST(Mesh2Triangle, DepthAndEdgesInClosedForm) {
    const Vec3 p1{0, 0, 0.5}, p2{1, 0, 0.5}, p3{0, 1, 0.5};
    for (const bool flipped : {false, true}) {
        const Vec3& a = flipped ? p2 : p1;
        const Vec3& b = flipped ? p1 : p2;
        double depth = 0;
        bool inside = false;
        ASSERT_TRUE(intersect_mesh2_triangle(a, b, p3, {0.25, 0.25, 2}, {0, 0, -1}, depth, inside));
        EXPECT_EQ(depth, 1.5);
        EXPECT_TRUE(inside);
        ASSERT_TRUE(intersect_mesh2_triangle(a, b, p3, {0.8, 0.8, 2}, {0, 0, -1}, depth, inside));
        EXPECT_EQ(depth, 1.5);
        EXPECT_FALSE(inside);
        EXPECT_FALSE(intersect_mesh2_triangle(a, b, p3, {0.25, 0.25, 2}, {0, 0, 1}, depth, inside));  // behind
        EXPECT_FALSE(intersect_mesh2_triangle(a, b, p3, {0.25, 0.25, 2}, {1, 0, 0}, depth, inside));  // parallel
    }
    double depth = 0;
    bool inside = false;
    EXPECT_FALSE(intersect_mesh2_triangle(p1, p2, p1 + (p2 - p1) * 0.5, {0.25, 0, 2}, {0, 0, -1}, depth, inside));
}

// The plane is kept in single precision. For the triangle (1, 0, 0), (0, 2, 0), (0, 0, 3) the
// normal (p3 − p1) × (p2 − p1) is (−6, −3, −2), length 7, so the unit normal n is (−6, −3, −2)/7
// and the distance −n·p1 = 6/7, none of them a float. For a ray from (0.1, 0.2, 3) along a
// unit direction d at a grazing 1e-4 rad to the plane the depth is −(D + S·o) / (S·d), with S
// the unit normal and D the distance each rounded to float (computed here through float
// variables); the exact depth, from the double plane, is far from it: the float plane's tilt
// and offset (some 1e-8) divided by the grazing angle, beyond double's rounding by far.
TEST(Mesh2Triangle, TheDistanceIsTheFloatPlanes) {
    const Vec3 p1{1, 0, 0}, p2{0, 2, 0}, p3{0, 0, 3};
    const Vec3 origin{0.1, 0.2, 3};
    const double seventh = 1.0 / 7;
    const Vec3 n{-6 * seventh, -3 * seventh, -2 * seventh};
    const Vec3 in_plane = normalize(cross(n, Vec3{0, 0, 1}));
    const Vec3 d = normalize(in_plane + n * 1e-4);
    volatile float s_x = float(n.x), s_y = float(n.y), s_z = float(n.z);
    volatile float n_dot_p1 = float(n.x * p1.x + n.y * p1.y + n.z * p1.z);
    const Vec3 s{s_x, s_y, s_z};
    const double distance = -double(n_dot_p1);
    const double expected =
        -(distance + (s.x * origin.x + s.y * origin.y + s.z * origin.z)) / (s.x * d.x + s.y * d.y + s.z * d.z);
    const double exact = -(dot(n, origin) - dot(n, p1)) / dot(n, d);
    double depth = 0;
    bool inside = false;
    ASSERT_TRUE(intersect_mesh2_triangle(p1, p2, p3, origin, d, depth, inside));
    EXPECT_NEAR(depth, expected, 1e-12 * std::fabs(expected));
    EXPECT_GT(std::fabs(depth - exact), 1e-6);
    EXPECT_LT(std::fabs(depth - exact), 1e-1);
}

// POV-Ray's smooth normal is the lecture's barycentric blend of the vertex normals, computed
// its own way: on the plane it agrees with n1·(1 − u − v) + n2·u + n3·v to float precision, at
// p1 it is n1 itself, and it does not depend on the winding the face was given in.
TEST(Mesh2SmoothNormal, IsTheBarycentricBlend) {
    const Vec3 p1{0.2, -0.1, 0.4}, p2{1.3, 0.2, -0.3}, p3{-0.4, 1.1, 0.1};
    const Vec3 n1 = normalize(Vec3{0.1, 0.2, 1}), n2 = normalize(Vec3{0.5, -0.1, 0.8}),
               n3 = normalize(Vec3{-0.3, 0.6, 0.7});
    for (const auto& [u, v] : {std::pair{0.2, 0.3}, std::pair{0.6, 0.1}, std::pair{0.05, 0.9}}) {
        const Vec3 point = p1 * (1 - u - v) + p2 * u + p3 * v;
        const Vec3 expected = normalize(n1 * (1 - u - v) + n2 * u + n3 * v);
        expect_vec_near(normalize(mesh2_smooth_normal(p1, p2, p3, n1, n2, n3, point)), expected, 1e-6);
        expect_vec_near(normalize(mesh2_smooth_normal(p2, p1, p3, n2, n1, n3, point)), expected, 1e-6);
    }
    const Vec3 at_p1 = mesh2_smooth_normal(p1, p2, p3, n1, n2, n3, p1);
    EXPECT_EQ(at_p1.x, n1.x);
    EXPECT_EQ(at_p1.y, n1.y);
    EXPECT_EQ(at_p1.z, n1.z);
}

// float_rounded keeps the rounding to float of neighbouring values, which GCC 12's SLP
// vectoriser dropped from Vec3{float(a.x), float(a.y), float(a.z)} (vec3.h): with a plain
// float conversion in float_rounded this test fails in the Release build (x and y come back
// unrounded; so does PovWriter.NormalsAreWrittenAsFloats). The
// inputs are read at run time so that nothing is folded before the vectoriser sees it.
TEST(FloatRounded, NeighbouringValuesAreEachRounded) {
    volatile double inputs[3] = {0.42426406871192845, 0.565685424949238, 0.7071067811865476};
    const Vec3 rounded = rounded_to_float({inputs[0], inputs[1], inputs[2]});
    for (int axis = 0; axis < 3; ++axis) {
        volatile float single = float(inputs[axis]);
        EXPECT_EQ(rounded[axis], double(single)) << "axis " << axis;
        EXPECT_NE(rounded[axis], inputs[axis]) << "axis " << axis;  // none of the three is a float
    }
}

// A small sphere far away: |oc|² and along² agree in nearly every digit, so a test that
// subtracts them loses r² entirely (radius 1e-3 at 1e5: relative error in the half chord of
// order 1). The distances here are closed-form: t = D − sqrt(r² − p²) at perpendicular offset p.
TEST(Sphere, SmallAndFarStaysAccurate) {
    for (const double distance : {1e3, 1e5, 1e6}) {
        const double r = 1e-3;
        const Sphere sphere{nullptr, {0.3, -0.2, distance}, r, 0};
        for (const double offset : {0.0, 0.5 * r, 0.9 * r}) {
            ShapeHit hit;
            const Ray ray{{0.3 + offset, -0.2, 0}, {0, 0, 1}, t_min, 1e9};
            ASSERT_TRUE(intersect_sphere(sphere, ray, t_min, 1e9, hit)) << distance << " " << offset;
            const double expected = distance - std::sqrt(r * r - offset * offset);
            // A few ulps of the distance itself: the best a double t can do.
            EXPECT_NEAR(hit.t, expected, 8 * distance * 1.1e-16 + 1e-12) << distance << " " << offset;
        }
        ShapeHit miss;
        EXPECT_FALSE(intersect_sphere(sphere, {{0.3 + 1.01 * r, -0.2, 0}, {0, 0, 1}, t_min, 1e9}, t_min, 1e9, miss));
    }
}

// next_up (vec3.h) stands in for std::nextafter(x, +infinity) on the hot path: the same value,
// bit for bit, at the special values and at a million random bit patterns of each width.
template <class Real, class Bits>
void expect_next_up_is_nextafter() {
    const Real inf = std::numeric_limits<Real>::infinity();
    const Real special[] = {Real(0),
                            -Real(0),
                            std::numeric_limits<Real>::denorm_min(),
                            -std::numeric_limits<Real>::denorm_min(),
                            std::numeric_limits<Real>::min(),
                            -std::numeric_limits<Real>::min(),
                            std::numeric_limits<Real>::max(),
                            -std::numeric_limits<Real>::max(),
                            inf,
                            -inf,
                            Real(1),
                            Real(-1),
                            Real(0.1),
                            Real(-0.1)};
    for (const Real x : special)
        EXPECT_EQ(std::bit_cast<Bits>(next_up(x)), std::bit_cast<Bits>(std::nextafter(x, inf))) << x;
    EXPECT_TRUE(std::isnan(next_up(std::numeric_limits<Real>::quiet_NaN())));
    std::mt19937_64 random(4620);
    for (int i = 0; i < 1000000; ++i) {
        const Real x = std::bit_cast<Real>(Bits(random()));
        if (std::isnan(x)) continue;
        ASSERT_EQ(std::bit_cast<Bits>(next_up(x)), std::bit_cast<Bits>(std::nextafter(x, inf))) << x;
    }
}

TEST(NextUp, IsNextafterTowardInfinity) {
    expect_next_up_is_nextafter<double, uint64_t>();
    expect_next_up_is_nextafter<float, uint32_t>();
}

}  // namespace
}  // namespace whitted
