// SPDX-License-Identifier: MIT
#pragma once

#include "core/vec3.h"

namespace whitted {

/// A ray p(t) = origin + t·direction, valid for t in (t_min, t_max).
struct Ray {
    Vec3 origin;
    Vec3 direction;  ///< unit length for camera, shadow and reflected rays
    double t_min = 0;
    double t_max = 0;

    Vec3 at(double t) const { return origin + direction * t; }
};

/// Self-intersection and range rules shared with POV-Ray 3.7 (docs/pov-model.md §3), so that both
/// renderers decide the same hits: no origin offset, only minimum distances.
namespace ray_limits {
/// Camera and reflected rays ignore hits closer than this (POV-Ray's MIN_ISECT_DEPTH).
inline constexpr double surface_t_min = 1e-4;
/// Shadow rays count a blocker only for shadow_epsilon < t < distance − shadow_epsilon.
inline constexpr double shadow_epsilon = 1e-3;
/// Hits further away than this are ignored (POV-Ray's MAX_DISTANCE).
inline constexpr double max_distance = 1e7;
/// A directional light behaves as POV-Ray's `parallel` light placed this far from the origin
/// against its direction: a shadow ray from x is clear when nothing lies within
/// (shadow_epsilon, directional_light_distance − x·l − shadow_epsilon). The converter puts the
/// POV-Ray light exactly there, so both renderers decide the same shadows.
inline constexpr double directional_light_distance = 1e6;
/// The n·l gate: a light counts only where n·l exceeds this (POV-Ray's EPSILON).
inline constexpr double cosine_epsilon = 1e-10;
/// `render.convention: course` (the Cornell CS4620 ray tracer): a shadow ray goes along the
/// unnormalised vector to the light, d = light − x, and counts blockers for t in (1e-6, 1) of
/// it, i.e. for course_shadow_fraction·|d| < t < |d| along the unit direction.
inline constexpr double course_shadow_fraction = 1e-6;
}  // namespace ray_limits

}  // namespace whitted
