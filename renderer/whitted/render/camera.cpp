// SPDX-License-Identifier: MIT
#include "whitted/render/camera.h"

namespace whitted {

Ray camera_ray(const Camera& camera, double x0, double y0) {
    const Vec3 offset = camera.right * x0 + camera.up * y0;
    if (camera.type == CameraType::orthographic)
        return {camera.eye + offset, camera.forward, ray_limits::surface_t_min, ray_limits::max_distance};
    return {camera.eye, normalize(camera.forward + offset), ray_limits::surface_t_min, ray_limits::max_distance};
}

}  // namespace whitted
