// SPDX-License-Identifier: MIT
#include "render/renderer.h"

#include "core/packet_array.h"

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <optional>
#include <thread>

namespace whitted {

Color render_pixel(const Scene& scene, const LectureShading& shading, int i, int j, RayCounts& counts) {
    const int n = scene.samples;
    Color sum(0.0);
    for_each_pixel_sample_packet(scene, i, j, [&](const Ray* rays, int count) {
        PacketArray<Color, Accelerator::packet_size> radiance;
        shading.trace_packet(rays, count, 0, radiance.data(), counts);
        for (int k = 0; k < count; ++k) sum += radiance[k];
        counts.camera += count;
    });
    return n == 1 ? sum : sum / double(n * n);
}

namespace {

/// The pixels of [x_begin, x_end) × [y_begin, y_end) with one sample each, traced as packets of
/// 4×4 neighbouring pixels; the same values render_pixel gives one by one.
void render_block_single_sample(const Scene& scene, const LectureShading& shading, int x_begin, int x_end, int y_begin,
                                int y_end, Image& image, RayCounts& counts) {
    for_each_single_sample_packet(
        scene, x_begin, x_end, y_begin, y_end, [&](const Ray* rays, int count, const int* pixel_x, const int* pixel_y) {
            PacketArray<Color, Accelerator::packet_size> radiance;
            shading.trace_packet(rays, count, 0, radiance.data(), counts);
            counts.camera += count;
            for (int k = 0; k < count; ++k) {
                float* out = &image.rgb[3 * (size_t(pixel_y[k]) * scene.width + pixel_x[k])];
                out[0] = float(radiance[k].x), out[1] = float(radiance[k].y), out[2] = float(radiance[k].z);
            }
        });
}

/// render_block_single_sample with layers: the same packets, watched by a LayerRecorder.
void render_block_layers_single_sample(const Scene& scene, const LectureShading& shading, LayerSet selection,
                                       int x_begin, int x_end, int y_begin, int y_end, Image& image,
                                       RayCounts& counts) {
    LayerRecorder recorder(scene, Accelerator::packet_size);
    PixelLayers pixel;
    for_each_single_sample_packet(
        scene, x_begin, x_end, y_begin, y_end, [&](const Ray* rays, int count, const int* pixel_x, const int* pixel_y) {
            PacketArray<Color, Accelerator::packet_size> radiance;
            recorder.reset();
            shading.trace_packet(rays, count, 0, radiance.data(), counts, recorder);
            counts.camera += count;
            for (int k = 0; k < count; ++k) {
                const size_t index = size_t(pixel_y[k]) * scene.width + pixel_x[k];
                pixel.clear();
                pixel.add_sample(recorder.lane(k), true);
                store_pixel_layers(pixel, selection, image.layers, index, &image.rgb[3 * index]);
            }
        });
}

/// render_pixel with layers, for n×n samples: the same packets, watched by a LayerRecorder.
void render_pixel_layers(const Scene& scene, const LectureShading& shading, LayerSet selection, int i, int j,
                         LayerRecorder& recorder, Image& image, RayCounts& counts) {
    const int n = scene.samples;
    PixelLayers pixel;
    bool first = true;
    for_each_pixel_sample_packet(scene, i, j, [&](const Ray* rays, int count) {
        PacketArray<Color, Accelerator::packet_size> radiance;
        recorder.reset();
        shading.trace_packet(rays, count, 0, radiance.data(), counts, recorder);
        for (int k = 0; k < count; ++k) {
            pixel.add_sample(recorder.lane(k), first);
            first = false;
        }
        counts.camera += count;
    });
    pixel.finish(n * n);
    const size_t index = size_t(j) * scene.width + i;
    store_pixel_layers(pixel, selection, image.layers, index, &image.rgb[3 * index]);
}

/// One tile with layers.
void render_tile_layers(const Scene& scene, const LectureShading& shading, LayerSet selection, int x_begin, int x_end,
                        int y_begin, int y_end, Image& image, RayCounts& counts) {
    if (scene.samples == 1) {
        render_block_layers_single_sample(scene, shading, selection, x_begin, x_end, y_begin, y_end, image, counts);
        return;
    }
    LayerRecorder recorder(scene, Accelerator::packet_size);
    for (int y = y_begin; y < y_end; ++y)
        for (int x = x_begin; x < x_end; ++x)
            render_pixel_layers(scene, shading, selection, x, y, recorder, image, counts);
}

}  // namespace

std::vector<CameraPacket> camera_packets(const Scene& scene, int i, int j) {
    std::vector<CameraPacket> packets;
    if (scene.samples == 1) {
        // render_block_single_sample's blocks: 4×4 from each 32×32 tile's corner, so at multiples of 4.
        const int bx = i / 4 * 4, by = j / 4 * 4;
        for_each_single_sample_packet(scene, bx, std::min(bx + 4, scene.width), by, std::min(by + 4, scene.height),
                                      [&](const Ray* rays, int count, const int* pixel_x, const int* pixel_y) {
                                          CameraPacket& packet = packets.emplace_back();
                                          packet.rays.assign(rays, rays + count);
                                          for (int k = 0; k < count; ++k)
                                              packet.sample.push_back(pixel_x[k] == i && pixel_y[k] == j ? 0 : -1);
                                      });
        return packets;
    }
    int sample = 0;
    for_each_pixel_sample_packet(scene, i, j, [&](const Ray* rays, int count) {
        CameraPacket& packet = packets.emplace_back();
        packet.rays.assign(rays, rays + count);
        for (int k = 0; k < count; ++k) packet.sample.push_back(sample++);
    });
    return packets;
}

size_t render_tile_count(int width, int height) {
    constexpr int tile = render_tile_size;
    return size_t((width + tile - 1) / tile) * size_t((height + tile - 1) / tile);
}

TileRect render_tile_rect(int width, int height, size_t t) {
    constexpr int tile = render_tile_size;
    const int tiles_x = (width + tile - 1) / tile;
    const int x_begin = int(t % tiles_x) * tile, y_begin = int(t / tiles_x) * tile;
    return {x_begin, std::min(x_begin + tile, width), y_begin, std::min(y_begin + tile, height)};
}

namespace {

/// A tile's pixels in the image and its layers (crop_image's cut), kept to put back (a tile
/// stopped midway).
class TileContents {
public:
    TileContents(const Image& image, const TileRect& rect) : m_rect(rect), m_saved(crop_image(image, rect)) {}
    void restore(Image& image) const {
        paste(m_saved.rgb, image.rgb, image.width, 3);
        for (size_t k = 0; k < image.layers.size(); ++k)
            paste(m_saved.layers[k].values, image.layers[k].values, image.width, image.layers[k].channels.size());
    }

private:
    void paste(const std::vector<float>& saved, std::vector<float>& values, int width, size_t channels) const {
        const size_t row = size_t(m_rect.x_end - m_rect.x_begin) * channels;
        for (int y = m_rect.y_begin; y < m_rect.y_end; ++y)
            std::copy_n(saved.begin() + ptrdiff_t(size_t(y - m_rect.y_begin) * row), row,
                        values.begin() + ptrdiff_t((size_t(y) * size_t(width) + size_t(m_rect.x_begin)) * channels));
    }

