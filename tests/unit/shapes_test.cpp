// SPDX-License-Identifier: MIT
// Ray–shape intersection in closed form: distances from elementary geometry, normals from the
// shapes' definitions (for a transformed sphere, the gradient of its implicit equation).

#include "whitted/geometry/shapes.h"
#include "whitted/core/transform.h"

#include <gtest/gtest.h>

#include <cmath>

namespace whitted {
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
TEST(Box, NearAnEdgeTheFaceFollowsPovRaysRule) {
    const Box box{nullptr, {-1, -1, -1}, {1, 1, 1}, 0};
    const auto hit_at = [&](double dx, double dy, double delta, ShapeHit& hit) {
        const Vec3 d = normalize(Vec3{dx, -dy, 0});
        const Vec3 on_face{-1, 1 - delta, 0.25};
        return intersect_box(box, ray_from(on_face - d * 4, d), t_min, t_max, hit);
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
    ASSERT_TRUE(intersect_box(box, ray_from(on_face - d * 4, d), t_min, t_max, hit));
    expect_vec_near(hit.normal, {0, 0, 1}, 0.0);
    EXPECT_NEAR(hit.t, 4 - 1e-7 * std::sqrt(10.0), 1e-9);  // x's crossing, held first
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

// The fallback for a float hit just over an edge: the plane's distance, whatever the edges and
// the range say, and the barycentrics pulled back onto the triangle.
TEST(Triangle, PlaneHitClampsBarycentricsOntoTheTriangle) {
    const Vec3 v0{0, 0, 0}, v1{1, 0, 0}, v2{0, 1, 0};
    ShapeHit hit;
    // Outside the edge u + v = 1, at (0.75, 0.5): u = 0.75, v = 0.5 scaled to sum 1.
    ASSERT_TRUE(hit_triangle_plane(v0, v1, v2, ray_from({0.75, 0.5, 2}, {0, 0, -1}), hit));
    EXPECT_NEAR(hit.t, 2.0, 1e-12);
    EXPECT_NEAR(hit.u, 0.6, 1e-12);
    EXPECT_NEAR(hit.v, 0.4, 1e-12);
    expect_vec_near(hit.normal, {0, 0, 1}, 1e-12);
    // Beyond the edge v = 0 (v = -0.25): v becomes 0, u stays.
    ASSERT_TRUE(hit_triangle_plane(v0, v1, v2, ray_from({0.5, -0.25, 3}, {0, 0, -1}), hit));
    EXPECT_NEAR(hit.t, 3.0, 1e-12);
    EXPECT_NEAR(hit.u, 0.5, 1e-12);
    EXPECT_EQ(hit.v, 0.0);
    // Inside, it agrees with intersect_triangle.
    ShapeHit exact;
    const Ray inside = ray_from({0.2, 0.3, -1}, {0.1, 0, 1});
    ASSERT_TRUE(intersect_triangle(v0, v1, v2, inside, t_min, t_max, exact));
    ASSERT_TRUE(hit_triangle_plane(v0, v1, v2, inside, hit));
    EXPECT_EQ(hit.t, exact.t);
    EXPECT_EQ(hit.u, exact.u);
    EXPECT_EQ(hit.v, exact.v);
    // Parallel to the plane: no answer.
    EXPECT_FALSE(hit_triangle_plane(v0, v1, v2, ray_from({0.2, 0.2, 1}, {1, 0, 0}), hit));
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

}  // namespace
}  // namespace whitted
