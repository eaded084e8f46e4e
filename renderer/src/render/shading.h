// SPDX-License-Identifier: MIT
#pragma once

#include "core/ray.h"
#include "render/accelerator.h"
#include "render/ray_spans.h"
#include "scene/scene.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace whitted {

/// Rays cast while computing a pixel, by kind (for the summary line and the benchmarks).
struct RayCounts {
    uint64_t camera = 0;
    uint64_t shadow = 0;
    uint64_t reflected = 0;  ///< secondary rays: mirror rays and refracted rays
    uint64_t total() const { return camera + shadow + reflected; }
    RayCounts& operator+=(const RayCounts& o) {
        camera += o.camera, shadow += o.shadow, reflected += o.reflected;
        return *this;
    }
};

/// One light's terms at one surface hit, as LectureShading computed them (for the observers).
struct LightTerms {
    Vec3 to_light;               ///< l (unit)
    double n_dot_l = 0;          ///< with the ray-facing n
    bool facing = false;         ///< n·l > cosine_epsilon: the light is in front of the surface
    Ray shadow_ray;              ///< from x toward the light; set where `facing`
    bool shadow_tested = false;  ///< the shadow ray's range was not empty (else the light is on the surface)
    bool blocked = false;        ///< something opaque lies on the shadow ray
    /// The product of the kt of the transmitting surfaces the shadow ray crosses (1: none);
    /// the light reaches the point as I·filter.
    Color filter{1.0};
    Color diffuse, specular;  ///< kd·I·filter·(n·l) and ks·I·filter·lobe; zero unless facing and not blocked
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
    /// The mirror ray r leaves the hit; `weight` is the path's new weight (times km, or times 1
    /// where the refracted ray is totally reflected).
    virtual void mirror(int lane, int level, const Ray& mirror_ray, const Color& weight) = 0;
    /// The refracted ray t leaves the hit, after `mirror` (if any); `weight` is its path's weight
    /// (times kt). Its path is traced before the mirror ray's: its segments come first.
    virtual void transmitted(int lane, int level, const Ray& refracted_ray, const Color& weight) = 0;
};

/// The transmitting objects a ray is inside, innermost last. Every refracted ray starts from a
/// copy of its parent's, so the first few are held in place: a path through glass is seldom
/// inside more than one or two objects, and a heap block per refracted ray was a tenth of
/// gears' render (malloc, free and the copies). Deeper nesting (up to max_depth) goes on the heap.
class Interiors {
public:
    struct Entry {
        uint32_t object;  ///< the object's number (SurfaceHit::object)
        double ior;       ///< its index of refraction
    };
    bool empty() const { return m_count == 0; }
    const Entry* begin() const { return data(); }
    const Entry* end() const { return data() + m_count; }
    const Entry& back() const { return data()[m_count - 1]; }
    void push_back(const Entry& entry) {
        if (m_count < in_place) {
            m_in_place[m_count++] = entry;
            return;
        }
        if (m_count == in_place) m_beyond.assign(m_in_place, m_in_place + in_place);
        m_beyond.push_back(entry);
        ++m_count;
    }
    void pop_back() { erase(end() - 1); }
    /// Removes the entry at `at` (one of this list's), keeping the others' order.
    void erase(const Entry* at) {
        const auto index = size_t(at - begin());
        if (m_count > in_place) {
            m_beyond.erase(m_beyond.begin() + std::ptrdiff_t(index));
            if (--m_count == in_place) {
                std::copy(m_beyond.begin(), m_beyond.end(), m_in_place);
                m_beyond.clear();
            }
            return;
        }
        std::copy(m_in_place + index + 1, m_in_place + m_count, m_in_place + index);
        --m_count;
    }

private:
    static constexpr size_t in_place = 4;
    const Entry* data() const { return m_count > in_place ? m_beyond.data() : m_in_place; }
    size_t m_count = 0;
    Entry m_in_place[in_place] = {};  ///< the entries while there are at most in_place
    std::vector<Entry> m_beyond;      ///< all of them once there are more
};

/// One light as a hit point x sees it, which is all the local terms need of it: l, n·l (as
/// the convention counts it), and I_i as it arrives at x (times the kt of the transmitting
/// surfaces its shadow ray crosses). `arrives` is false where the convention does not count
/// the light (behind the surface) or an opaque surface blocks its shadow ray.
struct ArrivingLight {
    Vec3 to_light;  ///< l (unit)
    double n_dot_l = 0;
    Color intensity;
    bool arrives = false;
};

/// One light's two local terms at a hit.
struct LightShare {
    Color diffuse;   ///< kd·I·max(0, n·l)
    Color specular;  ///< ks·I·max(0, n·h)^p (or the Phong lobe)
};

/// How the light leaving a hit divides between its local terms and its mirror ray L(r).
struct Reflectance {
    double local = 1.0;  ///< the factor on the local terms
    Color mirror;        ///< the weight of L(r)
};