    TileRect m_rect;
    Image m_saved;  ///< the tile's rectangle of the image, layers included
};

}  // namespace

std::vector<size_t> render_tiles_overlapping(const Scene& scene, const TileRect& window) {
    std::vector<size_t> tiles;
    const size_t count = render_tile_count(scene.width, scene.height);
    for (size_t t = 0; t < count; ++t)
        if (render_tile_rect(scene.width, scene.height, t).overlaps(window)) tiles.push_back(t);
    return tiles;
}

Image crop_image(const Image& image, const TileRect& window) {
    Image out;
    out.width = window.x_end - window.x_begin;
    out.height = window.y_end - window.y_begin;
    const auto cut = [&](const std::vector<float>& values, size_t channels) {
        std::vector<float> kept;
        kept.reserve(window.pixels() * channels);
        for (int y = window.y_begin; y < window.y_end; ++y) {
            const auto row =
                values.begin() + ptrdiff_t((size_t(y) * size_t(image.width) + size_t(window.x_begin)) * channels);
            kept.insert(kept.end(), row, row + ptrdiff_t(size_t(out.width) * channels));
        }
        return kept;
    };
    out.rgb = cut(image.rgb, 3);
    for (const ImageLayer& layer : image.layers) {
        out.layers.push_back({layer.name, layer.channels, layer.data, cut(layer.values, layer.channels.size())});
    }
    return out;
}

RenderedTiles render(const Scene& scene, const Accelerator& accelerator, const RenderJob& options) {
    using clock = std::chrono::steady_clock;
    const auto start = clock::now();
    // The tiles to render: every one, or those the crop window overlaps (a tile source, when
    // there is one, decides for itself).
    std::vector<size_t> cropped_tiles;
    if (options.crop && !options.next_tile) cropped_tiles = render_tiles_overlapping(scene, *options.crop);
    const size_t tile_count =
        options.crop && !options.next_tile ? cropped_tiles.size() : render_tile_count(scene.width, scene.height);
    const auto tile_number = [&](size_t i) { return options.crop && !options.next_tile ? cropped_tiles[i] : i; };

    RenderedTiles result;
    result.image.width = scene.width;
    result.image.height = scene.height;
    result.image.rgb.assign(size_t(scene.width) * scene.height * 3, 0.0f);
    result.image.layers = make_image_layers(scene, options.layers);
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
                const api::Progress progress{tiles_done.load(), tile_count,
                                             camera_rays.load() + shadow_rays.load() + reflected_rays.load(),
                                             std::chrono::duration<double>(clock::now() - start).count()};
                options.on_progress(progress);
            }
        });
    }

    const auto cancelled = [&] { return options.cancel && options.cancel->load(std::memory_order_relaxed); };
    const auto render_tile = [&](size_t t) {
        const TileRect rect = render_tile_rect(scene.width, scene.height, t);
        const int x_begin = rect.x_begin, x_end = rect.x_end;
        RayCounts counts;
        // A tile is rendered in bands of 4 rows (one row of 4×4 packets, so the packets are the
        // same as the whole tile's) and a stop is heeded between bands (and between pixels with
        // n×n samples): one tile of a legal scene can take minutes, and a caller that cannot end
        // the process (the Python module) would wait for it. A tile stopped midway is put back as
        // it was (black), and is not done.
        std::optional<TileContents> before;
        if (options.cancel) before.emplace(result.image, rect);
        for (int y_begin = rect.y_begin; y_begin < rect.y_end; y_begin += 4) {
            if (y_begin > rect.y_begin && cancelled()) {
                before->restore(result.image);
                return;
            }
            const int y_end = std::min(y_begin + 4, rect.y_end);
            if (!options.layers.empty()) {
                render_tile_layers(scene, shading, options.layers, x_begin, x_end, y_begin, y_end, result.image,
                                   counts);
            } else if (scene.samples == 1) {
                render_block_single_sample(scene, shading, x_begin, x_end, y_begin, y_end, result.image, counts);
            } else {
                for (int y = y_begin; y < y_end; ++y) {
                    for (int x = x_begin; x < x_end; ++x) {
                        // n×n samples: a pixel can take a second (heavy_tile.yaml: 0.34 s), so here
                        // the stop is heeded pixel by pixel.
                        if (before && (x > x_begin || y > rect.y_begin) && cancelled()) {
                            before->restore(result.image);
                            return;
                        }
                        const Color c = render_pixel(scene, shading, x, y, counts);
                        float* out = &result.image.rgb[3 * (size_t(y) * scene.width + x)];
                        out[0] = float(c.x), out[1] = float(c.y), out[2] = float(c.z);
                    }
                }
            }
        }
        camera_rays += counts.camera;
        shadow_rays += counts.shadow;
        reflected_rays += counts.reflected;
        if (options.on_tile_done) options.on_tile_done(t, result.image, counts);
        ++tiles_done;
    };

    const size_t pixels = size_t(scene.width) * size_t(scene.height) * size_t(scene.samples) * size_t(scene.samples);
    const int threads = options.threads > 0 ? options.threads : tbb::this_task_arena::max_concurrency();
    if (pixels <= most_pixels_on_one_thread && !accelerator.has_bvh() && !options.next_tile) {
        for (size_t i = 0; i < tile_count && !cancelled(); ++i) render_tile(tile_number(i));
    } else {
        tbb::task_arena arena(threads);
        arena.execute([&] {
            if (options.next_tile) {
                // One loop per thread, each asking the tile source until it has no more.
                tbb::parallel_for(0, threads, [&](int) {
                    size_t t;
                    while (!cancelled() && options.next_tile(t)) render_tile(t);
                });
                return;
            }
            tbb::parallel_for(tbb::blocked_range<size_t>(0, tile_count, 1),
                              [&](const tbb::blocked_range<size_t>& range) {
                                  for (size_t i = range.begin(); i != range.end(); ++i) {
                                      if (cancelled()) return;
                                      render_tile(tile_number(i));
                                  }
                              });
        });
    }

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
    // With a tile source this process renders only some tiles: it was cancelled if told to stop.
    result.cancelled = options.next_tile ? cancelled() : tiles_done.load() != tile_count;
    if (options.on_progress) options.on_progress({tiles_done.load(), tile_count, result.rays.total(), result.seconds});
    return result;
}

}  // namespace whitted
