// SPDX-License-Identifier: MIT
#pragma once

#include "core/ray.h"
#include "scene/scene.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace whitted {

/// Where the rays of the lecture's model start and end (docs/scene-format.md §2.3,
/// `render.intersection`). A ray leaves a surface from the hit point itself, with no offset; a
/// minimum distance keeps it from meeting that surface again, and a shadow ray's window leaves
/// out what lies next to x (where a smooth normal turns a mesh toward a light its facets hide
/// it from) and next to the light.
///
/// `exact` (the default): those distances are fractions of |x − eye|, the hit's distance from the
/// camera, so that moving the whole scene changes none of them and scaling it scales them all
/// with it: the image does not depend on where the scene stands or on its unit. A camera ray
/// meets everything in front of the eye (t > 0), a directional light is infinitely far, and a
/// ray reaches 1e16 (far_t_max): a plane's horizon there is within 1e-4 of a pixel of the true
/// one for any scene Whitted accepts (shapes, eye and lights within 1e15 of the origin), while a
/// point a ray reaches stays inside the range of Embree's float rays (about 1.8e19).
///
/// `povray`: POV-Ray 3.7's absolute distances (ray_limits, docs/pov-model.md §3), which
/// `whitted check` selects so that both renderers decide the same hits.
class RaySpans {
public:
    /// The fractions of |x − eye|: at the distance of most scenes' surfaces from their camera
    /// (a few units) they come to POV-Ray's 1e-4 and 1e-3.
    static constexpr double leaving_fraction = 2e-5, shadow_fraction = 2e-4;
    static constexpr double far_t_max = 1e16;

    explicit RaySpans(const Scene& scene)
        : m_exact(scene.intersection == Intersection::exact), m_eye(scene.camera.eye) {}

    /// Camera rays meet surfaces for t > camera_t_min().
    double camera_t_min() const { return m_exact ? 0.0 : ray_limits::surface_t_min; }
    /// Camera, mirror and refracted rays meet surfaces for t < t_max().
    double t_max() const { return m_exact ? far_t_max : ray_limits::max_distance; }
    /// A mirror or refracted ray leaving x meets surfaces beyond this.
    double leaving(const Vec3& x) const {
        return m_exact ? std::max(leaving_fraction * length(x - m_eye), rounding(x)) : ray_limits::surface_t_min;
    }
    /// A shadow ray from x counts blockers from this distance on, and up to this distance short
    /// of the light; a transmitting blocker at x is passed by this much.
    double shadow(const Vec3& x) const {
        return m_exact ? std::max(shadow_fraction * length(x - m_eye), rounding(x)) : ray_limits::shadow_epsilon;
    }
    /// The distance from x to a directional light along toward_light.
    double directional_light_distance(const Vec3& x, const Vec3& toward_light) const {
        return m_exact ? std::numeric_limits<double>::infinity()
                       : ray_limits::directional_light_distance - dot(x, toward_light);
    }

private:
    /// Not less than 64 ulps of the coordinates x was computed from, which a point right at the
    /// eye could otherwise come below: a ray leaving x must not meet its own surface again
    /// through rounding. Far below the fractions for any point not at the eye.
    double rounding(const Vec3& x) const {
        const double largest = std::max({std::fabs(x.x), std::fabs(x.y), std::fabs(x.z), std::fabs(m_eye.x),
                                         std::fabs(m_eye.y), std::fabs(m_eye.z)});
        return 64 * std::numeric_limits<double>::epsilon() * largest;
    }

    bool m_exact;
    Vec3 m_eye;
};

}  // namespace whitted
