// SPDX-License-Identifier: MIT
#pragma once

#include "render/accelerator.h"
#include "scene/scene.h"
#include "whitted/image.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace whitted {

/// What the lecture's equation needs of every sample of one render, kept to shade the image
/// again when only material coefficients (ka, kd, ks, p, km) or light intensities change: the
/// rays, their hits and which lights reach each hit do not depend on them (the LightMaterial
/// demo of `whitted live`, docs/live.md).
///
/// Per sample it keeps the path's surface hits in order (material, n, v, and per light that
/// arrives its l and n·l) and whether the path ended in a miss (the background) or where the
/// render stopped tracing it (km = 0, render.min_weight, render.max_depth). Re-shading calls
/// LectureShading's own local_terms and reflectance on these and sums as the driver and
/// render_pixel sum, so the image is bit for bit what render() gives of the edited scene.
/// Where the edited values would trace a mirror ray the render did not (km from 0, or a path
/// above the cut-off now), reshade() says so and the caller renders.
class ShadingCache {
public:
    /// Renders `scene` (the beauty, no layers: render()'s image bit for bit) into `image`,
    /// keeping what re-shading needs. Scenes with transmission (kt) are rendered but kept empty:
    /// their shadow rays and refracted paths depend on kt.
    static ShadingCache record(const Scene& scene, const Accelerator& accelerator, int threads, Image& image);

    /// Whether `edited` differs from the recorded scene at most in what re-shading covers, as
    /// far as the scene's numbers show: the image, camera, depth, convention, the lights' kinds,
    /// positions and directions, the number of materials and lights, and no transmission. The
    /// objects are the caller's to keep the same (the same file text).
    bool covers(const Scene& edited) const;

    /// The image of `edited` from the cache; false (and `image` unspecified) where the cache does
    /// not cover it, or a path would now go on past where the render stopped tracing it.
    bool reshade(const Scene& edited, int threads, Image& image) const;

    /// The cache's memory, in bytes.
    size_t bytes() const;
    bool empty() const { return m_tiles.empty(); }

    /// One surface hit of a path.
    struct Hit {
        Vec3 normal;                ///< the convention's n at the hit
        Vec3 to_eye;                ///< v = −(the ray's direction)
        uint32_t material = 0;      ///< index into Scene::materials
        uint32_t lights_begin = 0;  ///< its arriving lights: [lights_begin, next hit's lights_begin)
    };
    /// A light that reaches a hit (in front of it under the convention, its shadow ray clear).
    struct Arrived {
        Vec3 to_light;  ///< l
        double n_dot_l = 0;
        uint32_t light = 0;  ///< index into Scene::lights
    };
    /// The paths of one render tile: samples in the order the render traced them.
    struct Tile {
        std::vector<uint32_t> pixel;        ///< per pixel traced (per sample with 1 sample): its index y·W + x
        std::vector<uint32_t> hits_begin;   ///< per sample: its first hit in `hits`; one more at the end
        std::vector<uint8_t> ends_in_miss;  ///< per sample: 1 where the ray after its last hit missed
        std::vector<Hit> hits;              ///< one more at the end, for the last hit's lights
        std::vector<Arrived> lights;
    };

private:
    Scene m_scene;  ///< the recorded scene without its objects (they are not needed to compare)
    std::vector<Tile> m_tiles;
};

}  // namespace whitted
