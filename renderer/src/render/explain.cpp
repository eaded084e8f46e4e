// SPDX-License-Identifier: MIT
#include "render/explain.h"

#include "core/packet_array.h"
#include "render/renderer.h"

namespace whitted {

namespace {

/// Records the segments of the lanes that are the pixel's samples; ignores the others.
class SegmentRecorder final : public PathObserver {
public:
    SegmentRecorder(const Accelerator& accelerator, const std::vector<int>& sample)
        : m_accelerator(accelerator), m_sample(sample), m_samples(sample.size()) {
        for (size_t i = 0; i < sample.size(); ++i) m_samples[i].sample = sample[i];
    }
    std::vector<ExplainedSample>& samples() { return m_samples; }

    void miss(int lane, int level, const Ray& ray, const Color& weight, const Color& seen) override {
        if (m_sample[lane] < 0) return;
        const bool refracted = next_weight(lane).second;
        ExplainedSegment& segment = begin(lane, level, ray, weight);
        segment.refracted_path = refracted;
        segment.seen = seen;
    }
    void hit(int lane, int level, const Ray& ray, const SurfaceHit& hit, const Vec3& normal) override {
        if (m_sample[lane] < 0) return;
        const auto [weight, refracted] = next_weight(lane);
        ExplainedSegment& segment = begin(lane, level, ray, weight);
        segment.refracted_path = refracted;
        segment.hit = true;
        segment.surface = hit;
        segment.normal = normal;
    }
    void ambient(int lane, int, const Color& ambient) override {
        if (m_sample[lane] >= 0) m_samples[lane].segments.back().ambient = ambient;
    }
    void light(int lane, int, size_t light, const LightTerms& terms) override {
        if (m_sample[lane] < 0) return;
        ExplainedLight explained{light, terms, std::nullopt};
        if (terms.blocked) {
            SurfaceHit blocker;
            if (m_accelerator.intersect(terms.shadow_ray, blocker)) explained.blocker = blocker;
        }
        m_samples[lane].segments.back().lights.push_back(explained);
    }
    void local(int lane, int, const Color&, const Color& local, const Color& added) override {
        if (m_sample[lane] < 0) return;
        m_samples[lane].segments.back().local = local;
        m_samples[lane].segments.back().added = added;
    }
    void mirror(int lane, int, const Ray& mirror_ray, const Color& weight) override {
        if (m_sample[lane] < 0) return;
        ExplainedSegment& segment = m_samples[lane].segments.back();
        segment.mirrored = true;
        segment.mirror_ray = mirror_ray;
        segment.mirror_weight = weight;
        m_pending[size_t(lane)].emplace_back(weight, false);
    }
    void transmitted(int lane, int, const Ray& refracted_ray, const Color& weight) override {
        if (m_sample[lane] < 0) return;
        ExplainedSegment& segment = m_samples[lane].segments.back();
        segment.transmitted = true;
        segment.refracted_ray = refracted_ray;
        segment.refracted_weight = weight;
        m_pending[size_t(lane)].emplace_back(weight, true);
    }

private:
    /// The weight of the segment that starts now: paths are traced depth first, so the rays
    /// announced (mirror, then refracted) start their segments last announced, first.
    std::pair<Color, bool> next_weight(int lane) {
        std::vector<std::pair<Color, bool>>& pending = m_pending[size_t(lane)];
        if (pending.empty()) return {Color(1.0), false};
        const std::pair<Color, bool> next = pending.back();
        pending.pop_back();
        return next;
    }
    ExplainedSegment& begin(int lane, int level, const Ray& ray, const Color& weight) {
        ExplainedSegment segment;
        segment.level = level;
        segment.ray = ray;
        segment.weight = weight;
        m_samples[lane].segments.push_back(segment);
        return m_samples[lane].segments.back();
    }

    const Accelerator& m_accelerator;
    const std::vector<int>& m_sample;
    std::vector<ExplainedSample> m_samples;
    /// Per lane, the rays announced and not yet started: their weight, and whether refracted.
    std::vector<std::vector<std::pair<Color, bool>>> m_pending =
        std::vector<std::vector<std::pair<Color, bool>>>(m_samples.size());
};

/// Both observers at once: the segments and the layers of the same trace.
class BothRecorders final : public PathObserver {
public:
    BothRecorders(PathObserver& a, PathObserver& b) : m_a(a), m_b(b) {}
    void miss(int lane, int level, const Ray& r, const Color& w, const Color& seen) override {
        m_a.miss(lane, level, r, w, seen), m_b.miss(lane, level, r, w, seen);
    }
    void hit(int lane, int level, const Ray& r, const SurfaceHit& h, const Vec3& n) override {
        m_a.hit(lane, level, r, h, n), m_b.hit(lane, level, r, h, n);
    }
    void ambient(int lane, int level, const Color& a) override {
        m_a.ambient(lane, level, a), m_b.ambient(lane, level, a);
    }
    void light(int lane, int level, size_t k, const LightTerms& t) override {
        m_a.light(lane, level, k, t), m_b.light(lane, level, k, t);
    }
    void local(int lane, int level, const Color& w, const Color& l, const Color& added) override {
        m_a.local(lane, level, w, l, added), m_b.local(lane, level, w, l, added);
    }
    void mirror(int lane, int level, const Ray& r, const Color& w) override {
        m_a.mirror(lane, level, r, w), m_b.mirror(lane, level, r, w);
    }
    void transmitted(int lane, int level, const Ray& r, const Color& w) override {
        m_a.transmitted(lane, level, r, w), m_b.transmitted(lane, level, r, w);
    }

private:
    PathObserver &m_a, &m_b;
};

}  // namespace

PixelExplanation explain_pixel(const Scene& scene, const Accelerator& accelerator, int x, int y) {
    const LectureShading shading(scene, accelerator);
    PixelExplanation explanation;
    explanation.x = x, explanation.y = y;
    RayCounts counts;
    LayerRecorder layers(scene, Accelerator::packet_size);
    bool first = true;
    for (const CameraPacket& packet : camera_packets(scene, x, y)) {
        SegmentRecorder segments(accelerator, packet.sample);
        BothRecorders both(segments, layers);
        layers.reset();
        PacketArray<Color, Accelerator::packet_size> radiance;
        const int count = int(packet.rays.size());
        shading.trace_packet(packet.rays.data(), count, 0, radiance.data(), counts, both);
        for (int k = 0; k < count; ++k) {
            if (packet.sample[k] < 0) continue;
            ExplainedSample& sample = segments.samples()[k];
            sample.radiance = radiance[k];
            explanation.sum += radiance[k];  // as render_pixel sums its samples
            explanation.samples.push_back(std::move(sample));
            explanation.layers.add_sample(layers.lane(k), first);
            first = false;
        }
    }
    const int n = scene.samples;
    explanation.pixel = n == 1 ? explanation.sum : explanation.sum / double(n * n);
    for (int c = 0; c < 3; ++c) explanation.rgb[c] = float(explanation.pixel[c]);
    explanation.layers.finish(n * n);
    // The layers' beauty, as store_pixel_layers computes it.
    std::vector<ImageLayer> none;
    store_pixel_layers(explanation.layers, LayerSet(), none, 0, explanation.layer_beauty);
    return explanation;
}

}  // namespace whitted
