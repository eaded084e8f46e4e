// SPDX-License-Identifier: MIT
#pragma once

#include "whitted/core/ray.h"
#include "whitted/scene/scene.h"

#include <memory>

namespace whitted {

/// What a ray hit, in double precision.
struct SurfaceHit {
    double t = 0;
    Vec3 point;
    Vec3 normal;  ///< unit shading normal (interpolated for smooth meshes), not yet turned to the ray
    uint32_t material = 0;
};

/// Ray queries over a Scene. Embree's BVH finds the candidates (triangles natively, spheres and
/// boxes as user geometry intersected in double); infinite planes are tested directly. The hit
/// that wins is recomputed in double from the double ray, so shading sees POV-Ray's precision.
class Accelerator {
public:
    /// `threads`: how many threads Embree may use to build (0 = all cores); pass the render's.
    explicit Accelerator(const Scene& scene, int threads = 0);
    ~Accelerator();
    Accelerator(const Accelerator&) = delete;
    Accelerator& operator=(const Accelerator&) = delete;

    /// Bytes Embree holds now (the BVH), and the most it held while building.
    size_t embree_bytes() const;
    size_t peak_embree_bytes() const;

    /// Nearest hit with ray.t_min < t < ray.t_max.
    bool intersect(const Ray& ray, SurfaceHit& hit) const;
    /// Whether anything lies strictly between ray.t_min and ray.t_max (shadow rays).
    bool occluded(const Ray& ray) const;

    /// Up to packet_size rays at once, those with active[i]: Embree traces neighbouring (coherent)
    /// rays together much faster than one by one. Each answer is exactly what intersect() or
    /// occluded() gives for that ray alone, up to Embree's float choice between two triangles
    /// meeting at an edge.
    static constexpr int packet_size = 16;
    void intersect_packet(const Ray* rays, const bool* active, int count, SurfaceHit* hits, bool* found) const;
    void occluded_packet(const Ray* rays, const bool* active, int count, bool* blocked) const;

private:
    struct Impl;
    std::unique_ptr<Impl> m_impl;
};

}  // namespace whitted
