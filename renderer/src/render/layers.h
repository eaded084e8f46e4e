// SPDX-License-Identifier: MIT
#pragma once

// Render layers (AOVs): the pixel's radiance split into the lecture's terms, and data about the
// camera ray's first hit, written as extra channels of the EXR (docs/layers.md).

#include "core/vec3.h"
#include "render/shading.h"
#include "scene/layer_names.h"
#include "scene/scene.h"
#include "whitted/image.h"

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace whitted {

/// The radiance of one camera ray split into the layers' terms, and its first hit's data.
struct PathLayers {
    Color ambient, diffuse, specular, mirror, transmission, background;
    std::vector<Color> lights;  ///< one per light
    Vec3 N, Ng, P;
    double Z = 0;
    Color albedo;
    uint32_t object = 0, material = 0;
    int hits = 0;
};

/// A PathObserver that sorts every term of a packet's paths into PathLayers, lane by lane.
class LayerRecorder final : public PathObserver {
public:
    LayerRecorder(const Scene& scene, int lanes);
    /// Starts a new packet: every lane's layers back to a miss with nothing added.
    void reset();
    const PathLayers& lane(int i) const { return m_lanes[i]; }

    void miss(int lane, int level, const Ray& ray, const Color& weight, const Color& seen) override;
    void hit(int lane, int level, const Ray& ray, const SurfaceHit& hit, const Vec3& normal) override;
    void ambient(int lane, int level, const Color& ambient) override;
    void light(int lane, int level, size_t light, const LightTerms& terms) override;
    void local(int lane, int level, const Color& weight, const Color& local, const Color& added) override;
    void mirror(int lane, int level, const Ray&, const Color&) override;
    void transmitted(int lane, int level, const Ray&, const Color&) override;

private:
    /// Where a lane's terms past the first hit go: the mirror or the transmission layer, by the
    /// first hit's ray they come back along. The rays the first hit sends start their segments
    /// last announced, first (depth first), so each segment at level 1 takes the latest.
    /// A segment starts: at level 1, it takes the first hit's ray announced last.
    void start_segment(int lane, int level);
    Color& secondary(int lane) {
        return m_in_transmission[size_t(lane)] ? m_lanes[lane].transmission : m_lanes[lane].mirror;
    }
    const Scene& m_scene;
    std::vector<PathLayers> m_lanes;
    std::vector<std::vector<bool>> m_announced;  ///< per lane: the first hit's rays not yet started (true: refracted)
    std::vector<bool> m_in_transmission;
};

// ImageLayer, one layer of an image, is public: whitted/image.h.

/// The image layers of `selection` for `scene`, sized and zeroed (Z: +inf), in a fixed order.
std::vector<ImageLayer> make_image_layers(const Scene& scene, LayerSet selection);

/// Layer values of one pixel, in double, before they are stored as float.
struct PixelLayers {
    PathLayers sum;    ///< colour terms: summed over the pixel's samples, then averaged by finish()
    PathLayers first;  ///< data terms: the pixel's first sample's
    /// Back to no samples, keeping the storage (a render calls this once per pixel).
    void clear();
    void add_sample(const PathLayers& sample, bool first_sample);
    void finish(int samples_per_pixel);
};

/// Stores pixel `index`'s layers into `layers` (made by make_image_layers with `selection`) and
/// its beauty into beauty[0..2]: the float sum ambient + diffuse + specular + mirror + transmission + background
/// of the layers' float values, in that order, so that the file's layers add up to its R, G, B
/// bit for bit.
void store_pixel_layers(const PixelLayers& pixel, LayerSet selection, std::vector<ImageLayer>& layers, size_t index,
                        float* beauty);

}  // namespace whitted
