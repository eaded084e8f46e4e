// SPDX-License-Identifier: MIT
#include "render/layers.h"

#include <limits>
#include <stdexcept>

namespace whitted {

namespace {
constexpr double inf = std::numeric_limits<double>::infinity();
}  // namespace

LayerRecorder::LayerRecorder(const Scene& scene, int lanes)
    : m_scene(scene), m_lanes(size_t(lanes)), m_announced(size_t(lanes)), m_in_transmission(size_t(lanes), false) {
    for (PathLayers& lane : m_lanes) lane.lights.resize(scene.lights.size());
    reset();
}

void LayerRecorder::reset() {
    for (auto& announced : m_announced) announced.clear();
    m_in_transmission.assign(m_in_transmission.size(), false);
    for (PathLayers& lane : m_lanes) {
        lane.ambient = lane.diffuse = lane.specular = lane.mirror = lane.transmission = lane.background = Color(0.0);
        for (Color& light : lane.lights) light = Color(0.0);
        lane.N = lane.Ng = lane.P = Vec3(0.0);
        lane.Z = inf;
        lane.albedo = Color(0.0);
        lane.object = lane.material = 0;
        lane.hits = 0;
    }
}

void LayerRecorder::start_segment(int i, int level) {
    if (level != 1 || m_announced[size_t(i)].empty()) return;
    m_in_transmission[size_t(i)] = m_announced[size_t(i)].back();
    m_announced[size_t(i)].pop_back();
}

void LayerRecorder::mirror(int i, int level, const Ray&, const Color&) {
    if (level == 0) m_announced[size_t(i)].push_back(false);
}

void LayerRecorder::transmitted(int i, int level, const Ray&, const Color&) {
    if (level == 0) m_announced[size_t(i)].push_back(true);
}

void LayerRecorder::miss(int i, int level, const Ray&, const Color&, const Color& seen) {
    start_segment(i, level);
    (level == 0 ? m_lanes[i].background : secondary(i)) += seen;
}

void LayerRecorder::hit(int i, int level, const Ray&, const SurfaceHit& hit, const Vec3& normal) {
    start_segment(i, level);
    PathLayers& lane = m_lanes[i];
    ++lane.hits;
    if (level != 0) return;
    lane.N = normal;
    lane.Ng = hit.geometric_normal;
    lane.P = hit.point;
    lane.Z = hit.t;
    lane.albedo = m_scene.materials[hit.material].kd;
    lane.object = hit.object;
    lane.material = hit.material + 1;
}

void LayerRecorder::ambient(int i, int level, const Color& ambient) {
    if (level == 0) m_lanes[i].ambient = ambient;
}

void LayerRecorder::light(int i, int level, size_t light, const LightTerms& terms) {
    if (level != 0) return;
    PathLayers& lane = m_lanes[i];
    lane.diffuse += terms.diffuse;
    lane.specular += terms.specular;
    lane.lights[light] += terms.diffuse + terms.specular;
}

void LayerRecorder::local(int i, int level, const Color&, const Color&, const Color& added) {
    // The first hit's local terms are in ambient, diffuse and specular; every later one, times
    // the mirror weight, is part of what the first mirror ray brings back.
    if (level != 0) secondary(i) += added;
}

std::vector<ImageLayer> make_image_layers(const Scene& scene, LayerSet selection) {
    std::vector<ImageLayer> layers;
    const size_t pixels = size_t(scene.width) * scene.height;
    const auto add = [&](const std::string& name, std::vector<std::string> suffixes, bool data, float fill) {
        ImageLayer layer;
        layer.name = name;
        for (const std::string& suffix : suffixes)
            layer.channels.push_back(suffix.empty() ? name : name + "." + suffix);
        layer.data = data;
        layer.values.assign(pixels * layer.channels.size(), fill);
        layers.push_back(std::move(layer));
    };
    for (int k = 0; k < layer_kinds; ++k) {
        const Layer layer = Layer(k);
        if (!selection.has(layer)) continue;
        switch (layer) {
            case Layer::ambient:
            case Layer::diffuse:
            case Layer::specular:
            case Layer::mirror:
            case Layer::transmission:
            case Layer::background:
                add(layer_name(layer), {"R", "G", "B"}, false, 0.0f);
                break;
            case Layer::lights:
                for (size_t i = 0; i < scene.lights.size(); ++i)
                    add("light" + std::to_string(i + 1), {"R", "G", "B"}, false, 0.0f);
                break;
            case Layer::albedo:
                add(layer_name(layer), {"R", "G", "B"}, true, 0.0f);
                break;
            case Layer::N:
            case Layer::Ng:
            case Layer::P:
                add(layer_name(layer), {"X", "Y", "Z"}, true, 0.0f);
                break;
            case Layer::Z:
                add("Z", {""}, true, std::numeric_limits<float>::infinity());
                break;
            case Layer::objectId:
            case Layer::materialId:
            case Layer::hits:
                add(layer_name(layer), {""}, true, 0.0f);
                break;
        }
    }
    return layers;
}

void PixelLayers::clear() {
    sum.ambient = sum.diffuse = sum.specular = sum.mirror = sum.transmission = sum.background = Color(0.0);
    for (Color& light : sum.lights) light = Color(0.0);
}

void PixelLayers::add_sample(const PathLayers& sample, bool first_sample) {
    if (sum.lights.size() != sample.lights.size()) sum.lights.assign(sample.lights.size(), Color(0.0));
    sum.ambient += sample.ambient;
    sum.diffuse += sample.diffuse;
    sum.specular += sample.specular;
    sum.mirror += sample.mirror;
    sum.transmission += sample.transmission;
    sum.background += sample.background;
    for (size_t i = 0; i < sample.lights.size(); ++i) sum.lights[i] += sample.lights[i];
    if (first_sample) first = sample;
}

void PixelLayers::finish(int samples_per_pixel) {
    if (samples_per_pixel == 1) return;
    const double n = double(samples_per_pixel);  // as render_pixel averages the beauty
    sum.ambient = sum.ambient / n;
    sum.diffuse = sum.diffuse / n;
    sum.specular = sum.specular / n;
    sum.mirror = sum.mirror / n;
    sum.transmission = sum.transmission / n;
    sum.background = sum.background / n;
    for (Color& light : sum.lights) light = light / n;
}

namespace {
void store3(ImageLayer& layer, size_t index, const Vec3& v) {
    float* out = &layer.values[3 * index];
    out[0] = float(v.x), out[1] = float(v.y), out[2] = float(v.z);
}
}  // namespace

void store_pixel_layers(const PixelLayers& pixel, LayerSet selection, std::vector<ImageLayer>& layers, size_t index,
                        float* beauty) {
    const PathLayers& c = pixel.sum;
    const PathLayers& d = pixel.first;
    // The beauty is the sum of the float layer values, in float, in this fixed order.
    const Color terms[] = {c.ambient, c.diffuse, c.specular, c.mirror, c.transmission, c.background};
    for (int channel = 0; channel < 3; ++channel) {
        float total = 0.0f;
        for (const Color& term : terms) total += float(term[channel]);
        beauty[channel] = total;
    }
    size_t next = 0;  // layers are in make_image_layers' order
    for (int k = 0; k < layer_kinds; ++k) {
        const Layer layer = Layer(k);
        if (!selection.has(layer)) continue;
        switch (layer) {
            case Layer::ambient:
                store3(layers[next++], index, c.ambient);
                break;
            case Layer::diffuse:
                store3(layers[next++], index, c.diffuse);
                break;
            case Layer::specular:
                store3(layers[next++], index, c.specular);
                break;
            case Layer::mirror:
                store3(layers[next++], index, c.mirror);
                break;
            case Layer::transmission:
                store3(layers[next++], index, c.transmission);
                break;
            case Layer::background:
                store3(layers[next++], index, c.background);
                break;
            case Layer::lights:
                for (const Color& light : c.lights) store3(layers[next++], index, light);
                break;
            case Layer::N:
                store3(layers[next++], index, d.N);
                break;
            case Layer::Ng:
                store3(layers[next++], index, d.Ng);
                break;
            case Layer::P:
                store3(layers[next++], index, d.P);
                break;
            case Layer::Z:
                layers[next++].values[index] = float(d.Z);
                break;
            case Layer::albedo:
                store3(layers[next++], index, d.albedo);
                break;
            case Layer::objectId:
                layers[next++].values[index] = float(d.object);
                break;
            case Layer::materialId:
                layers[next++].values[index] = float(d.material);
                break;
            case Layer::hits:
                layers[next++].values[index] = float(d.hits);
                break;
        }
    }
}

}  // namespace whitted
