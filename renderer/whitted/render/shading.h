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

/// The lecture's shading model, evaluated Whitted-style:
///
///   L = ka·Ia + Σ_i [ kd·I_i·max(0, n·l_i) + ks·I_i·max(0, n·h_i)^p ] + km·L(r)
///
/// with the conventions of scene-format v1 (and POV-Ray 3.7): two-sided normals, a light
/// counts only where n·l_i > 1e-10 and its shadow ray is clear, and then adds both its diffuse
/// and its specular term; r = 2(n·v)n − v is traced while the path has surface hits left.
///
/// The recursion km·L(r) is unrolled into a loop over path segments with a running weight
/// (the product of the km met so far), so that up to a packet of neighbouring rays is traced
/// together at every level: camera rays, then their shadow rays light by light, then their
/// mirror rays.
class LectureShading {
public:
    LectureShading(const Scene& scene, const Accelerator& accelerator) : m_scene(scene), m_accelerator(accelerator) {}

    /// Radiance along `ray`, which is the `hits_so_far`-th segment of its path (0 = camera ray).
    Color trace(const Ray& ray, int hits_so_far, RayCounts& counts) const;

    /// Radiance along `count` (≤ Accelerator::packet_size) rays that start their paths here,
    /// each as trace(rays[i], hits_so_far) would give it.
    void trace_packet(const Ray* rays, int count, int hits_so_far, Color* radiance, RayCounts& counts) const;

    /// ka·Ia plus the unshadowed lights' diffuse and specular terms at one hit, for up to a
    /// packet of hits (`active` marks the lanes in use). `normal` receives each hit's
    /// ray-facing normal, which the mirror ray needs too.
    void direct_lighting(const SurfaceHit* hits, const Ray* rays, const bool* active, int count, Color* local,
                         Vec3* normal, RayCounts& counts) const;

    /// The specular term's angular factor for one light: max(0, n·h)^p (Blinn-Phong) or
    /// max(0, r_v·l)^p (Phong). Unit vectors in; `to_eye` is v.
    static double specular_lobe(const Material& material, const Vec3& normal, const Vec3& to_eye, const Vec3& to_light);

    /// Schlick's Fresnel factor F = R0 + (1 − R0)(1 − n·v)^5, and 0 where n·v < 0.
    static double schlick_fresnel(double r0, double n_dot_v);

    /// n turned toward where the ray came from: surfaces are two-sided.
    static Vec3 facing_normal(const SurfaceHit& hit, const Ray& ray) {
        return dot(hit.normal, ray.direction) > 0 ? -hit.normal : hit.normal;
    }

private:
    const Scene& m_scene;
    const Accelerator& m_accelerator;
};

}  // namespace whitted
