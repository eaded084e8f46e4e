// SPDX-License-Identifier: MIT
#pragma once

#include "core/ray.h"
#include "scene/scene.h"

namespace whitted {

/// The primary ray through screen point (x0, y0), where x0 ∈ [−0.5, 0.5] runs left to right and
/// y0 ∈ [−0.5, 0.5] bottom to top; pixel (i, j)'s centre is x0 = (i + 0.5)/W − 0.5,
/// y0 = 0.5 − (j + 0.5)/H (scene-format v1, the same as POV-Ray 3.7). It meets surfaces for
/// t_min < t < t_max (RaySpans::camera_t_min, RaySpans::t_max).
Ray camera_ray(const Camera& camera, double x0, double y0, double t_min = ray_limits::surface_t_min,
               double t_max = ray_limits::max_distance);
/// The same for the scene's camera, with the range its render.intersection gives (RaySpans).
Ray camera_ray(const Scene& scene, double x0, double y0);

/// Screen coordinates of sample (a, b) of an n×n grid inside pixel (i, j) of a W×H image.
inline void sample_position(int i, int j, int a, int b, int n, int width, int height, double& x0, double& y0) {
    x0 = (i + (a + 0.5) / n) / width - 0.5;
    y0 = 0.5 - (j + (b + 0.5) / n) / height;
}

}  // namespace whitted
