// SPDX-License-Identifier: MIT
#include "render/reshade.h"

#include "core/packet_array.h"
#include "render/renderer.h"
#include "render/shading.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>

namespace whitted {

namespace {

/// Watches one packet's paths and keeps, lane by lane, what re-shading needs.
class PathRecorder final : public PathObserver {
public:
    explicit PathRecorder(int lanes) : m_lanes(size_t(lanes)) {}
    void reset() {
        for (Lane& lane : m_lanes) lane.hits.clear(), lane.lights.clear(), lane.miss = false;
    }
    void miss(int lane, int, const Ray&, const Color&, const Color&) override { m_lanes[size_t(lane)].miss = true; }
    void hit(int lane, int, const Ray& ray, const SurfaceHit& hit, const Vec3& normal) override {
        Lane& l = m_lanes[size_t(lane)];
        l.hits.push_back({normal, -ray.direction, hit.material, uint32_t(l.lights.size())});
    }
    void ambient(int, int, const Color&) override {}
    void light(int lane, int, size_t light, const LightTerms& terms) override {
        // As see_lights decides `arrives`: counted by the convention and not blocked.
        if (terms.facing && !terms.blocked)
            m_lanes[size_t(lane)].lights.push_back({terms.to_light, terms.n_dot_l, uint32_t(light)});
    }
    void local(int, int, const Color&, const Color&, const Color&) override {}
    void mirror(int, int, const Ray&, const Color&) override {}
    void transmitted(int, int, const Ray&, const Color&) override {}

