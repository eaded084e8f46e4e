// SPDX-License-Identifier: MIT
#include "whitted/render/shading.h"

#include "whitted/core/packet_array.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace whitted {

namespace {
constexpr int packet_size = Accelerator::packet_size;

/// x^p. Whole exponents up to 1024, the usual case (p = 10, 50, 200, ...), go by repeated
/// squaring: a few multiplications, within a few units in the last place of std::pow, against
/// std::pow's ~40 ns, which was an eighth of a render's time.
double power(double x, double p) {
    if (p >= 1 && p <= 1024 && p == std::floor(p)) {
        unsigned n = unsigned(p);
        double result = 1, square = x;
        while (n) {
            if (n & 1) result *= square;
            square *= square;
            n >>= 1;
        }
        return result;
    }
    return std::pow(x, p);
}
}  // namespace

Color LectureShading::trace(const Ray& ray, int hits_so_far, RayCounts& counts) const {
    Color radiance;
    trace_packet(&ray, 1, hits_so_far, &radiance, counts);
    return radiance;
}

double LectureShading::schlick_fresnel(double r0, double n_dot_v) {
    if (!(n_dot_v >= 0)) return 0.0;  // seen from behind (only with normals as given): no glaze
    const double c = 1.0 - n_dot_v;
    return r0 + (1.0 - r0) * (c * c * c * c * c);
}

double LectureShading::specular_lobe(const Material& material, const Vec3& normal, const Vec3& to_eye,
                                     const Vec3& to_light) {
    if (material.highlight == Highlight::blinn) {
        const Vec3 half_vector = to_eye + to_light;  // h = normalize(l + v)
        const double half_length = length(half_vector);
        if (!(half_length > 0)) return 0.0;
        const double n_dot_h = dot(half_vector, normal) / half_length;
        return n_dot_h > 0 ? power(n_dot_h, material.p) : 0.0;
    }
    // Classic Phong: the view ray mirrored about n, r_v = 2(n·v)n − v, against l. POV-Ray drops
    // the term for p ≥ 60 when r_v·l ≤ 0.0008; there it is below 0.0008^60 ≈ 1e-186 anyway,
    // so computing it exactly gives the same pixels (docs/validation.md).
    const Vec3 mirrored_view = normal * (2.0 * dot(normal, to_eye)) - to_eye;
    const double r_dot_l = dot(mirrored_view, to_light);
    return r_dot_l > 0 ? power(r_dot_l, material.p) : 0.0;
}

namespace {
/// The observer of a render without layers: every call is empty and inlined away.
struct NoObserver {
    static constexpr bool watching = false;
    void miss(int, int, const Ray&, const Color&, const Color&) {}
    void hit(int, int, const Ray&, const SurfaceHit&, const Vec3&) {}
    void ambient(int, int, const Color&) {}
    void light(int, int, size_t, const LightTerms&) {}
    void local(int, int, const Color&, const Color&, const Color&) {}
    void mirror(int, int, const Ray&, const Color&) {}
    void transmitted(int, int, const Ray&, const Color&) {}
    NoObserver for_lane(int) const { return {}; }
};
/// PathObserver behind the same interface, with `watching` for what only it needs computed.
/// A refracted ray's path is traced as a packet of one lane of its own: `lane`, when set, is
/// the lane of the packet that path belongs to.
struct Watching {
    static constexpr bool watching = true;
    PathObserver& to;
    int lane = -1;
    int at(int i) const { return lane >= 0 ? lane : i; }
    void miss(int i, int level, const Ray& r, const Color& w, const Color& seen) { to.miss(at(i), level, r, w, seen); }
    void hit(int i, int level, const Ray& r, const SurfaceHit& h, const Vec3& n) { to.hit(at(i), level, r, h, n); }
    void ambient(int i, int level, const Color& a) { to.ambient(at(i), level, a); }
    void light(int i, int level, size_t k, const LightTerms& t) { to.light(at(i), level, k, t); }
    void local(int i, int level, const Color& w, const Color& l, const Color& a) { to.local(at(i), level, w, l, a); }
    void mirror(int i, int level, const Ray& r, const Color& w) { to.mirror(at(i), level, r, w); }
    void transmitted(int i, int level, const Ray& r, const Color& w) { to.transmitted(at(i), level, r, w); }
    Watching for_lane(int i) const { return {to, at(i)}; }
};
}  // namespace

