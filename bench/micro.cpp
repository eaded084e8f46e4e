// SPDX-License-Identifier: MIT
// Micro-benchmarks of the hot kernels (Google Benchmark). Speed targets live here and in
// scripts/bench, never in timed unit tests.

#include "geometry/shapes.h"
#include "render/accelerator.h"
#include "render/camera.h"
#include "render/renderer.h"
#include "render/shading.h"
#include "scene/description.h"
#include "scene/scene.h"

#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>
#include <string>

namespace {

using namespace whitted;

/// A torus of major × minor segments as an inline-mesh scene over a mirror floor (the anchor
/// scenes' set-up at a smaller image), built in memory so the benchmark needs no files.
Scene torus_scene(int major, int minor) {
    std::string yaml = R"(
camera: { eye: [0, 2.5, 6.5], look_at: [0, 1, 0], fov: 60 }
image: { width: 320, height: 240, background: [0.05, 0.07, 0.1] }
lights:
  - { type: point, position: [-5, 8, 4], intensity: [1, 0.95, 0.9] }
  - { type: point, position: [6, 5, 2], intensity: [0.4, 0.45, 0.5] }
objects:
  - { type: plane, point: [0, 0, 0], normal: [0, 1, 0], material: { kd: 0.55, ka: 0.03, km: 0.35 } }
)";
    SceneDescription description = parse_scene_text(yaml, "bench.yaml");
    ObjectDescription object;
    MeshShape& mesh = object.shape.emplace<MeshShape>();
    MaterialDescription material;
    material.kd.value = {0.6, 0.35, 0.2};
    material.ks.value = Color(0.5);
    material.p.value = 60;
    material.km.value = Color(0.1);
    MaterialReference reference;
    reference.inline_ = material;
    object.material = reference;
    for (int i = 0; i < major; ++i) {
        const double u = 2 * std::numbers::pi * i / major;
        for (int j = 0; j < minor; ++j) {
            const double v = 2 * std::numbers::pi * j / minor;
            mesh.vertices.push_back({(1.2 + 0.45 * std::cos(v)) * std::cos(u), 1.6 + 0.45 * std::sin(v),
                                     (1.2 + 0.45 * std::cos(v)) * std::sin(u) - 0.5});
        }
    }
    for (int i = 0; i < major; ++i)
        for (int j = 0; j < minor; ++j) {
            const int64_t a = i * minor + j, b = ((i + 1) % major) * minor + j,
                          c = ((i + 1) % major) * minor + (j + 1) % minor, d = i * minor + (j + 1) % minor;
            mesh.triangles.push_back({a, c, b});
            mesh.triangles.push_back({a, d, c});
            mesh.triangle_where.resize(mesh.triangles.size());
        }
    description.objects.push_back(std::move(object));
    return validate_scene(description);
}

// The inputs go through DoNotOptimize every iteration: with link-time optimisation the compiler
// otherwise saw constant inputs and hoisted the whole test out of the loop (0.26 ns a triangle).
void BM_intersect_sphere(benchmark::State& state) {
    Sphere sphere;
    sphere.radius = 1;
    Ray ray{{0.3, 0.2, -5}, normalize(Vec3{0, 0, 1}), 1e-4, 1e7};
    ShapeHit hit;
    for (auto _ : state) {
        benchmark::DoNotOptimize(ray);
        benchmark::DoNotOptimize(intersect_sphere(sphere, ray, ray.t_min, ray.t_max, hit));
    }
}
BENCHMARK(BM_intersect_sphere);

void BM_intersect_triangle(benchmark::State& state) {
    Ray ray{{0.2, 0.2, -5}, {0, 0, 1}, 1e-4, 1e7};
    Vec3 v0{0, 0, 0}, v1{1, 0, 0}, v2{0, 1, 0};
    ShapeHit hit;
    for (auto _ : state) {
        benchmark::DoNotOptimize(ray);
        benchmark::DoNotOptimize(v0);
        benchmark::DoNotOptimize(intersect_triangle(v0, v1, v2, ray, ray.t_min, ray.t_max, hit));
    }
}
BENCHMARK(BM_intersect_triangle);

/// Camera rays against a 100k-triangle torus and a plane: closest-hit throughput.
void BM_camera_rays_torus100k(benchmark::State& state) {
    static const Scene scene = torus_scene(316, 158);
    static const Accelerator accelerator(scene);
    int pixel = 0;
    SurfaceHit hit;
    for (auto _ : state) {
        const int i = pixel % scene.width, j = (pixel / scene.width) % scene.height;
        ++pixel;
        benchmark::DoNotOptimize(accelerator.intersect(
            camera_ray(scene.camera, (i + 0.5) / scene.width - 0.5, 0.5 - (j + 0.5) / scene.height), hit));
    }
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_camera_rays_torus100k);

/// Shadow rays from floor points toward the first light (rtcOccluded1 + the plane test).
void BM_shadow_rays_torus100k(benchmark::State& state) {
    static const Scene scene = torus_scene(316, 158);
    static const Accelerator accelerator(scene);
    int k = 0;
    for (auto _ : state) {
        const Vec3 point{-3 + 0.006 * (k % 1000), 0, -3 + 0.006 * ((k / 1000) % 1000)};
        ++k;
        const Vec3 offset = scene.lights[0].position - point;
        const double distance = length(offset);
        benchmark::DoNotOptimize(accelerator.occluded({point, offset / distance, 1e-3, distance - 1e-3}));
    }
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_shadow_rays_torus100k);

/// Whole pixels (camera ray, shading, shadow and mirror rays) on one thread.
void BM_pixels_torus100k(benchmark::State& state) {
    static const Scene scene = torus_scene(316, 158);
    static const Accelerator accelerator(scene);
    const LectureShading shading(scene, accelerator);
    int pixel = 0;
    RayCounts counts;
    for (auto _ : state) {
        benchmark::DoNotOptimize(
            render_pixel(scene, shading, pixel % scene.width, (pixel / scene.width) % scene.height, counts));
        ++pixel;
    }
    state.SetItemsProcessed(state.iterations());
    state.counters["rays/pixel"] = double(counts.total()) / double(state.iterations());
}
BENCHMARK(BM_pixels_torus100k);

void BM_build_bvh_torus100k(benchmark::State& state) {
    const Scene scene = torus_scene(316, 158);
    for (auto _ : state) {
        const Accelerator accelerator(scene);
        benchmark::DoNotOptimize(&accelerator);
    }
}
BENCHMARK(BM_build_bvh_torus100k)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
