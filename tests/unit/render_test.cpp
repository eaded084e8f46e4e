// SPDX-License-Identifier: MIT
// whitted::render: tiles run in any order on any number of threads, and the BVH may be built
// on any number of threads, yet every pixel depends only on the scene, so the image must be
// bit-identical for every combination; with one sample per pixel (packets of 4×4 pixels,
// render_block_single_sample) and with n×n samples (render_pixel) alike. Separate processes,
// other thread counts and every Embree instruction set: tests/isa/isa_identical.py. Packets
// against single rays on random rays: accelerator_test.cpp.

#include "render/accelerator.h"
#include "render/renderer.h"
#include "scene/scene.h"

#include "test_support.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cstring>
#include <set>

namespace whitted {
namespace {

// Several tiles (16-pixel tiles over 41×23: the last column and row of tiles, and of 4×4
// packets, are partly filled), mirrors, shadows, and every shape kind; `samples` per pixel.
std::string scene_text(int samples) {
    return test::join_lines({
        "camera: {eye: [0.3, 1.5, 6], look_at: [0, 0.2, 0], fov: 55}",
        "image: {width: 41, height: 23, background: [0.1, 0.2, 0.3], samples: " + std::to_string(samples) + "}",
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
        "  - {type: mesh, material: shiny, vertices: [[-2, 1.5, -1], [-1, 2.5, -1.5], [0, 1.5, -1], [-1, 1, -0.5]],",
        "     triangles: [[0, 1, 2], [0, 2, 3]]}",
        "  - {type: plane, point: [0, -1, 0], normal: [0, 1, 0], material: floor}",
    });
}

bool same_pixels(const Image& a, const Image& b) {
    return a.rgb.size() == b.rgb.size() && std::memcmp(a.rgb.data(), b.rgb.data(), a.rgb.size() * sizeof(float)) == 0;
}

class RenderPerSamples : public testing::TestWithParam<int> {};

// The reference: a BVH built on 1 thread, rendered on 1. Every other pair of (BVH build
// threads, render threads), each BVH a new Accelerator in this one process, gives the same
// bytes. Embree's `threads=N` limits the whole process's TBB workers while its device exists,
// so the reference's BVH is gone before the others are built, and with the 1-thread BVH the
// renders run on one worker whatever they ask; with the 2- and 3-thread BVHs they are parallel.
TEST_P(RenderPerSamples, ImageIsBitIdenticalForEveryBuildAndRenderThreadCount) {
    const int samples = GetParam();
    const Scene scene = test::scene_from(scene_text(samples));
    ASSERT_EQ(scene.samples, samples);
    RenderJob options;
    options.threads = 1;
    RenderedTiles one;
    {
        const Accelerator first(scene, 1);
        one = render(scene, first, options);
    }
    ASSERT_FALSE(one.cancelled);
    ASSERT_EQ(one.image.rgb.size(), size_t(41) * 23 * 3);
    // A constant image would make the comparison meaningless.
    const std::set<float> distinct(one.image.rgb.begin(), one.image.rgb.end());
    ASSERT_GT(distinct.size(), 100u);
    EXPECT_EQ(one.rays.camera, uint64_t(41) * 23 * samples * samples);

    for (const int build_threads : {1, 2, 3}) {
        const Accelerator accelerator(scene, build_threads);  // a new BVH: only the scene is shared
        for (const int threads : {1, 2, 3}) {
            if (build_threads == 1 && threads == 1) continue;
            options.threads = threads;
            const RenderedTiles other = render(scene, accelerator, options);
            EXPECT_TRUE(same_pixels(other.image, one.image))
                << "BVH built on " << build_threads << " thread(s), rendered on " << threads;
            EXPECT_EQ(other.rays.total(), one.rays.total()) << build_threads << "/" << threads << " threads";
        }
    }
}

// The tiled render stores exactly what render_pixel computes, rounded to float, rows from the
// top: for every pixel, so with one sample the 4×4 packets (partly filled at the right and
// bottom edges) are proven against one pixel at a time.
TEST_P(RenderPerSamples, EveryPixelHoldsTheRenderPixelValue) {
    const int samples = GetParam();
    const Scene scene = test::scene_from(scene_text(samples));
    const Accelerator accelerator(scene, 2);
    RenderJob options;
    options.threads = 2;
    const RenderedTiles result = render(scene, accelerator, options);
    const LectureShading shading(scene, accelerator);
    int differing = 0;
    for (int j = 0; j < scene.height; ++j)
        for (int i = 0; i < scene.width; ++i) {
            RayCounts counts;
            const Color c = render_pixel(scene, shading, i, j, counts);
            const float* stored = result.image.pixel(i, j);
            const bool same = stored[0] == float(c.x) && stored[1] == float(c.y) && stored[2] == float(c.z);
            if (!same && ++differing <= 5) ADD_FAILURE() << "pixel " << i << "," << j << " differs";
            EXPECT_EQ(counts.camera, uint64_t(samples * samples));  // an n×n grid
        }
    EXPECT_EQ(differing, 0);
}

// A crop window traces only the tiles it overlaps, and its pixels are the whole render's: a
// window across the two tiles' boundary (32-pixel tiles over 41 columns), and one inside the
// first tile alone, whose camera rays are that tile's 32 × 23 pixels' and no more.
TEST_P(RenderPerSamples, ACropWindowIsTheWholeRendersPixels) {
    const int samples = GetParam();
    const Scene scene = test::scene_from(scene_text(samples));
    const Accelerator accelerator(scene, 2);
    RenderJob options;
    options.threads = 2;
    const RenderedTiles whole = render(scene, accelerator, options);
    for (const TileRect window : {TileRect{20, 35, 5, 15}, TileRect{1, 6, 1, 6}, TileRect{0, 41, 0, 23}}) {
        options.crop = window;
        const RenderedTiles cropped = render(scene, accelerator, options);
        const Image part = crop_image(cropped.image, window);
        ASSERT_EQ(part.width, window.x_end - window.x_begin);
        ASSERT_EQ(part.height, window.y_end - window.y_begin);
        EXPECT_TRUE(same_pixels(part, crop_image(whole.image, window)))
            << "window from " << window.x_begin << "," << window.y_begin;
        if (window.x_end <= render_tile_size) {
            EXPECT_EQ(cropped.rays.camera, uint64_t(render_tile_size) * 23 * samples * samples);
        }
    }
    // crop_image itself: the window's rows, each from its first column.
    const Image corner = crop_image(whole.image, {40, 41, 22, 23});
    ASSERT_EQ(corner.rgb.size(), 3u);
    EXPECT_EQ(std::memcmp(corner.rgb.data(), whole.image.pixel(40, 22), 3 * sizeof(float)), 0);
}

INSTANTIATE_TEST_SUITE_P(OneAndNxN, RenderPerSamples, testing::Values(1, 2, 3),
                         [](const testing::TestParamInfo<int>& samples_info) {
                             return "samples" + std::to_string(samples_info.param);
                         });

// A small image of a scene without a BVH is rendered on the calling thread (renderer.h,
// most_pixels_on_one_thread); a tile source (RenderJob::next_tile) makes the same tiles go
// through TBB's worker threads instead. The two give the same bytes, with one sample per pixel
// (packets) and 2×2: the scene above without its triangles.
TEST(Render, ASmallImageOnOneThreadIsTheThreadsImage) {
    for (const int samples : {1, 2}) {
        std::string text = scene_text(samples);
        text = text.substr(0, text.find("  - {type: triangle")) + text.substr(text.find("  - {type: plane"));
        const Scene scene = test::scene_from(text);
        ASSERT_TRUE(scene.meshes.empty());
        ASSERT_LE(size_t(scene.width) * scene.height * samples * samples, most_pixels_on_one_thread);
        const Accelerator accelerator(scene, 2);
        ASSERT_FALSE(accelerator.has_bvh());
        RenderJob options;
        options.threads = 2;
        const RenderedTiles alone = render(scene, accelerator, options);
        const size_t tiles = render_tile_count(scene.width, scene.height);
        std::atomic<size_t> next{0};
        std::atomic<int> tiles_given{0};
        options.next_tile = [&](size_t& tile) {
            tile = next++;
            if (tile >= tiles) return false;
            ++tiles_given;
            return true;
        };
        const RenderedTiles threaded = render(scene, accelerator, options);
        EXPECT_EQ(tiles_given.load(), int(tiles)) << samples;
        EXPECT_TRUE(same_pixels(alone.image, threaded.image)) << samples << "×" << samples << " samples";
        EXPECT_EQ(alone.rays.total(), threaded.rays.total()) << samples;
        const std::set<float> distinct(alone.image.rgb.begin(), alone.image.rgb.end());
        EXPECT_GT(distinct.size(), 100u) << samples;
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
