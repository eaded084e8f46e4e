// SPDX-License-Identifier: MIT
#pragma once

// `whitted explain`: every term of one pixel's equation, as the render computed it.

#include "render/accelerator.h"
#include "render/layers.h"
#include "render/shading.h"
#include "scene/scene.h"

#include <optional>
#include <vector>

namespace whitted {

struct ExplainedLight {
    size_t light = 0;  ///< 0-based, file order
    LightTerms terms;
    /// Where terms.blocked: the nearest surface on the shadow ray (its object and t).
    std::optional<SurfaceHit> blocker;
};

/// One path segment: the ray, then its hit and the terms there, or its miss.
struct ExplainedSegment {
    int level = 0;                ///< 0 = the camera ray
    bool refracted_path = false;  ///< the segment's ray is a refracted ray (else camera or mirror)
    Ray ray;
    Color weight;  ///< the product of the km (and kt) met before this segment
    bool hit = false;
    Color seen;  ///< a miss: weight·background
    SurfaceHit surface;
    Vec3 normal;  ///< n, turned toward the ray
    Color ambient;
    std::vector<ExplainedLight> lights;
    Color local, added;  ///< local = ka·Ia + Σ(diffuse + specular); added = weight·local
    bool mirrored = false;
    Ray mirror_ray;
    Color mirror_weight;  ///< weight·km (1 at total internal reflection), the mirror segment's weight
    bool transmitted = false;
    Ray refracted_ray;
    Color refracted_weight;  ///< weight·kt, the refracted segment's weight (its segments come first)
};

struct ExplainedSample {
    int sample = 0;  ///< b·n + a in the n×n grid
    std::vector<ExplainedSegment> segments;
    Color radiance;  ///< Σ of the segments' `added` and `seen`, in that order, as traced
};

struct PixelExplanation {
    int x = 0, y = 0;
    std::vector<ExplainedSample> samples;
    Color sum;                   ///< Σ radiance over the samples, in order
    Color pixel;                 ///< sum / samples (as render_pixel), before rounding to float
    float rgb[3] = {};           ///< the pixel of `whitted render`'s EXR without layers
    PixelLayers layers;          ///< the same paths as render layers
    float layer_beauty[3] = {};  ///< the pixel of an EXR rendered with layers (their float sum)
};

/// Traces pixel (x, y) in the packets render() uses (camera_packets) and records every term.
PixelExplanation explain_pixel(const Scene& scene, const Accelerator& accelerator, int x, int y);

}  // namespace whitted