Color LectureShading::shadow_filter(Ray shadow_ray) const {
    // POV-Ray's walk: each surface met multiplies the light by its kt, and the search goes on
    // from the shadow window's width past it (RaySpans::shadow, at that surface); an opaque one
    // ends it.
    Color filter(1.0);
    SurfaceHit hit;
    while (shadow_ray.t_max > shadow_ray.t_min && m_accelerator.intersect(shadow_ray, hit)) {
        const Color& kt = m_scene.materials[hit.material].kt;
        if (is_zero(kt)) return Color(0.0);
        filter = filter * kt;
        shadow_ray.t_min = hit.t + m_spans.shadow(hit.point);
    }
    return filter;
}

bool LectureShading::refract(const Ray& ray, const SurfaceHit& hit, const Vec3& normal, Interiors& interiors,
                             Vec3& direction) const {
    // η = n_from / n_to from the objects the ray is inside, as POV-Ray 3.7 keeps them: entering
    // from outside, leaving the innermost object, leaving one of two overlapping objects (their
    // overlap counts as the later one's: η = 1), or entering an object inside another.
    const uint32_t object = hit.object;
    const double ior = m_scene.materials[hit.material].ior;
    double eta;
    const auto inside =
        std::find_if(interiors.begin(), interiors.end(), [object](const auto& entry) { return entry.first == object; });
    if (interiors.empty()) {
        eta = 1.0 / ior;
        interiors.emplace_back(object, ior);
    } else if (interiors.back().first == object) {
        const double leaving = interiors.back().second;
        interiors.pop_back();
        eta = leaving / (interiors.empty() ? 1.0 : interiors.back().second);
    } else if (inside != interiors.end()) {
        interiors.erase(inside);
        eta = 1.0;
    } else {
        eta = interiors.back().second / ior;
        interiors.emplace_back(object, ior);
    }
    // The same medium on both sides: the ray goes on unbent.
    if (std::fabs(eta - 1.0) < 1e-10) {
        direction = ray.direction;
        return true;
    }
    // Snell's law in Heckbert's form, with n the normal on the side the ray comes from and
    // c = −d·n > 0: t = η d + (η c − √(1 − η²(1 − c²))) n; no root is total internal reflection.
    double c = dot(ray.direction, normal);
    Vec3 toward = normal;
    if (c <= 0)
        c = -c;
    else
        toward = -normal;
    const double k = 1.0 + eta * eta * (c * c - 1.0);
    if (k < 0) return false;
    direction = normalize(ray.direction * eta + toward * (eta * c - std::sqrt(k)));
    return true;
}

void LectureShading::direct_lighting(const SurfaceHit* hits, const Ray* rays, const bool* active, int count,
                                     Color* local, Vec3* normal, RayCounts& counts) const {
    NoObserver none;
    direct_lighting_with(hits, rays, active, count, local, normal, counts, 0, none);
}

