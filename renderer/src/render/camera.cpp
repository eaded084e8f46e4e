// SPDX-License-Identifier: MIT
#include "render/camera.h"

#include "render/ray_spans.h"

namespace whitted {

Ray camera_ray(const Camera& camera, double x0, double y0, double t_min, double t_max) {
    const Vec3 offset = camera.right * x0 + camera.up * y0;
    if (camera.type == CameraType::orthographic) return {camera.eye + offset, camera.forward, t_min, t_max};
    return {camera.eye, normalize(camera.forward + offset), t_min, t_max};
}

Ray camera_ray(const Scene& scene, double x0, double y0) {
    const RaySpans spans(scene);
    return camera_ray(scene.camera, x0, y0, spans.camera_t_min(), spans.t_max());
}

}  // namespace whitted
