// SPDX-License-Identifier: MIT
#include "whitted/render/renderer.h"

#include "whitted/render/camera.h"

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>

namespace whitted {

Color render_pixel(const Scene& scene, const LectureShading& shading, int i, int j, RayCounts& counts) {
    const int n = scene.samples;
    Color sum(0.0);
    for (int b = 0; b < n; ++b) {
        for (int a = 0; a < n; ++a) {
            double x0, y0;
            sample_position(i, j, a, b, n, scene.width, scene.height, x0, y0);
            ++counts.camera;
            sum += shading.trace(camera_ray(scene.camera, x0, y0), 0, counts);
        }
    }
    return n == 1 ? sum : sum / double(n * n);
}

RenderResult render(const Scene& scene, const Accelerator& accelerator, const RenderOptions& options) {
    using clock = std::chrono::steady_clock;
    const auto start = clock::now();
    constexpr int tile = 16;
    const int tiles_x = (scene.width + tile - 1) / tile, tiles_y = (scene.height + tile - 1) / tile;
    const size_t tile_count = size_t(tiles_x) * tiles_y;

    RenderResult result;
    result.tile_size = tile;
    result.image.width = scene.width;
    result.image.height = scene.height;
    result.image.rgb.assign(size_t(scene.width) * scene.height * 3, 0.0f);
    std::vector<char> done(tile_count, 0);
    std::atomic<size_t> tiles_done{0};
    std::atomic<uint64_t> camera_rays{0}, shadow_rays{0}, reflected_rays{0};
    const LectureShading shading(scene, accelerator);

    // Progress is reported from its own thread so that workers never wait on the terminal.
    std::mutex mutex;
    std::condition_variable finished_signal;
    bool finished = false;
    std::thread reporter;
    if (options.on_progress) {
        reporter = std::thread([&] {
            std::unique_lock lock(mutex);
            while (!finished_signal.wait_for(lock, std::chrono::milliseconds(200), [&] { return finished; })) {
                const RenderProgress progress{tiles_done.load(), tile_count,
                                              camera_rays.load() + shadow_rays.load() + reflected_rays.load(),
                                              std::chrono::duration<double>(clock::now() - start).count()};
                options.on_progress(progress);
            }
        });
    }

    const int threads = options.threads > 0 ? options.threads : tbb::this_task_arena::max_concurrency();
    tbb::task_arena arena(threads);
    arena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, tile_count, 1), [&](const tbb::blocked_range<size_t>& range) {
            for (size_t t = range.begin(); t != range.end(); ++t) {
                if (options.cancel && options.cancel->load(std::memory_order_relaxed)) return;
                const int x_begin = int(t % tiles_x) * tile, y_begin = int(t / tiles_x) * tile;
                const int x_end = std::min(x_begin + tile, scene.width), y_end = std::min(y_begin + tile, scene.height);
                RayCounts counts;
                for (int y = y_begin; y < y_end; ++y) {
                    for (int x = x_begin; x < x_end; ++x) {
                        const Color c = render_pixel(scene, shading, x, y, counts);
                        float* out = &result.image.rgb[3 * (size_t(y) * scene.width + x)];
                        out[0] = float(c.x), out[1] = float(c.y), out[2] = float(c.z);
                    }
                }
                camera_rays += counts.camera;
                shadow_rays += counts.shadow;
                reflected_rays += counts.reflected;
                done[t] = 1;
                ++tiles_done;
            }
        });
    });

    if (reporter.joinable()) {
        {
            std::lock_guard lock(mutex);
            finished = true;
        }
        finished_signal.notify_all();
        reporter.join();
    }
    result.rays = {camera_rays.load(), shadow_rays.load(), reflected_rays.load()};
    result.seconds = std::chrono::duration<double>(clock::now() - start).count();
    result.tile_done.assign(done.begin(), done.end());
    result.cancelled = tiles_done.load() != tile_count;
    if (options.on_progress) options.on_progress({tiles_done.load(), tile_count, result.rays.total(), result.seconds});
    return result;
}

}  // namespace whitted