template <class Observer>
void LectureShading::direct_lighting_with(const SurfaceHit* hits, const Ray* rays, const bool* active, int count,
                                          Color* local, Vec3* normal, RayCounts& counts, int level,
                                          Observer& observer) const {
    const bool course = m_scene.convention == Convention::course;
    for (int i = 0; i < count; ++i) {
        if (!active[i]) continue;
        // The course's ray tracer uses every normal as it is, so a back face is shaded dark.
        normal[i] = course ? hits[i].normal : facing_normal(hits[i], rays[i]);
        local[i] = m_scene.materials[hits[i].material].ka * m_scene.ambient;  // ambient: ka·Ia
        observer.hit(i, level, rays[i], hits[i], normal[i]);
        observer.ambient(i, level, local[i]);
    }
    for (size_t light_index = 0; light_index < m_scene.lights.size(); ++light_index) {
        const Light& light = m_scene.lights[light_index];
        PacketArray<Ray, packet_size> shadow_rays;  // set where `query`
        bool query[packet_size] = {}, blocked[packet_size] = {}, lit[packet_size] = {};
        double n_dot_l[packet_size];
        for (int i = 0; i < count; ++i) {
            if (!active[i]) continue;
            if constexpr (Observer::watching) shadow_rays[i] = Ray{}, n_dot_l[i] = 0;  // told even where unlit
            const Vec3& point = hits[i].point;
            Vec3 to_light;  // l
            double light_distance;
            if (light.type == LightType::point) {
                const Vec3 offset = light.position - point;
                light_distance = length(offset);
                if (!(light_distance > 0)) continue;
                to_light = offset / light_distance;
            } else {
                to_light = light.toward_light;
                // The course's span is a fraction of the light's distance: it needs a finite one.
                light_distance = course ? ray_limits::directional_light_distance - dot(point, to_light)
                                        : m_spans.directional_light_distance(point, to_light);
            }
            n_dot_l[i] = dot(normal[i], to_light);
            if constexpr (Observer::watching) shadow_rays[i].direction = to_light;  // l, also where unlit
            if (course) {
                // No gate: diffuse max(0, n·l), the highlight as it comes; the shadow ray spans
                // (1e-6, 1) of the vector to the light.
                n_dot_l[i] = std::max(0.0, n_dot_l[i]);
                lit[i] = true;
                shadow_rays[i] = {point, to_light, ray_limits::course_shadow_fraction * light_distance, light_distance};
                query[i] = true;
                counts.shadow += 1;
                continue;
            }
            // The gate on both terms: a light behind the surface adds nothing.
            if (!(n_dot_l[i] > ray_limits::cosine_epsilon)) continue;
            lit[i] = true;
            // Shadow ray from x itself (no offset; the window does the work) to just short of the light.
            const double window = m_spans.shadow(point);
            shadow_rays[i] = {point, to_light, window, light_distance - window};
            query[i] = shadow_rays[i].t_max > shadow_rays[i].t_min;  // else the light is on the surface: unblocked
            counts.shadow += query[i];
        }
        // With transmitting surfaces in the scene a shadow ray is a walk (shadow_filter), else a
        // plain occlusion test.
        PacketArray<Color, packet_size> filter;
        if (m_transmits) {
            for (int i = 0; i < count; ++i) {
                filter[i] = Color(1.0);
                if (!active[i] || !query[i]) continue;
                filter[i] = shadow_filter(shadow_rays[i]);
                blocked[i] = is_zero(filter[i]);
            }
        } else {
            m_accelerator.occluded_packet(shadow_rays.data(), query, count, blocked);
        }
        for (int i = 0; i < count; ++i) {
            if constexpr (Observer::watching) {
                if (active[i] && !(lit[i] && !(query[i] && blocked[i]))) {  // the light adds nothing here
                    LightTerms terms;
                    terms.to_light = shadow_rays[i].direction;
                    terms.n_dot_l = n_dot_l[i];  // l and n·l stay 0 for a point light at x itself
                    terms.facing = lit[i];
                    if (lit[i]) terms.shadow_ray = shadow_rays[i];
                    terms.shadow_tested = query[i];
                    terms.blocked = query[i] && blocked[i];
                    if (m_transmits) terms.filter = filter[i];
                    observer.light(i, level, light_index, terms);
                }
            }
            if (!lit[i] || (query[i] && blocked[i])) continue;  // a blocked light adds neither term
            const Material& material = m_scene.materials[hits[i].material];
            const Vec3& to_light = shadow_rays[i].direction;
            const Color intensity = m_transmits ? light.intensity * filter[i] : light.intensity;
            const Color diffuse = material.kd * intensity * n_dot_l[i];
            // ks = 0 (most NFF fills): the lobe (often a pow) is not computed. It is finite and
            // never negative, so ks·I·0 is the same zero, sign included.
            const double lobe =
                is_zero(material.ks) ? 0.0 : specular_lobe(material, normal[i], -rays[i].direction, to_light);
            const Color specular = material.ks * intensity * lobe;
            local[i] += diffuse + specular;
            if constexpr (Observer::watching) {
                LightTerms terms;
                terms.to_light = to_light;
                terms.n_dot_l = n_dot_l[i];
                terms.facing = true;
                terms.shadow_ray = shadow_rays[i];
                terms.shadow_tested = query[i];
                if (m_transmits) terms.filter = filter[i];
                terms.diffuse = diffuse;
                terms.specular = specular;
                observer.light(i, level, light_index, terms);
            }
        }
    }
}

void LectureShading::trace_packet(const Ray* first_rays, int count, int hits_so_far, Color* radiance,
                                  RayCounts& counts) const {
    NoObserver none;
    for (int i = 0; i < count; ++i) radiance[i] = Color(0.0);
    trace_paths(first_rays, nullptr, nullptr, count, hits_so_far, radiance, counts, none);
}

void LectureShading::trace_packet(const Ray* first_rays, int count, int hits_so_far, Color* radiance, RayCounts& counts,
                                  PathObserver& observer) const {
    Watching watching{observer};
    for (int i = 0; i < count; ++i) radiance[i] = Color(0.0);
    trace_paths(first_rays, nullptr, nullptr, count, hits_so_far, radiance, counts, watching);
}

