// SPDX-License-Identifier: MIT
#pragma once

#include "core/packet_array.h"
#include "render/accelerator.h"
#include "render/camera.h"
#include "render/layers.h"
#include "render/shading.h"
#include "scene/scene.h"
#include "whitted/image.h"
#include "whitted/progress.h"

#include <algorithm>
#include <atomic>
#include <functional>
#include <optional>
#include <vector>

namespace whitted {

// Image, the film every part shares, is public: whitted/image.h.

/// A rectangle of pixels, [x_begin, x_end) × [y_begin, y_end).
struct TileRect {
    int x_begin, x_end, y_begin, y_end;
    size_t pixels() const { return size_t(x_end - x_begin) * size_t(y_end - y_begin); }
    bool overlaps(const TileRect& other) const {
        return x_begin < other.x_end && other.x_begin < x_end && y_begin < other.y_end && other.y_begin < y_end;
    }
};

/// What the tile renderer is asked to do: the library's side of api::RenderOptions (which the
/// API turns into this), with the crop as tiles, the layers parsed, and the hooks only the
/// library itself uses (where tiles come from and go to, for a distributed render).
struct RenderJob {
    int threads = 0;  ///< 0 = all cores
    /// Render only the tiles that overlap this window of the image (`whitted render --crop`):
    /// the image is still the whole image, black outside those tiles; crop_image() cuts it out.
    /// Each pixel is the one the whole render gives, bit for bit.
    std::optional<TileRect> crop;
    /// Render layers to compute. With any, the beauty is the float sum of the colour layers
    /// (docs/layers.md); without, the render takes the path that knows nothing of layers.
    LayerSet layers;
    /// Set from outside (a signal handler) to stop early; checked before every tile.
    const std::atomic<bool>* cancel = nullptr;
    /// Called from one thread a few times a second while rendering (e.g. a progress bar).
    std::function<void(const api::Progress&)> on_progress;
    /// Where the tiles come from (a distributed render: docs/distributed.md). Unset: every tile,
    /// spread over the threads. Set: each worker thread asks it for a tile index (row-major,
    /// tile_rect) until it returns false, so this process renders only the tiles it is given;
    /// it is called from several threads at once.
    std::function<bool(size_t& tile)> next_tile;
    /// Called from the worker thread that finished `tile`, once its pixels are in `image`
    /// (only that tile's rectangle is final; other tiles are being written meanwhile).
    std::function<void(size_t tile, const struct Image& image, const RayCounts& counts)> on_tile_done;
};

/// render() works in square tiles of this many pixels a side, numbered row by row.
constexpr int render_tile_size = 32;
size_t render_tile_count(int width, int height);
/// An image of at most this many samples (pixels × samples per pixel) of a scene without a BVH
/// (Accelerator::has_bvh: a few shapes, so little work per sample) is rendered on the calling
/// thread, tile after tile: TBB's start (its allocator, its arena, its worker threads) costs a
/// process about 2 ms, more than such an image takes on one core (a 64 × 48 sphere: 0.5 ms).
/// With a BVH, Embree's device has started TBB already. The pixels are the same either way.
constexpr size_t most_pixels_on_one_thread = 64 * 64;
TileRect render_tile_rect(int width, int height, size_t tile);

/// What render() gives back: the whole image (black outside the tiles rendered), from which
/// the API makes an api::RenderResult (cut to the crop window, the rays as RenderStats).
struct RenderedTiles {
    Image image;
    RayCounts rays;
    double seconds = 0;
    bool cancelled = false;
};

/// The tiles (their numbers, ascending) that overlap `window`.
std::vector<size_t> render_tiles_overlapping(const Scene& scene, const TileRect& window);
/// The window's pixels of `image` (every layer too), as an image of the window's size.
Image crop_image(const Image& image, const TileRect& window);

/// Renders the scene in tiles on all (or `threads`) cores. Every pixel depends only on the
/// scene, never on the order tiles finish, so the image is bit-identical for any thread count.
RenderedTiles render(const Scene& scene, const Accelerator& accelerator, const RenderJob& options);

/// One pixel, all its samples averaged (box filter).
Color render_pixel(const Scene& scene, const LectureShading& shading, int i, int j, RayCounts& counts);

// The packets render() traces its camera rays in. Every caller that must give render()'s values
// bit for bit (the layers, the shading cache, `whitted explain`) forms them here, since a ray's
// packet mates change the order of Embree's candidates and so, at a tie, its hit.

/// Pixel (i, j)'s n×n camera rays (n = scene.samples), row by row, in packets of up to
/// Accelerator::packet_size: `trace(rays, count)` once per packet, in order.
template <class TracePacket>
void for_each_pixel_sample_packet(const Scene& scene, int i, int j, TracePacket&& trace) {
    const int n = scene.samples;
    PacketArray<Ray, Accelerator::packet_size> rays;
    int count = 0;
    for (int b = 0; b < n; ++b) {
        for (int a = 0; a < n; ++a) {
            double x0, y0;
            sample_position(i, j, a, b, n, scene.width, scene.height, x0, y0);
            rays[count++] = camera_ray(scene, x0, y0);
            if (count == Accelerator::packet_size || (a == n - 1 && b == n - 1)) {
                trace(static_cast<const Ray*>(rays.data()), count);
                count = 0;
            }
        }
    }
}

/// The camera rays of [x_begin, x_end) × [y_begin, y_end), one sample per pixel, in packets of
/// 4×4 neighbouring pixels from the corner (render() starts each at a multiple of 4):
/// `trace(rays, count, pixel_x, pixel_y)` once per packet.
template <class TracePacket>
void for_each_single_sample_packet(const Scene& scene, int x_begin, int x_end, int y_begin, int y_end,
                                   TracePacket&& trace) {
    constexpr int side = 4;
    static_assert(side * side == Accelerator::packet_size);
    for (int by = y_begin; by < y_end; by += side) {
        for (int bx = x_begin; bx < x_end; bx += side) {
            PacketArray<Ray, Accelerator::packet_size> rays;
            int pixel_x[Accelerator::packet_size], pixel_y[Accelerator::packet_size];
            int count = 0;
            for (int y = by; y < std::min(by + side, y_end); ++y) {
                for (int x = bx; x < std::min(bx + side, x_end); ++x) {
                    double x0, y0;
                    sample_position(x, y, 0, 0, 1, scene.width, scene.height, x0, y0);
                    rays[count] = camera_ray(scene, x0, y0);
                    pixel_x[count] = x, pixel_y[count] = y;
                    ++count;
                }
            }
            trace(static_cast<const Ray*>(rays.data()), count, static_cast<const int*>(pixel_x),
                  static_cast<const int*>(pixel_y));
        }
    }
}

/// The camera rays render() traces together in one packet, and which of them are pixel (i, j)'s.
struct CameraPacket {
    std::vector<Ray> rays;
    std::vector<int> sample;  ///< per ray: its sample number b·n + a in pixel (i, j), or −1 (another pixel's)
};
/// The packets in which render() traces pixel (i, j)'s camera rays, in order: with one sample per
/// pixel, the 4×4 block of pixels that holds it; with n×n samples, its samples 16 at a time. So
/// `whitted explain` traces exactly what the render traced.
std::vector<CameraPacket> camera_packets(const Scene& scene, int i, int j);

}  // namespace whitted
