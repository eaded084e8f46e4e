// SPDX-License-Identifier: MIT
// PovrayTestOrder: POV-Ray's order of testing spheres and boxes, which settles exact ties. Which
// of two tied cubes POV-Ray shows in a large field is checked against POV-Ray itself
// (pov.cube_field, pov.cube_field_turned); here, what holds without POV-Ray: the nearest hit is
// never lost, the order without a hierarchy is the file's, and what is not covered says so.

#include "compat/povray/tie_order.h"

#include "geometry/shapes.h"
#include "scene/scene.h"

#include "test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>

namespace whitted {
namespace {

Ray ray_from(const Vec3& origin, const Vec3& toward) {
    return {origin, normalize(toward - origin), ray_limits::surface_t_min, ray_limits::max_distance};
}

// Two boxes with their tops in one plane, overlapping, and nothing else: POV-Ray builds no
// hierarchy for fewer than three objects (lights count) and tests them in the file's order,
// keeping the first of equal hits.
TEST(PovrayTestOrder, WithoutAHierarchyTheFirstInTheFileShows) {
    const std::string a = "  - { type: box, min: [-1, 0, -1], max: [0.5, 0.5, 0.5], material: m }\n";
    const std::string b = "  - { type: box, min: [-0.5, 0, -0.5], max: [1, 0.5, 1], material: m }\n";
    const std::string head =
        "camera: { eye: [0, 5, 0.01], look_at: [0, 0, 0], up: [0, 1, 0], fov: 60 }\n"
        "image: { width: 8, height: 8 }\n"
        "materials: { m: { kd: 1 } }\n"
        "objects:\n";
    const Ray down = ray_from({0.01, 5, 0.02}, {0.01, 0, 0.02});
    for (const bool a_first : {true, false}) {
        const Scene scene = load_scene_text(head + (a_first ? a + b : b + a), "ties.yaml");
        const PovrayTestOrder order(scene);
        PovrayTestOrder::Found found;
        ASSERT_TRUE(order.nearest(down, found));
        EXPECT_FALSE(found.sphere);
        EXPECT_EQ(found.index, 0u) << "the first box in the file, a_first = " << a_first;
        EXPECT_NEAR(found.hit.t, 4.5, 1e-12);
        // Both boxes meet the ray at exactly that t: it is a tie.
        ShapeHit other;
        ASSERT_TRUE(intersect_box(scene.boxes[1], down, down.t_min, down.t_max, other));
        EXPECT_EQ(other.t, found.hit.t);
    }
}

// Through the hierarchy and its queue, the hit found is the nearest one: the same t as testing
// every shape, for rays in every direction through a crowd of spheres, boxes and turned ones
// (a bounding box that cut a shape off, or a queue that stopped early, would lose hits).
TEST(PovrayTestOrder, TheHitFoundIsTheNearest) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1, 1);
    std::string text =
        "camera: { eye: [0, 0, 20], look_at: [0, 0, 0], up: [0, 1, 0], fov: 60 }\n"
        "image: { width: 8, height: 8 }\n"
        "lights: [ { type: point, position: [0, 10, 0] } ]\n"
        "materials: { m: { kd: 1 } }\n"
        "objects:\n"
        "  - { type: plane, point: [0, -9, 0], normal: [0, 1, 0], material: m }\n";
    for (int i = 0; i < 600; ++i) {
        const double x = 8 * u(rng), y = 8 * u(rng), z = 8 * u(rng), s = 0.3 + 0.25 * u(rng);
        const std::string at = "[" + std::to_string(x) + ", " + std::to_string(y) + ", " + std::to_string(z) + "]";
        switch (i % 3) {
            case 0:
                text += "  - { type: sphere, center: " + at + ", radius: " + std::to_string(s) + ", material: m }\n";
                break;
            case 1:
                text += "  - { type: box, min: [" + std::to_string(x - s) + ", " + std::to_string(y - s) + ", " +
                        std::to_string(z - s) + "], max: " + at + ", material: m }\n";
                break;
            default:
                text += "  - { type: box, min: [-" + std::to_string(s) + ", 0, -0.2], max: [" + std::to_string(s) +
                        ", 0.4, 0.2], material: m, transform: [ { rotate: { axis: [1, 2, 3], angle: " +
                        std::to_string(180 * u(rng)) + " } }, { translate: " + at + " } ] }\n";
        }
    }
    const Scene scene = load_scene_text(text, "crowd.yaml");
    const PovrayTestOrder order(scene);
    int hits = 0;
    for (int r = 0; r < 3000; ++r) {
        const Ray ray = ray_from({12 * u(rng), 12 * u(rng), 12 * u(rng)}, {3 * u(rng), 3 * u(rng), 3 * u(rng)});
        double nearest = std::numeric_limits<double>::infinity();
        for (const Sphere& sphere : scene.spheres) {
            ShapeHit hit;
            if (intersect_sphere(sphere, ray, ray.t_min, ray.t_max, hit)) nearest = std::min(nearest, hit.t);
        }
        for (const Box& box : scene.boxes) {
            ShapeHit hit;
            if (intersect_box(box, ray, ray.t_min, ray.t_max, hit)) nearest = std::min(nearest, hit.t);
        }
        PovrayTestOrder::Found found;
        const bool any = order.nearest(ray, found);
        ASSERT_EQ(any, std::isfinite(nearest)) << "ray " << r;
        if (!any) continue;
        ++hits;
        ASSERT_EQ(found.hit.t, nearest) << "ray " << r;
    }
    EXPECT_GT(hits, 1000);  // the rays do meet the crowd
}

// Meshes and instances are not in the rebuilt hierarchy (their bounding boxes would be needed
// too): such a scene says so, and ties there keep Embree's order.
// A mesh is a leaf of the hierarchy but never the answer: the box behind it is found, and a
// ray that meets only the mesh finds nothing.
TEST(PovrayTestOrder, AMeshIsPassedOver) {
    const Scene scene = load_scene_text(
        "camera: { eye: [0, 0, 5], look_at: [0, 0, 0], up: [0, 1, 0], fov: 60 }\n"
        "image: { width: 8, height: 8 }\n"
        "materials: { m: { kd: 1 } }\n"
        "objects:\n"
        "  - { type: triangle, vertices: [[-2, -2, 1], [2, -2, 1], [-2, 2, 1]], material: m }\n"
        "  - { type: box, min: [-1, -1, -1], max: [0, 0, 0], material: m }\n"
        "  - { type: sphere, center: [3, 3, 0], radius: 0.5, material: m }\n"
        "  - { type: sphere, center: [-3, 3, 0], radius: 0.5, material: m }\n",
        "mesh.yaml");
    const PovrayTestOrder order(scene);
    PovrayTestOrder::Found found;
    ASSERT_TRUE(order.nearest(ray_from({-0.5, -0.5, 5}, {-0.5, -0.5, 0}), found));
    EXPECT_FALSE(found.sphere);
    EXPECT_EQ(found.index, 0u);
    EXPECT_DOUBLE_EQ(found.hit.t, 5.0);
    EXPECT_FALSE(order.nearest(ray_from({-1.5, 1, 5}, {-1.5, 1, 0}), found));
}

}  // namespace
}  // namespace whitted
