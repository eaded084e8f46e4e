// SPDX-License-Identifier: MIT
// whitted::render: tiles run in any order on any number of threads, yet every pixel depends
// only on the scene, so the image must be bit-identical for 1, 2 and 3 threads.

#include "whitted/render/accelerator.h"
#include "whitted/render/renderer.h"
#include "whitted/scene/scene.h"

#include "test_support.h"

#include <gtest/gtest.h>

#include <cstring>
#include <set>

namespace whitted {
namespace {

// Several tiles (16-pixel tiles over 41×23), supersampling, mirrors, shadows, and every shape kind.
const std::string scene_text = test::join_lines({
    "camera: {eye: [0.3, 1.5, 6], look_at: [0, 0.2, 0], fov: 55}",
    "image: {width: 41, height: 23, background: [0.1, 0.2, 0.3], samples: 2}",
    "render: {max_depth: 4}",
    "ambient: [0.9, 1, 1.1]",
    "lights:",
    "  - {type: point, position: [-4, 5, 3], intensity: [1, 0.9, 0.8]}",
    "  - {type: directional, direction: [1, -1, -0.5], intensity: 0.4}",
    "materials:",
    "  shiny: {ka: 0.05, kd: [0.6, 0.3, 0.2], ks: 0.5, p: 40, km: 0.3}",
    "  matte: {ka: [0.02, 0.04, 0.06], kd: [0.2, 0.4, 0.6], ks: [0.3, 0.1, 0.0], p: 8, highlight: phong}",
    "  floor: {ka: 0.05, kd: 0.5, km: 0.5}",
    "objects:",
    "  - {type: sphere, center: [-1, 0.2, 0], radius: 1, material: shiny}",
    "  - {type: box, min: [0.5, -1, -1], max: [2, 0.5, 0.5], material: matte,",
    "     transform: [{rotate: {axis: [0, 1, 0], angle: 25}}]}",
    "  - {type: triangle, vertices: [[-2, -1, -2], [2, -1, -2], [0, 2, -2.5]], material: matte}",
    "  - {type: plane, point: [0, -1, 0], normal: [0, 1, 0], material: floor}",
});

TEST(Render, ImageIsBitIdenticalForOneTwoAndThreeThreads) {
    const Scene scene = test::scene_from(scene_text);
    const Accelerator accelerator(scene);
    RenderOptions options;
    options.threads = 1;
    const RenderResult one = render(scene, accelerator, options);
    ASSERT_FALSE(one.cancelled);
    ASSERT_EQ(one.image.rgb.size(), size_t(41) * 23 * 3);
    // A constant image would make the comparison meaningless.
    const std::set<float> distinct(one.image.rgb.begin(), one.image.rgb.end());
    ASSERT_GT(distinct.size(), 100u);

    for (const int threads : {2, 3}) {
        options.threads = threads;
        const RenderResult other = render(scene, accelerator, options);
        ASSERT_EQ(other.image.rgb.size(), one.image.rgb.size());
        EXPECT_EQ(std::memcmp(other.image.rgb.data(), one.image.rgb.data(), one.image.rgb.size() * sizeof(float)), 0)
            << threads << " threads";
        EXPECT_EQ(other.rays.total(), one.rays.total()) << threads << " threads";
    }
}

// The tiled render stores exactly what render_pixel computes, rounded to float, rows from the top.
TEST(Render, ImageHoldsRenderPixelValues) {
    const Scene scene = test::scene_from(scene_text);
    const Accelerator accelerator(scene);
    RenderOptions options;
    options.threads = 2;
    const RenderResult result = render(scene, accelerator, options);
    const LectureShading shading(scene, accelerator);
    for (const auto& [i, j] : {std::pair{0, 0}, std::pair{40, 0}, std::pair{20, 11}, std::pair{17, 22}}) {
        RayCounts counts;
        const Color c = render_pixel(scene, shading, i, j, counts);
        const float* stored = result.image.pixel(i, j);
        EXPECT_EQ(stored[0], float(c.x)) << i << "," << j;
        EXPECT_EQ(stored[1], float(c.y)) << i << "," << j;
        EXPECT_EQ(stored[2], float(c.z)) << i << "," << j;
        EXPECT_EQ(counts.camera, 4u);  // samples: 2 → a 2×2 grid
    }
}

// --stats reports Embree's memory: a BVH over a few thousand triangles holds tens of kilobytes
// at least (more than the triangles' own 36 bytes each), and the build's peak is no less.
TEST(Render, AcceleratorReportsEmbreeMemory) {
    std::string vertices, triangles;
    constexpr int n = 40;  // an n x n grid of quads: 3200 triangles
    for (int i = 0; i <= n; ++i)
        for (int j = 0; j <= n; ++j)
            vertices += (vertices.empty() ? "" : ", ") + std::string("[") + std::to_string(i) + ", 0, " +
                        std::to_string(j) + "]";
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            const int a = i * (n + 1) + j, b = a + n + 1;
            triangles += (triangles.empty() ? "" : ", ") + std::string("[") + std::to_string(a) + ", " +
                         std::to_string(b) + ", " + std::to_string(b + 1) + "], [" + std::to_string(a) + ", " +
                         std::to_string(b + 1) + ", " + std::to_string(a + 1) + "]";
        }
    const Scene scene = test::scene_from(test::join_lines({
        "camera: {eye: [20, 10, 60], look_at: [20, 0, 20]}",
        "image: {width: 8, height: 8}",
        "materials:",
        "  m: {kd: 0.5}",
        "objects:",
        "  - {type: mesh, material: m, vertices: [" + vertices + "], triangles: [" + triangles + "]}",
    }));
    ASSERT_EQ(scene.triangle_count(), size_t(2 * n * n));
    const Accelerator accelerator(scene, 1);
    EXPECT_GT(accelerator.embree_bytes(), size_t(36 * 2 * n * n));
    EXPECT_GE(accelerator.peak_embree_bytes(), accelerator.embree_bytes());
}

}  // namespace
}  // namespace whitted