    /// Lane `lane`'s path appended to `tile` as its next sample.
    void append(int lane, ShadingCache::Tile& tile) const {
        const Lane& l = m_lanes[size_t(lane)];
        const uint32_t lights_base = uint32_t(tile.lights.size());
        tile.hits.pop_back();  // the sentinel, put back after this sample's hits
        for (ShadingCache::Hit hit : l.hits) {
            hit.lights_begin += lights_base;
            tile.hits.push_back(hit);
        }
        tile.lights.insert(tile.lights.end(), l.lights.begin(), l.lights.end());
        tile.hits.push_back({{}, {}, 0, uint32_t(tile.lights.size())});
        tile.ends_in_miss.push_back(l.miss);
        tile.hits_begin.push_back(uint32_t(tile.hits.size() - 1));
    }

private:
    struct Lane {
        std::vector<ShadingCache::Hit> hits;
        std::vector<ShadingCache::Arrived> lights;
        bool miss = false;
    };
    std::vector<Lane> m_lanes;
};

ShadingCache::Tile empty_tile() {
    ShadingCache::Tile tile;
    tile.hits_begin.push_back(0);
    tile.hits.push_back({});  // the sentinel: its lights_begin ends the last hit's lights
    return tile;
}

/// render.min_weight's test, as the driver makes it (shading.cpp).
bool worth_tracing(const Color& weight, double min_weight) {
    return !(std::max({weight.x, weight.y, weight.z}) < min_weight);
}

/// One sample's radiance from its recorded path, as LectureShading::trace_paths sums it for a
/// scene without transmission; false where the path would go on past its recorded end.
bool shade_sample(const Scene& scene, const ShadingCache::Tile& tile, size_t sample, ArrivingLight* arriving,
                  Color& radiance) {
    const size_t light_count = scene.lights.size();
    const uint32_t first = tile.hits_begin[sample], end = tile.hits_begin[sample + 1];
    radiance = Color(0.0);
    Color weight(1.0);
    for (int level = 0; level < scene.max_depth; ++level) {
        const uint32_t at = first + uint32_t(level);
        if (at == end) {
            if (!tile.ends_in_miss[sample]) return false;  // the render did not trace this ray
            radiance += weight * scene.background;
            return true;
        }
        const ShadingCache::Hit& hit = tile.hits[at];
        for (size_t k = 0; k < light_count; ++k) arriving[k].arrives = false;
        for (uint32_t a = hit.lights_begin; a < tile.hits[at + 1].lights_begin; ++a) {
            const ShadingCache::Arrived& light = tile.lights[a];
            ArrivingLight& seen = arriving[light.light];
            seen.to_light = light.to_light;
            seen.n_dot_l = light.n_dot_l;
            seen.intensity = scene.lights[light.light].intensity;
            seen.arrives = true;
        }
        const Material& material = scene.materials[hit.material];
        const Color local =
            LectureShading::local_terms(material, scene.ambient, hit.normal, hit.to_eye, arriving, light_count);
        const Reflectance reflected = LectureShading::reflectance(material, hit.normal, hit.to_eye);
        const Color added = weight * local * reflected.local;
        radiance += added;
        const Color mirror_weight = reflected.mirror;
        const Color next_weight = weight * mirror_weight;
        if (!is_zero(mirror_weight) && level + 1 < scene.max_depth && worth_tracing(next_weight, scene.min_weight))
            weight = next_weight;
        else
            return true;
    }
    return true;
}

bool transmits(const Scene& scene) {
    for (const Material& material : scene.materials)
        if (!is_zero(material.kt)) return true;
    return false;
}

}  // namespace

ShadingCache ShadingCache::record(const Scene& scene, const Accelerator& accelerator, int threads, Image& image) {
    ShadingCache cache;
    Scene& kept = cache.m_scene;
    kept.width = scene.width, kept.height = scene.height, kept.samples = scene.samples;
    kept.max_depth = scene.max_depth, kept.convention = scene.convention, kept.intersection = scene.intersection;
    kept.camera = scene.camera, kept.lights = scene.lights, kept.materials = scene.materials;

    image = Image();
    image.width = scene.width, image.height = scene.height;
    image.rgb.assign(size_t(scene.width) * size_t(scene.height) * 3, 0.0f);
    const bool keep = !transmits(scene) && scene.lights.size() < (size_t(1) << 31);
    const size_t tile_count = render_tile_count(scene.width, scene.height);
    if (keep) cache.m_tiles.resize(tile_count);
    const LectureShading shading(scene, accelerator);
    const int n = scene.samples;
    const auto record_tile = [&](size_t t) {
        const TileRect rect = render_tile_rect(scene.width, scene.height, t);
        Tile tile = empty_tile();
        PathRecorder recorder(Accelerator::packet_size);
        PacketArray<Color, Accelerator::packet_size> radiance;
        RayCounts counts;
        const auto store = [&](int x, int y, const Color& c) {
            float* out = &image.rgb[3 * (size_t(y) * size_t(scene.width) + size_t(x))];
            out[0] = float(c.x), out[1] = float(c.y), out[2] = float(c.z);
        };
        if (n == 1) {
            for_each_single_sample_packet(
                scene, rect.x_begin, rect.x_end, rect.y_begin, rect.y_end,
                [&](const Ray* rays, int count, const int* px, const int* py) {
                    recorder.reset();
                    shading.trace_packet(rays, count, 0, radiance.data(), counts, recorder);
                    for (int k = 0; k < count; ++k) {
                        store(px[k], py[k], radiance[k]);
                        if (!keep) continue;
                        tile.pixel.push_back(uint32_t(py[k]) * uint32_t(scene.width) + uint32_t(px[k]));
                        recorder.append(k, tile);
                    }
                });
        } else {
            for (int y = rect.y_begin; y < rect.y_end; ++y)
                for (int x = rect.x_begin; x < rect.x_end; ++x) {
                    Color sum(0.0);
                    for_each_pixel_sample_packet(scene, x, y, [&](const Ray* rays, int count) {
                        recorder.reset();
                        shading.trace_packet(rays, count, 0, radiance.data(), counts, recorder);
                        for (int k = 0; k < count; ++k) {
                            sum += radiance[k];
                            if (keep) recorder.append(k, tile);
                        }
                    });
                    store(x, y, sum / double(n * n));
                    if (keep) tile.pixel.push_back(uint32_t(y) * uint32_t(scene.width) + uint32_t(x));
                }
        }
        if (keep) {
            tile.hits.shrink_to_fit(), tile.lights.shrink_to_fit();
            cache.m_tiles[t] = std::move(tile);
        }
    };
    tbb::task_arena arena(threads > 0 ? threads : tbb::this_task_arena::max_concurrency());
    arena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, tile_count, 1), [&](const tbb::blocked_range<size_t>& range) {
            for (size_t t = range.begin(); t != range.end(); ++t) record_tile(t);
        });
    });
    return cache;
}

