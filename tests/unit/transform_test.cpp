// SPDX-License-Identifier: MIT
// Transforms: list order (scale, then rotate, then translate), the right-hand rule, inverses and
// normals, against hand-worked points.

#include "core/transform.h"
#include "geometry/shapes.h"
#include "scene/scene.h"

#include "test_support.h"

#include <gtest/gtest.h>

#include <cmath>

namespace whitted {
namespace {

void expect_vec_near(const Vec3& actual, const Vec3& expected, double tol) {
    EXPECT_NEAR(actual.x, expected.x, tol);
    EXPECT_NEAR(actual.y, expected.y, tol);
    EXPECT_NEAR(actual.z, expected.z, tol);
}

TransformStep step(TransformStep::Kind kind, const Vec3& v, double angle = 0) {
    TransformStep s;
    s.kind = kind;
    s.vector = v;
    s.angle = angle;
    return s;
}

// (1, 0, 0) scaled by 2 → (2, 0, 0), turned 90° about +z → (0, 2, 0), moved by (0, 0, 5) → (0, 2, 5).
TEST(Transform, ListOrderIsScaleThenRotateThenTranslate) {
    using K = TransformStep::Kind;
    const Transform t =
        make_transform({step(K::scale, {2, 2, 2}), step(K::rotate, {0, 0, 1}, 90), step(K::translate, {0, 0, 5})});
    expect_vec_near(t.apply_point({1, 0, 0}), {0, 2, 5}, 1e-12);
    // Reversed list: translate to (1, 0, 5), rotate to (0, 1, 5), scale to (0, 2, 10).
    const Transform reversed =
        make_transform({step(K::translate, {0, 0, 5}), step(K::rotate, {0, 0, 1}, 90), step(K::scale, {2, 2, 2})});
    expect_vec_near(reversed.apply_point({1, 0, 0}), {0, 2, 10}, 1e-12);
    // Vectors ignore the translation.
    expect_vec_near(t.apply_vector({1, 0, 0}), {0, 2, 0}, 1e-12);
}

TEST(Transform, ThenAppliesLeftFirst) {
    const Transform a = Transform::translate({1, 0, 0});
    const Transform b = Transform::scale({3, 1, 1});
    expect_vec_near(a.then(b).apply_point({1, 1, 1}), {6, 1, 1}, 1e-12);  // (1+1)·3
    expect_vec_near(b.then(a).apply_point({1, 1, 1}), {4, 1, 1}, 1e-12);  // 1·3+1
}

// Right-hand rule: a positive angle turns x toward y about +z, y toward z about +x, z toward x
// about +y; 120° about (1, 1, 1) permutes the axes cyclically.
TEST(Transform, RotationFollowsRightHandRule) {
    expect_vec_near(Transform::rotate({0, 0, 1}, 90).apply_point({1, 0, 0}), {0, 1, 0}, 1e-12);
    expect_vec_near(Transform::rotate({2, 0, 0}, 90).apply_point({0, 1, 0}), {0, 0, 1}, 1e-12);
    expect_vec_near(Transform::rotate({0, 0.5, 0}, 90).apply_point({0, 0, 1}), {1, 0, 0}, 1e-12);
    const Transform cyclic = Transform::rotate({1, 1, 1}, 120);
    expect_vec_near(cyclic.apply_point({1, 0, 0}), {0, 1, 0}, 1e-12);
    expect_vec_near(cyclic.apply_point({0, 1, 0}), {0, 0, 1}, 1e-12);
    // 30° about z: (cos 30°, sin 30°, 0).
    expect_vec_near(Transform::rotate({0, 0, 1}, 30).apply_point({1, 0, 0}), {std::sqrt(3.0) / 2, 0.5, 0}, 1e-12);
    EXPECT_NEAR(Transform::rotate({1, 2, 3}, 77).determinant(), 1.0, 1e-12);
}

TEST(Transform, InverseUndoesForward) {
    const Transform t = Transform::scale({1, 2, 3})
                            .then(Transform::rotate({1, 2, 3}, 37))
                            .then(Transform::translate({4, 5, 6}))
                            .then(Transform::rotate({0, 1, 0}, -110));
    for (const Vec3& p : {Vec3{0, 0, 0}, Vec3{1, -2, 3}, Vec3{-7.5, 0.25, 11}}) {
        expect_vec_near(t.inverse_point(t.apply_point(p)), p, 1e-12);
        expect_vec_near(t.apply_point(t.inverse_point(p)), p, 1e-12);
        expect_vec_near(t.inverse_vector(t.apply_vector(p)), p, 1e-12);
    }
    EXPECT_NEAR(t.determinant(), 1.0 * 2.0 * 3.0, 1e-12);  // rotations keep volume
}

// About a coordinate axis, that axis's row and column stay exactly those of the identity, for
// any angle and then a move across it: a box turned about y keeps its top at exactly its height,
// so two equal boxes turned differently meet a ray at exactly the same t (cube_field.py
// --turned). Rodrigues' c + (1 − c) gave 1 − 2⁻⁵³ for 9 % of angles.
TEST(Transform, TurningAboutACoordinateAxisLeavesThatAxisExact) {
    for (int i = 0; i < 3600; ++i) {
        const double degrees = i * 0.1 + 0.0123;
        const Transform t = Transform::rotate({0, 1, 0}, degrees).then(Transform::translate({-17.95, 0, 19.64}));
        const auto& m = t.rows();
        ASSERT_EQ(m[4], 0.0) << degrees;
        ASSERT_EQ(m[5], 1.0) << degrees;
        ASSERT_EQ(m[6], 0.0) << degrees;
        ASSERT_EQ(m[7], 0.0) << degrees;
        const Vec3 up = t.inverse_vector({0.3, -0.24, -0.9});
        ASSERT_EQ(up.y, -0.24) << degrees;
        ASSERT_EQ(t.inverse_point({0, 12, 24}).y, 12.0) << degrees;
    }
    EXPECT_EQ(Transform::rotate({2, 0, 0}, 142.98).rows()[0], 1.0);
    EXPECT_EQ(Transform::rotate({0, 0, -3}, 142.98).rows()[10], 1.0);
}

// The inverse depends on the whole matrix only, as POV-Ray's does: `whitted convert` writes
// an object's transform as one matrix and POV-Ray inverts that, so a composed transform and the
// same rows taken as one must take a ray into the object's space with the same bits.
TEST(Transform, TheInverseIsThatOfTheWholeMatrix) {
    const Transform composed = Transform::scale({1, 2, 3})
                                   .then(Transform::rotate({1, 2, 3}, 37))
                                   .then(Transform::translate({4, 5, 6}))
                                   .then(Transform::rotate({0, 1, 0}, -110));
    const Transform whole = Transform::from_rows(composed.rows());
    for (const Vec3& p : {Vec3{0, 0, 0}, Vec3{1, -2, 3}, Vec3{-7.5, 0.25, 11}, Vec3{0.1, 0.2, 0.3}}) {
        const Vec3 a = composed.inverse_point(p), b = whole.inverse_point(p);
        EXPECT_EQ(a.x, b.x);
        EXPECT_EQ(a.y, b.y);
        EXPECT_EQ(a.z, b.z);
    }
    // Exact where the arithmetic is: a scale by powers of two and a move.
    const Transform dyadic = Transform::scale({2, 4, 0.5}).then(Transform::translate({1, -3, 8}));
    const Vec3 back = dyadic.inverse_point({5, 1, 9});
    EXPECT_EQ(back.x, 2.0);
    EXPECT_EQ(back.y, 1.0);
    EXPECT_EQ(back.z, 2.0);
}

// Normals stay perpendicular to transformed tangents: apply_normal is the inverse transpose.
TEST(Transform, NormalsStayPerpendicularToTangents) {
    const Transform t =
        Transform::scale({4, 1, 0.25}).then(Transform::rotate({1, 1, 0}, 40)).then(Transform::translate({1, 2, 3}));
    const Vec3 normal = normalize(Vec3{1, 1, 1});
    for (const Vec3& tangent : {Vec3{1, -1, 0}, Vec3{0, 1, -1}, Vec3{1, 0, -1}}) {
        ASSERT_NEAR(dot(normal, tangent), 0, 1e-15);
        EXPECT_NEAR(dot(t.apply_normal(normal), t.apply_vector(tangent)), 0, 1e-12);
    }
    // The plain linear map does not keep the angle here (so the check above has teeth).
    EXPECT_GT(std::fabs(dot(t.apply_vector(normal), t.apply_vector(Vec3{1, -1, 0}))), 0.1);
}

// A row-major 4x4 `matrix` step with the translation in the last column.
TEST(Transform, MatrixStepIsRowMajor) {
    TransformStep s;
    s.kind = TransformStep::Kind::matrix;
    s.matrix = {0, -1, 0, 7, 1, 0, 0, 8, 0, 0, 1, 9, 0, 0, 0, 1};  // 90° about z, then (7, 8, 9)
    const Transform t = make_transform({s});
    expect_vec_near(t.apply_point({1, 0, 0}), {7, 9, 9}, 1e-12);
    expect_vec_near(t.apply_point({0, 1, 0}), {6, 8, 9}, 1e-12);
}

// In a scene, a child's own transform applies before its group's: a unit sphere at (1, 0, 0)
// scaled by 2 is centred at (2, 0, 0) with radius 2, then the group moves it to (12, 0, 0).
TEST(Transform, ChildTransformAppliesBeforeGroupTransform) {
    const Scene scene = test::scene_from(test::join_lines({
        "camera: {eye: [0, 0, 50], look_at: [0, 0, 0]}",
        "image: {width: 2, height: 2}",
        "objects:",
        "  - type: group",
        "    transform: [{translate: [10, 0, 0]}]",
        "    objects:",
        "      - type: sphere",
        "        center: [1, 0, 0]",
        "        radius: 1",
        "        transform: [{scale: 2}]",
        "        material: {kd: 1}",
    }));
    ASSERT_EQ(scene.spheres.size(), 1u);
    ShapeHit hit;
    // Down the axis through (12, 0, ·): the top is at z = 2.
    ASSERT_TRUE(intersect_sphere(scene.spheres[0], {{12, 0, 10}, {0, 0, -1}, 1e-4, 1e7}, 1e-4, 1e7, hit));
    EXPECT_NEAR(hit.t, 8.0, 1e-12);
    // At x = 13.9 the radius-2 sphere is still there; a radius-1 one (wrong scale) would be missed.
    EXPECT_TRUE(intersect_sphere(scene.spheres[0], {{13.9, 0, 10}, {0, 0, -1}, 1e-4, 1e7}, 1e-4, 1e7, hit));
    // Where a translate-then-scale order would have put it (22, 0, 0), there is nothing.
    EXPECT_FALSE(intersect_sphere(scene.spheres[0], {{22, 0, 10}, {0, 0, -1}, 1e-4, 1e7}, 1e-4, 1e7, hit));
}

}  // namespace
}  // namespace whitted
