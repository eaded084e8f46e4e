// SPDX-License-Identifier: MIT
#pragma once

#include "core/ray.h"
#include "render/accelerator_device.h"
#include "scene/scene.h"

#include <memory>
#include <string>
#include <vector>

namespace whitted {

/// What a ray hit, in double precision.
struct SurfaceHit {
    double t = 0;
    Vec3 point;
    Vec3 normal;  ///< unit shading normal (interpolated for smooth meshes), not yet turned to the ray
    uint32_t material = 0;
    /// Unit geometric normal: the triangle's face normal ((v1 − v0) × (v2 − v0)), or the
    /// analytic normal of a sphere, box or plane (the same as `normal` there); not turned.
    /// Which side is lit is still decided with `normal`, as POV-Ray decides it (docs/validation.md,
    /// "Which side is lit").
    Vec3 geometric_normal;
    uint32_t object = 0;  ///< Scene::objects index + 1 (SceneObject): the objectId layer
};

/// What a query fills in a SurfaceHit: all of it, or all but the two normals (left as they
/// were), for a shadow walk, which needs only where it met what. The hit itself is the same
/// either way.
enum class HitParts { all, without_normals };

/// Whether an Accelerator makes a BVH (and an Embree device) for a scene of a few spheres,
/// boxes and cones and nothing else but planes, or has each ray test them all, which answers
/// every query the same and saves the device and the build.
enum class BvhChoice { when_worthwhile, always };

/// Ray queries over a Scene. Embree's BVH finds the candidates (triangles natively, spheres and
/// boxes as user geometry intersected in double); infinite planes are tested directly. The hit
/// that wins is recomputed in double from the double ray, so shading sees POV-Ray's precision.
class Accelerator {
public:
    /// `threads`: how many threads Embree may use to build (0 = all cores); pass the render's.
    /// Embree's instruction set comes from $WHITTED_EMBREE_ISA (embree_isa_from_environment).
    explicit Accelerator(const Scene& scene, int threads = 0);
    /// `isa`: one of embree_isa_names(), or "" for the widest the CPU has. Throws
    /// std::invalid_argument when the CPU cannot run it.
    Accelerator(const Scene& scene, int threads, const std::string& isa, BvhChoice bvh = BvhChoice::when_worthwhile);
    ~Accelerator();
    Accelerator(const Accelerator&) = delete;
    Accelerator& operator=(const Accelerator&) = delete;

    /// Whether the scene has a BVH: false where each ray tests its few shapes (BvhChoice).
    bool has_bvh() const;
    /// Bytes Embree holds now (the BVH), and the most it held while building.
    size_t embree_bytes() const;
    size_t peak_embree_bytes() const;

    /// Nearest hit with ray.t_min < t < ray.t_max.
    bool intersect(const Ray& ray, SurfaceHit& hit, HitParts parts = HitParts::all) const;
    /// Whether anything lies strictly between ray.t_min and ray.t_max (shadow rays).
    bool occluded(const Ray& ray) const;

    /// Up to packet_size rays at once, those with active[i]: Embree traces neighbouring (coherent)
    /// rays together much faster than one by one. Each answer is exactly what intersect() or
    /// occluded() gives for that ray alone, up to Embree's float choice between two triangles
    /// meeting at an edge. The rays go to Embree in groups of lane_width(); a lane that is not
    /// active holds an empty ray, never stale memory, since only Embree's native packet code
    /// honours its `valid` mask.
    static constexpr int packet_size = 16;
    /// Rays per Embree call: the widest packet Embree traverses natively with the instruction
    /// set in use (16 with AVX-512, 8 with AVX/AVX2, 4 with SSE), 1 if it has no packets.
    int lane_width() const;
    /// The instruction set asked for ("" = Embree's choice), as given to the constructor.
    const std::string& isa() const;
    void intersect_packet(const Ray* rays, const bool* active, int count, SurfaceHit* hits, bool* found,
                          HitParts parts = HitParts::all) const;
    void occluded_packet(const Ray* rays, const bool* active, int count, bool* blocked) const;

private:
    struct Impl;
    std::unique_ptr<Impl> m_impl;
};

}  // namespace whitted