bool ShadingCache::covers(const Scene& edited) const {
    const Scene& s = m_scene;
    if (m_tiles.empty() || transmits(edited)) return false;
    if (edited.width != s.width || edited.height != s.height || edited.samples != s.samples ||
        edited.max_depth != s.max_depth || edited.convention != s.convention || edited.intersection != s.intersection)
        return false;
    const Camera &a = edited.camera, &b = s.camera;
    if (a.type != b.type || !(a.eye == b.eye) || !(a.forward == b.forward) || !(a.right == b.right) || !(a.up == b.up))
        return false;
    if (edited.materials.size() != s.materials.size() || edited.lights.size() != s.lights.size()) return false;
    for (size_t k = 0; k < s.lights.size(); ++k) {
        const Light &e = edited.lights[k], &r = s.lights[k];
        if (e.type != r.type || !(e.position == r.position) || !(e.toward_light == r.toward_light)) return false;
    }
    return true;
}

bool ShadingCache::reshade(const Scene& edited, int threads, Image& image) const {
    if (!covers(edited)) return false;
    image = Image();
    image.width = edited.width, image.height = edited.height;
    image.rgb.assign(size_t(edited.width) * size_t(edited.height) * 3, 0.0f);
    const int n = edited.samples;
    const double samples = double(n * n);
    std::atomic<bool> covered{true};
    const auto shade_tile = [&](const Tile& tile) {
        std::vector<ArrivingLight> arriving(edited.lights.size());
        Color radiance;
        size_t sample = 0;
        for (const uint32_t pixel : tile.pixel) {
            // As render_pixel: the samples' sum over n², or with one sample the radiance as it is.
            Color sum(0.0);
            for (int s = 0; s < n * n; ++s, ++sample) {
                if (!shade_sample(edited, tile, sample, arriving.data(), radiance)) {
                    covered.store(false, std::memory_order_relaxed);
                    return;
                }
                sum += radiance;
            }
            const Color c = n == 1 ? radiance : sum / samples;
            float* out = &image.rgb[3 * size_t(pixel)];
            out[0] = float(c.x), out[1] = float(c.y), out[2] = float(c.z);
        }
    };
    tbb::task_arena arena(threads > 0 ? threads : tbb::this_task_arena::max_concurrency());
    arena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, m_tiles.size(), 1),
                          [&](const tbb::blocked_range<size_t>& range) {
                              for (size_t t = range.begin(); t != range.end(); ++t) {
                                  if (!covered.load(std::memory_order_relaxed)) return;
                                  shade_tile(m_tiles[t]);
                              }
                          });
    });
    return covered.load();
}

size_t ShadingCache::bytes() const {
    size_t total = sizeof(*this) + m_tiles.capacity() * sizeof(Tile);
    for (const Tile& tile : m_tiles)
        total += tile.pixel.capacity() * sizeof(uint32_t) + tile.hits_begin.capacity() * sizeof(uint32_t) +
                 tile.ends_in_miss.capacity() + tile.hits.capacity() * sizeof(Hit) +
                 tile.lights.capacity() * sizeof(Arrived);
    return total;
}

}  // namespace whitted