/// The lecture's shading model, evaluated Whitted-style:
///
///   L = ka·Ia + Σ_i [ kd·I_i·max(0, n·l_i) + ks·I_i·max(0, n·h_i)^p ] + km·L(r) + kt·L(t)
///
/// The equation is written once, per hit and scalar: local_terms (with light_terms and
/// ambient_term), mirror_direction for r = 2(n·v)n − v, refract for t, reflectance for km or a
/// glaze. Around them, in shading.cpp, are the named policies and the driver:
///
/// * the convention (scene-format v1 and POV-Ray 3.7, or the course's): which normal a hit
///   has, which lights count there (v1: two-sided normals, a light counts only where
///   n·l_i > 1e-10 and then adds both its terms) and the span of its shadow ray;
/// * the driver, which unrolls the recursion km·L(r) into a loop over path segments with a
///   running weight (the product of the km met so far), so that up to a packet of neighbouring
///   rays is traced together at every level: camera rays, then their shadow rays light by
///   light, then their mirror rays. r is traced while the path has surface hits left. The
///   refracted ray t (Whitted 1980) bends by Snell's law; where it cannot leave (total internal
///   reflection) the light comes back along r with weight 1 in place of both km·L(r) and
///   kt·L(t); the refracted rays leaving one level's hits start paths of their own, traced
///   together as a packet before the mirror rays go on, so that each pixel's terms are still
///   summed in the order of the depth-first recursion. A shadow ray crossing transmitting
///   surfaces brings I times the product of their kt.
class LectureShading {
public:
    LectureShading(const Scene& scene, const Accelerator& accelerator)
        : m_scene(scene), m_accelerator(accelerator), m_spans(scene) {
        for (const Material& material : scene.materials) m_transmits |= !is_zero(material.kt);
    }

    /// Radiance along `ray`, which is the `hits_so_far`-th segment of its path (0 = camera ray).
    Color trace(const Ray& ray, int hits_so_far, RayCounts& counts) const;

    /// Radiance along `count` (≤ Accelerator::packet_size) rays that start their paths here,
    /// each as trace(rays[i], hits_so_far) would give it.
    void trace_packet(const Ray* rays, int count, int hits_so_far, Color* radiance, RayCounts& counts) const;
    /// The same, bit for bit, telling `observer` every term as it is computed.
    void trace_packet(const Ray* rays, int count, int hits_so_far, Color* radiance, RayCounts& counts,
                      PathObserver& observer) const;

    /// The local terms at one hit, with n the hit's normal and v the unit vector to the eye:
    /// ka·Ia + Σ_i [ kd·I_i·max(0, n·l_i) + ks·I_i·max(0, n·h_i)^p ] over the `count` lights.
    static Color local_terms(const Material& material, const Color& ambient_light, const Vec3& normal,
                             const Vec3& to_eye, const ArrivingLight* lights, size_t count);
    /// ka·Ia.
    static Color ambient_term(const Material& material, const Color& ambient_light);
    /// One light's diffuse and specular terms, where it arrives.
    static LightShare light_terms(const Material& material, const Vec3& normal, const Vec3& to_eye,
                                  const ArrivingLight& light);

    /// The specular term's angular factor for one light: max(0, n·h)^p (Blinn-Phong) or
    /// max(0, r_v·l)^p (Phong). Unit vectors in; `to_eye` is v.
    static double specular_lobe(const Material& material, const Vec3& normal, const Vec3& to_eye, const Vec3& to_light);

    /// The mirror ray's direction r = 2(n·v)n − v.
    static Vec3 mirror_direction(const Vec3& normal, const Vec3& to_eye);

    /// The lecture's km·L(r) beside the whole local terms; for a glazed material
    /// (fresnel_r0 ≥ 0) instead (1 − F)·local + F·L(r), F = schlick_fresnel(r0, n·v).
    static Reflectance reflectance(const Material& material, const Vec3& normal, const Vec3& to_eye);

    /// Schlick's Fresnel factor F = R0 + (1 − R0)(1 − n·v)^5, and 0 where n·v < 0.
    static double schlick_fresnel(double r0, double n_dot_v);

    /// n turned toward where the ray came from: surfaces are two-sided.
    static Vec3 facing_normal(const SurfaceHit& hit, const Ray& ray) {
        return dot(hit.normal, ray.direction) > 0 ? -hit.normal : hit.normal;
    }

private:
    /// The driver, with `Convention` PovRayConvention or CourseConvention and `Observer` either
    /// PathObserver or NoObserver, whose calls compile to nothing: a render without layers pays
    /// nothing for them. The paths of `count` rays, each starting with weight first_weights[i]
    /// (1 if null) inside first_interiors[i] (none if null); their radiance is added to
    /// radiance[i], term by term in the order the observer is told them.
    template <class Convention, class Observer>
    void trace_paths(const Ray* rays, const Color* first_weights, const Interiors* first_interiors, int count,
                     int hits_so_far, Color* radiance, RayCounts& counts, Observer& observer) const;
    /// Every light as each active hit of a packet sees it: lights[i·L + k] is light k at hit i
    /// (L lights). The shadow rays go light by light, as a packet.
    template <class Convention, class Observer>
    void see_lights(const Ray* rays, const SurfaceHit* hits, const Vec3* normal, const bool* active, int count,
                    ArrivingLight* lights, RayCounts& counts, int level, Observer& observer) const;
    /// The refracted ray at a hit of a material with kt, as POV-Ray 3.7 bends it (docs/pov-model.md
    /// §5): η from the objects the ray is inside, Heckbert's formula; false for total internal
    /// reflection. `interiors` becomes the refracted ray's.
    bool refract(const Ray& ray, const SurfaceHit& hit, const Vec3& normal, Interiors& interiors,
                 Vec3& direction) const;
    /// For each of `count` shadow rays with tested[i]: the product of the kt of the surfaces
    /// along it, filter[i] (0 where an opaque one blocks it), and blocked[i] where that is 0.
    /// The rays' t_min is moved past each surface met.
    void shadow_filters(Ray* shadow_rays, const bool* tested, int count, Color* filter, bool* blocked) const;

    const Scene& m_scene;
    const Accelerator& m_accelerator;
    RaySpans m_spans;          ///< where rays start and end (render.intersection)
    bool m_transmits = false;  ///< some material has kt: shadow rays walk, refracted rays branch
};

}  // namespace whitted
