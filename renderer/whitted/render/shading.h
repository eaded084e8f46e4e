// SPDX-License-Identifier: MIT
#pragma once

#include "whitted/core/ray.h"
#include "whitted/render/accelerator.h"
#include "whitted/scene/scene.h"

#include <cstdint>

namespace whitted {

/// Rays cast while computing a pixel, by kind (for the summary line and the benchmarks).
struct RayCounts {
    uint64_t camera = 0;
    uint64_t shadow = 0;
    uint64_t reflected = 0;
    uint64_t total() const { return camera + shadow + reflected; }
    RayCounts& operator+=(const RayCounts& o) {
        camera += o.camera, shadow += o.shadow, reflected += o.reflected;
        return *this;
    }
};

/// The lecture's shading model, evaluated recursively (Whitted-style):
///
///   L = ka·Ia + Σ_i [ kd·I_i·max(0, n·l_i) + ks·I_i·max(0, n·h_i)^p ] + km·L(r)
///
/// with the conventions of scene-format v1 (and POV-Ray 3.7): two-sided normals, a light
/// counts only where n·l_i > 1e-10 and its shadow ray is clear, and then adds both its diffuse
/// and its specular term; r = 2(n·v)n − v is traced while the path has surface hits left.
class LectureShading {
public:
    LectureShading(const Scene& scene, const Accelerator& accelerator) : m_scene(scene), m_accelerator(accelerator) {}

    /// Radiance along `ray`, which is the `hits_so_far`-th segment of its path (0 = camera ray).
    Color trace(const Ray& ray, int hits_so_far, RayCounts& counts) const;

    /// The colour of one hit: ambient + every unshadowed light + mirror.
    Color shade(const Ray& ray, const SurfaceHit& hit, int hits_so_far, RayCounts& counts) const;

    /// The specular term's angular factor for one light: max(0, n·h)^p (Blinn-Phong) or
    /// max(0, r_v·l)^p (Phong). Unit vectors in; `to_eye` is v.
    static double specular_lobe(const Material& material, const Vec3& normal, const Vec3& to_eye, const Vec3& to_light);

private:
    bool shadow_ray_blocked(const Vec3& point, const Vec3& to_light, double light_distance, RayCounts& counts) const;

    const Scene& m_scene;
    const Accelerator& m_accelerator;
};

}  // namespace whitted
