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

/// One light's terms at one surface hit, as LectureShading::direct_lighting computed them.
struct LightTerms {
    Vec3 to_light;               ///< l (unit)
    double n_dot_l = 0;          ///< with the ray-facing n
    bool facing = false;         ///< n·l > cosine_epsilon: the light is in front of the surface
    Ray shadow_ray;              ///< from x toward the light; set where `facing`
    bool shadow_tested = false;  ///< the shadow ray's range was not empty (else the light is on the surface)
    bool blocked = false;        ///< something lies on the shadow ray
    Color diffuse, specular;     ///< kd·I·(n·l) and ks·I·lobe; zero unless facing and not blocked
};

/// Watches LectureShading evaluate the equation, lane by lane and path segment by segment
/// (`level` 0 is the camera ray): the render layers (docs/layers.md) and `whitted explain` are
/// built from what it is told, so they see exactly the numbers that made the pixel. A render
/// without layers traces with no observer at all, through the same code.
class PathObserver {
public:
    virtual ~PathObserver() = default;
    /// The segment missed everything: `seen` = weight·background was added to the radiance.
    virtual void miss(int lane, int level, const Ray& ray, const Color& weight, const Color& seen) = 0;
    /// The segment hit; `normal` is the shading normal turned toward the ray.
    virtual void hit(int lane, int level, const Ray& ray, const SurfaceHit& hit, const Vec3& normal) = 0;
    /// ka·Ia at the hit.
    virtual void ambient(int lane, int level, const Color& ambient) = 0;
    /// Light number `light` (0-based, file order) at the hit.
    virtual void light(int lane, int level, size_t light, const LightTerms& terms) = 0;
    /// local = ka·Ia + Σ(diffuse + specular) at the hit; `added` = weight·local went into the radiance.
    virtual void local(int lane, int level, const Color& weight, const Color& local, const Color& added) = 0;
    /// The mirror ray r leaves the hit; `weight` is the path's new weight (times km).
    virtual void mirror(int lane, int level, const Ray& mirror_ray, const Color& weight) = 0;
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
    /// The same, bit for bit, telling `observer` every term as it is computed.
    void trace_packet(const Ray* rays, int count, int hits_so_far, Color* radiance, RayCounts& counts,
                      PathObserver& observer) const;

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
    /// trace_packet and direct_lighting, with `Observer` either PathObserver or NoObserver, whose
    /// calls compile to nothing: a render without layers pays nothing for them.
    template <class Observer>
    void trace_packet_with(const Ray* rays, int count, int hits_so_far, Color* radiance, RayCounts& counts,
                           Observer& observer) const;
    template <class Observer>
    void direct_lighting_with(const SurfaceHit* hits, const Ray* rays, const bool* active, int count, Color* local,
                              Vec3* normal, RayCounts& counts, int level, Observer& observer) const;

    const Scene& m_scene;
    const Accelerator& m_accelerator;
};

}  // namespace whitted
