// SPDX-License-Identifier: MIT
#include "whitted/render/shading.h"

#include <cmath>

namespace whitted {

Color LectureShading::trace(const Ray& ray, int hits_so_far, RayCounts& counts) const {
    // Past the last allowed surface hit a ray contributes black, not the background
    // (POV-Ray's max_trace_level semantics, scene-format v1 `render.max_depth`).
    if (hits_so_far >= m_scene.max_depth) return Color(0.0);
    SurfaceHit hit;
    if (!m_accelerator.intersect(ray, hit)) return m_scene.background;
    return shade(ray, hit, hits_so_far, counts);
}

double LectureShading::specular_lobe(const Material& material, const Vec3& normal, const Vec3& to_eye,
                                     const Vec3& to_light) {
    if (material.highlight == Highlight::blinn) {
        const Vec3 half_vector = to_eye + to_light;  // h = normalize(l + v)
        const double half_length = length(half_vector);
        if (!(half_length > 0)) return 0.0;
        const double n_dot_h = dot(half_vector, normal) / half_length;
        return n_dot_h > 0 ? std::pow(n_dot_h, material.p) : 0.0;
    }
    // Classic Phong: the view ray mirrored about n, r_v = 2(n·v)n − v, against l. POV-Ray drops
    // the term for p ≥ 60 when r_v·l ≤ 0.0008; there it is below 0.0008^60 ≈ 1e-186 anyway,
    // so computing it exactly gives the same pixels (docs/validation.md).
    const Vec3 mirrored_view = normal * (2.0 * dot(normal, to_eye)) - to_eye;
    const double r_dot_l = dot(mirrored_view, to_light);
    return r_dot_l > 0 ? std::pow(r_dot_l, material.p) : 0.0;
}

bool LectureShading::shadow_ray_blocked(const Vec3& point, const Vec3& to_light, double light_distance,
                                        RayCounts& counts) const {
    ++counts.shadow;
    const Ray shadow_ray{point, to_light, ray_limits::shadow_epsilon, light_distance - ray_limits::shadow_epsilon};
    if (!(shadow_ray.t_max > shadow_ray.t_min)) return false;  // the light is (almost) on the surface
    return m_accelerator.occluded(shadow_ray);
}

Color LectureShading::shade(const Ray& ray, const SurfaceHit& hit, int hits_so_far, RayCounts& counts) const {
    const Material& material = m_scene.materials[hit.material];
    // Two-sided surfaces: turn n toward where the ray came from.
    const Vec3 normal = dot(hit.normal, ray.direction) > 0 ? -hit.normal : hit.normal;
    const Vec3 to_eye = -ray.direction;  // v

    Color radiance = material.ka * m_scene.ambient;  // ambient: ka·Ia
    for (const Light& light : m_scene.lights) {
        Vec3 to_light;  // l
        double light_distance;
        if (light.type == LightType::point) {
            const Vec3 offset = light.position - hit.point;
            light_distance = length(offset);
            if (!(light_distance > 0)) continue;
            to_light = offset / light_distance;
        } else {
            to_light = light.toward_light;
            light_distance = ray_limits::directional_light_distance - dot(hit.point, to_light);
        }
        const double n_dot_l = dot(normal, to_light);
        // The gate on both terms: a light behind the surface, or blocked, adds nothing.
        if (!(n_dot_l > ray_limits::cosine_epsilon)) continue;
        if (shadow_ray_blocked(hit.point, to_light, light_distance, counts)) continue;
        const Color diffuse = material.kd * light.intensity * n_dot_l;
        const Color specular = material.ks * light.intensity * specular_lobe(material, normal, to_eye, to_light);
        radiance += diffuse + specular;
    }

    if (!is_zero(material.km) && hits_so_far + 1 < m_scene.max_depth) {
        // Mirror: r = 2(n·v)n − v, from the hit point itself (no offset; t_min does the work).
        const Vec3 mirror_direction = normalize(normal * (2.0 * dot(normal, to_eye)) - to_eye);
        const Ray reflected{hit.point, mirror_direction, ray_limits::surface_t_min, ray_limits::max_distance};
        ++counts.reflected;
        radiance += material.km * trace(reflected, hits_so_far + 1, counts);
    }
    return radiance;
}

}  // namespace whitted