template <class Observer>
void LectureShading::trace_paths(const Ray* first_rays, const Color* first_weights, const Interiors* first_interiors,
                                 int count, int hits_so_far, Color* radiance, RayCounts& counts,
                                 Observer& observer) const {
    PacketArray<Ray, packet_size> rays;
    PacketArray<Color, packet_size> weight;  // product of the mirror coefficients along the path so far
    bool active[packet_size] = {};
    // The transmitting objects each path is inside (only ever filled where a material has kt).
    std::array<Interiors, packet_size> interiors;
    for (int i = 0; i < count; ++i) {
        rays[i] = first_rays[i];
        weight[i] = first_weights ? first_weights[i] : Color(1.0);
        if (first_interiors) interiors[i] = first_interiors[i];
        active[i] = true;
    }
    // A path segment past the last allowed surface hit contributes black, not the background
    // (POV-Ray's max_trace_level semantics, scene-format v1 `render.max_depth`).
    for (int level = hits_so_far; level < m_scene.max_depth; ++level) {
        PacketArray<SurfaceHit, packet_size> hits;  // set where `found`
        bool found[packet_size] = {};
        m_accelerator.intersect_packet(rays.data(), active, count, hits.data(), found);
        bool any_hit = false;
        for (int i = 0; i < count; ++i) {
            if (active[i] && !found[i]) {
                const Color seen = weight[i] * m_scene.background;  // a miss sees the background
                radiance[i] += seen;
                observer.miss(i, level, rays[i], weight[i], seen);
                active[i] = false;
            }
            any_hit |= active[i];
        }
        if (!any_hit) break;

        PacketArray<Color, packet_size> local;  // set where `active`
        PacketArray<Vec3, packet_size> normal;
        direct_lighting_with(hits.data(), rays.data(), active, count, local.data(), normal.data(), counts, level,
                             observer);
        for (int i = 0; i < count; ++i) {
            if (!active[i]) continue;
            const Material& material = m_scene.materials[hits[i].material];
            const Vec3 to_eye = -rays[i].direction;
            Color mirror_weight = material.km;
            Color added;
            if (material.fresnel_r0 >= 0) {
                // Glazed: (1 − F)·(the other terms) + F·L(r), F from Schlick's approximation.
                const double fresnel = schlick_fresnel(material.fresnel_r0, dot(normal[i], to_eye));
                added = weight[i] * local[i] * (1.0 - fresnel);
                mirror_weight = Color(fresnel);
            } else {
                added = weight[i] * local[i];
            }
            radiance[i] += added;
            observer.local(i, level, weight[i], local[i], added);
            // kt·L(t): the refracted ray, or at total internal reflection the light back along r
            // with weight 1 in place of km (as POV-Ray 3.7 adds it, docs/pov-model.md §5).
            bool refracted = false;
            Ray refracted_ray;
            Interiors refracted_interiors;
            if (m_transmits && !is_zero(material.kt) && level + 1 < m_scene.max_depth) {
                refracted_interiors = interiors[i];
                Vec3 direction;
                if (refract(rays[i], hits[i], normal[i], refracted_interiors, direction)) {
                    refracted = true;
                    refracted_ray = {hits[i].point, direction, m_spans.leaving(hits[i].point), m_spans.t_max()};
                } else {
                    mirror_weight = Color(1.0);
                }
            }
            const Color refracted_weight = refracted ? weight[i] * material.kt : Color(0.0);
            bool mirrored = !is_zero(mirror_weight) && level + 1 < m_scene.max_depth;
            const Color next_weight = weight[i] * mirror_weight;
            // render.min_weight: too faint a path is not traced further.
            if (mirrored && std::max({next_weight.x, next_weight.y, next_weight.z}) < m_scene.min_weight)
                mirrored = false;
            if (mirrored) {
                // Mirror: r = 2(n·v)n − v, from the hit point itself (no offset; t_min does the work).
                const Vec3 mirror_direction = normalize(normal[i] * (2.0 * dot(normal[i], to_eye)) - to_eye);
                rays[i] = {hits[i].point, mirror_direction, m_spans.leaving(hits[i].point), m_spans.t_max()};
                weight[i] = next_weight;
                observer.mirror(i, level, rays[i], weight[i]);
                ++counts.reflected;
            } else {
                active[i] = false;
            }
            if (refracted &&
                !(std::max({refracted_weight.x, refracted_weight.y, refracted_weight.z}) < m_scene.min_weight)) {
                observer.transmitted(i, level, refracted_ray, refracted_weight);
                ++counts.reflected;
                Observer lane = observer.for_lane(i);
                trace_paths(&refracted_ray, &refracted_weight, &refracted_interiors, 1, level + 1, &radiance[i], counts,
                            lane);
            }
        }
    }
}

}  // namespace whitted
