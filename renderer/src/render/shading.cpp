// SPDX-License-Identifier: MIT
#include "render/shading.h"

#include "core/packet_array.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <new>

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

// ---- The slide -------------------------------------------------------------------------------
//
//   L = ka·Ia + Σ_i [ kd·I_i·max(0, n·l_i) + ks·I_i·max(0, n·h_i)^p ] + km·L(r) + kt·L(t)
//
// per hit and scalar. Which lights arrive (the convention's gate and the shadow rays) is decided
// before, for a packet of hits at once; what r and t bring back is traced after, by the driver.

Color LectureShading::local_terms(const Material& material, const Color& ambient_light, const Vec3& normal,
                                  const Vec3& to_eye, const ArrivingLight* lights, size_t count) {
    Color local = ambient_term(material, ambient_light);
    for (size_t i = 0; i < count; ++i) {
        if (!lights[i].arrives) continue;  // behind the surface, or in shadow: neither term
        const LightShare share = light_terms(material, normal, to_eye, lights[i]);
        local += share.diffuse + share.specular;
    }
    return local;
}

Color LectureShading::ambient_term(const Material& material, const Color& ambient_light) {
    return material.ka * ambient_light;  // ka·Ia
}

LightShare LectureShading::light_terms(const Material& material, const Vec3& normal, const Vec3& to_eye,
                                       const ArrivingLight& light) {
    const Color& intensity = light.intensity;  // I_i, times the kt of any glass on the way
    // Where ks = 0 (most NFF fills) the lobe, often a pow, is not computed: it is finite and never
    // negative, so ks·I·0 is the same zero, sign included.
    const double lobe = is_zero(material.ks) ? 0.0 : specular_lobe(material, normal, to_eye, light.to_light);
    return {material.kd * intensity * std::max(0.0, light.n_dot_l), material.ks * intensity * lobe};
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

Vec3 LectureShading::mirror_direction(const Vec3& normal, const Vec3& to_eye) {
    return normalize(normal * (2.0 * dot(normal, to_eye)) - to_eye);  // r = 2(n·v)n − v
}

namespace {
/// The transmission step: the refracted direction t of the unit direction d at a surface with
/// normal n, η = n_from / n_to, by Snell's law in Heckbert's form; false where there is none
/// (total internal reflection). With n on the side d comes from and c = −d·n > 0:
/// t = η d + (η c − √(1 − η²(1 − c²))) n.
bool refraction_direction(const Vec3& d, const Vec3& normal, double eta, Vec3& t) {
    double c = dot(d, normal);
    Vec3 toward = normal;
    if (c <= 0)
        c = -c;
    else
        toward = -normal;
    const double k = 1.0 + eta * eta * (c * c - 1.0);
    if (k < 0) return false;
    t = normalize(d * eta + toward * (eta * c - std::sqrt(k)));
    return true;
}
}  // namespace

// ---- The policies beside it ---------------------------------------------------------------------

Reflectance LectureShading::reflectance(const Material& material, const Vec3& normal, const Vec3& to_eye) {
    if (!(material.fresnel_r0 >= 0)) return {1.0, material.km};  // the lecture: km·L(r)
    // Glazed: (1 − F)·(the other terms) + F·L(r), F from Schlick's approximation.
    const double fresnel = schlick_fresnel(material.fresnel_r0, dot(normal, to_eye));
    return {1.0 - fresnel, Color(fresnel)};
}

double LectureShading::schlick_fresnel(double r0, double n_dot_v) {
    if (!(n_dot_v >= 0)) return 0.0;  // seen from behind (only with normals as given): no glaze
    const double c = 1.0 - n_dot_v;
    return r0 + (1.0 - r0) * (c * c * c * c * c);
}

namespace {
/// Scene-format v1's convention, which is POV-Ray 3.7's: surfaces are two-sided (n turned toward
/// the ray); a light counts only where n·l > 1e-10, and then with both its terms, so no highlight
/// shows on the side a light does not reach; its shadow ray leaves x itself (no offset) and
/// spans RaySpans' window from x to just short of the light.
struct PovRayConvention {
    static Vec3 normal(const SurfaceHit& hit, const Ray& ray) { return LectureShading::facing_normal(hit, ray); }
    static double directional_light_distance(const RaySpans& spans, const Vec3& x, const Vec3& to_light) {
        return spans.directional_light_distance(x, to_light);
    }
    static bool count(ArrivingLight& light, Ray& shadow_ray, const RaySpans& spans, const Vec3& x,
                      double light_distance) {
        light.arrives = light.n_dot_l > ray_limits::cosine_epsilon;
        if (!light.arrives) return false;
        const double window = spans.shadow(x);
        shadow_ray = {x, light.to_light, window, light_distance - window};
        return shadow_ray.t_max > shadow_ray.t_min;  // an empty span: the light is on the surface
    }
};

/// The course's ray tracer (`convention: course`): every normal as given, so a back face is
/// shaded dark; no gate: every light counts, its diffuse term is max(0, n·l) and its highlight
/// comes as it is; the shadow ray spans (1e-6, 1) of the vector to the light, which for a
/// directional light needs a finite distance.
struct CourseConvention {
    static Vec3 normal(const SurfaceHit& hit, const Ray&) { return hit.normal; }
    static double directional_light_distance(const RaySpans&, const Vec3& x, const Vec3& to_light) {
        return ray_limits::directional_light_distance - dot(x, to_light);
    }
    static bool count(ArrivingLight& light, Ray& shadow_ray, const RaySpans&, const Vec3& x, double light_distance) {
        light.n_dot_l = std::max(0.0, light.n_dot_l);
        light.arrives = true;
        shadow_ray = {x, light.to_light, ray_limits::course_shadow_fraction * light_distance, light_distance};
        return true;
    }
};

/// `light` from x on a surface with normal n, under `Convention`: `seen` gets l, n·l and I, and
/// `arrives` where the convention counts the light; `shadow_ray` is set where it counts (Ray{}
/// elsewhere). True where the shadow ray is to be traced.
template <class Convention>
inline bool sight(const Light& light, const Vec3& x, const Vec3& normal, const RaySpans& spans, ArrivingLight& seen,
                  Ray& shadow_ray) {
    double light_distance;
    seen.intensity = light.intensity;
    if (light.type == LightType::point) {
        const Vec3 offset = light.position - x;
        light_distance = length(offset);
        if (!(light_distance > 0)) {  // the light at x itself: no l, no terms
            seen.to_light = Vec3{}, seen.n_dot_l = 0, seen.arrives = false, shadow_ray = Ray{};
            return false;
        }
        seen.to_light = offset / light_distance;
    } else {
        seen.to_light = light.toward_light;
        light_distance = Convention::directional_light_distance(spans, x, seen.to_light);
    }
    seen.n_dot_l = dot(normal, seen.to_light);
    if (Convention::count(seen, shadow_ray, spans, x, light_distance)) return true;
    if (!seen.arrives) shadow_ray = Ray{};
    return false;
}

/// render.min_weight: a path fainter than this in every channel is not traced further.
bool worth_tracing(const Color& weight, double min_weight) {
    return !(std::max({weight.x, weight.y, weight.z}) < min_weight);
}
}  // namespace

// ---- The driver: packets, shadow rays, observers -----------------------------------------------

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
    NoObserver for_lanes(const int*, int, int*) const { return {}; }
};
/// PathObserver behind the same interface, with `watching` for what only it needs computed.
/// Refracted paths are traced as packets of their own: `lanes`, when set, holds for each of
/// their lanes the lane of the camera packet that path belongs to.
struct Watching {
    static constexpr bool watching = true;
    PathObserver& to;
    const int* lanes = nullptr;
    int at(int i) const { return lanes ? lanes[i] : i; }
    void miss(int i, int level, const Ray& r, const Color& w, const Color& seen) { to.miss(at(i), level, r, w, seen); }
    void hit(int i, int level, const Ray& r, const SurfaceHit& h, const Vec3& n) { to.hit(at(i), level, r, h, n); }
    void ambient(int i, int level, const Color& a) { to.ambient(at(i), level, a); }
    void light(int i, int level, size_t k, const LightTerms& t) { to.light(at(i), level, k, t); }
    void local(int i, int level, const Color& w, const Color& l, const Color& a) { to.local(at(i), level, w, l, a); }
    void mirror(int i, int level, const Ray& r, const Color& w) { to.mirror(at(i), level, r, w); }
    void transmitted(int i, int level, const Ray& r, const Color& w) { to.transmitted(at(i), level, r, w); }
    /// The observer of a packet whose lane j continues lane parent[j] of this one; `room`
    /// (count entries) holds the map.
    Watching for_lanes(const int* parent, int count, int* room) const {
        for (int j = 0; j < count; ++j) room[j] = at(parent[j]);
        return {to, room};
    }
};
}  // namespace

Color LectureShading::trace(const Ray& ray, int hits_so_far, RayCounts& counts) const {
    Color radiance;
    trace_packet(&ray, 1, hits_so_far, &radiance, counts);
    return radiance;
}

void LectureShading::shadow_filters(Ray* shadow_rays, const bool* tested, int count, Color* filter,
                                    bool* blocked) const {
    // POV-Ray's walk: each surface met multiplies the light by its kt, and the search goes on
    // from the shadow window's width past it (RaySpans::shadow, at that surface); an opaque one
    // ends it. The rays still walking take each step together, as a packet.
    bool walking[packet_size];
    int left = 0;
    for (int i = 0; i < count; ++i) {
        filter[i] = Color(1.0);
        walking[i] = tested[i] && shadow_rays[i].t_max > shadow_rays[i].t_min;
        left += walking[i];
    }
    PacketArray<SurfaceHit, packet_size> hits;
    bool found[packet_size];
    while (left > 0) {
        m_accelerator.intersect_packet(shadow_rays, walking, count, hits.data(), found, HitParts::without_normals);
        for (int i = 0; i < count; ++i) {
            if (!walking[i]) continue;
            bool ends = !found[i];
            if (found[i]) {
                const Color& kt = m_scene.materials[hits[i].material].kt;
                ends = is_zero(kt);
                filter[i] = ends ? Color(0.0) : filter[i] * kt;
                shadow_rays[i].t_min = hits[i].t + m_spans.shadow(hits[i].point);
            }
            if (ends || !(shadow_rays[i].t_max > shadow_rays[i].t_min)) {
                walking[i] = false;
                --left;
            }
        }
    }
    for (int i = 0; i < count; ++i) blocked[i] = tested[i] && is_zero(filter[i]);
}

bool LectureShading::refract(const Ray& ray, const SurfaceHit& hit, const Vec3& normal, Interiors& interiors,
                             Vec3& direction) const {
    // η = n_from / n_to from the objects the ray is inside, as POV-Ray 3.7 keeps them: entering
    // from outside, leaving the innermost object, leaving one of two overlapping objects (their
    // overlap counts as the later one's: η = 1), or entering an object inside another.
    const uint32_t object = hit.object;
    const double ior = m_scene.materials[hit.material].ior;
    double eta;
    const Interiors::Entry* const inside = std::find_if(
        interiors.begin(), interiors.end(), [object](const Interiors::Entry& entry) { return entry.object == object; });
    if (interiors.empty()) {
        eta = 1.0 / ior;
        interiors.push_back({object, ior});
    } else if (interiors.back().object == object) {
        const double leaving = interiors.back().ior;
        interiors.pop_back();
        eta = leaving / (interiors.empty() ? 1.0 : interiors.back().ior);
    } else if (inside != interiors.end()) {
        interiors.erase(inside);
        eta = 1.0;
    } else {
        eta = interiors.back().ior / ior;
        interiors.push_back({object, ior});
    }
    // The same medium on both sides: the ray goes on unbent.
    if (std::fabs(eta - 1.0) < 1e-10) {
        direction = ray.direction;
        return true;
    }
    return refraction_direction(ray.direction, normal, eta, direction);
}

template <class Convention, class Observer>
void LectureShading::see_lights(const Ray* rays, const SurfaceHit* hits, const Vec3* normal, const bool* active,
                                int count, ArrivingLight* lights, RayCounts& counts, int level,
                                Observer& observer) const {
    const size_t light_count = m_scene.lights.size();
    for (size_t k = 0; k < light_count; ++k) {
        const Light& light = m_scene.lights[k];
        PacketArray<Ray, packet_size> shadow_rays;  // set where `active`
        bool tested[packet_size] = {}, blocked[packet_size] = {}, counted[packet_size] = {};
        for (int i = 0; i < count; ++i) {
            if (!active[i]) continue;
            ArrivingLight& seen = lights[i * light_count + k];
            tested[i] = sight<Convention>(light, hits[i].point, normal[i], m_spans, seen, shadow_rays[i]);
            counted[i] = seen.arrives;
            counts.shadow += tested[i];
        }
        // With transmitting surfaces in the scene a shadow ray is a walk (shadow_filters), else a
        // plain occlusion test.
        PacketArray<Color, packet_size> filter;
        if (m_transmits) {
            PacketArray<Ray, packet_size> walked;  // the walk moves t_min; the observer sees the ray as cast
            for (int i = 0; i < count; ++i)
                if (tested[i]) walked[i] = shadow_rays[i];
            shadow_filters(walked.data(), tested, count, filter.data(), blocked);
        } else {
            m_accelerator.occluded_packet(shadow_rays.data(), tested, count, blocked);
        }
        for (int i = 0; i < count; ++i) {
            if (!active[i]) continue;
            ArrivingLight& arriving = lights[i * light_count + k];
            if (m_transmits) arriving.intensity = light.intensity * filter[i];
            arriving.arrives = counted[i] && !(tested[i] && blocked[i]);  // a blocked light adds neither term
            if constexpr (Observer::watching) {
                LightTerms terms;
                terms.to_light = arriving.to_light;
                terms.n_dot_l = arriving.n_dot_l;
                terms.facing = counted[i];
                terms.shadow_ray = shadow_rays[i];
                terms.shadow_tested = tested[i];
                terms.blocked = tested[i] && blocked[i];
                if (m_transmits) terms.filter = filter[i];
                if (arriving.arrives) {
                    const LightShare share =
                        light_terms(m_scene.materials[hits[i].material], normal[i], -rays[i].direction, arriving);
                    terms.diffuse = share.diffuse;
                    terms.specular = share.specular;
                }
                observer.light(i, level, k, terms);
            }
        }
    }
}

void LectureShading::trace_packet(const Ray* first_rays, int count, int hits_so_far, Color* radiance,
                                  RayCounts& counts) const {
    NoObserver none;
    for (int i = 0; i < count; ++i) radiance[i] = Color(0.0);
    if (m_scene.convention == Convention::course)
        trace_paths<CourseConvention>(first_rays, nullptr, nullptr, count, hits_so_far, radiance, counts, none);
    else
        trace_paths<PovRayConvention>(first_rays, nullptr, nullptr, count, hits_so_far, radiance, counts, none);
}

void LectureShading::trace_packet(const Ray* first_rays, int count, int hits_so_far, Color* radiance, RayCounts& counts,
                                  PathObserver& observer) const {
    Watching watching{observer};
    for (int i = 0; i < count; ++i) radiance[i] = Color(0.0);
    if (m_scene.convention == Convention::course)
        trace_paths<CourseConvention>(first_rays, nullptr, nullptr, count, hits_so_far, radiance, counts, watching);
    else
        trace_paths<PovRayConvention>(first_rays, nullptr, nullptr, count, hits_so_far, radiance, counts, watching);
}

template <class Convention, class Observer>
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
    // Every light as each hit sees it, lane by lane: raw room, filled before it is read.
    const size_t light_count = m_scene.lights.size();
    const std::unique_ptr<unsigned char[]> light_room(new unsigned char[sizeof(ArrivingLight) * light_count * count]);
    ArrivingLight* const lights = std::launder(reinterpret_cast<ArrivingLight*>(light_room.get()));
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

        PacketArray<Vec3, packet_size> normal;  // set where `active`
        for (int i = 0; i < count; ++i) {
            if (!active[i]) continue;
            normal[i] = Convention::normal(hits[i], rays[i]);
            observer.hit(i, level, rays[i], hits[i], normal[i]);
            if constexpr (Observer::watching)
                observer.ambient(i, level, ambient_term(m_scene.materials[hits[i].material], m_scene.ambient));
        }
        see_lights<Convention>(rays.data(), hits.data(), normal.data(), active, count, lights, counts, level, observer);
        // This level's refracted rays, lane by lane: lane j's path continues lane parent[j]'s.
        PacketArray<Ray, packet_size> refracted_rays;
        PacketArray<Color, packet_size> refracted_weights;
        std::array<Interiors, packet_size> refracted_interiors;
        PacketArray<Color, packet_size> refracted_radiance;
        int parent[packet_size];
        int refracted_count = 0;
        for (int i = 0; i < count; ++i) {
            if (!active[i]) continue;
            const Material& material = m_scene.materials[hits[i].material];
            const Vec3 to_eye = -rays[i].direction;
            const Color local =
                local_terms(material, m_scene.ambient, normal[i], to_eye, &lights[i * light_count], light_count);
            const Reflectance reflected = reflectance(material, normal[i], to_eye);
            const Color added = weight[i] * local * reflected.local;
            radiance[i] += added;
            observer.local(i, level, weight[i], local, added);
            // kt·L(t): the refracted ray, or at total internal reflection the light back along r
            // with weight 1 in place of km (as POV-Ray 3.7 adds it, docs/pov-model.md §5).
            Color mirror_weight = reflected.mirror;
            bool refracted = false;
            Ray refracted_ray;
            Interiors& refracted_inside = refracted_interiors[refracted_count];
            if (m_transmits && !is_zero(material.kt) && level + 1 < m_scene.max_depth) {
                refracted_inside = interiors[i];
                Vec3 direction;
                if (refract(rays[i], hits[i], normal[i], refracted_inside, direction)) {
                    refracted = true;
                    refracted_ray = {hits[i].point, direction, m_spans.leaving(hits[i].point), m_spans.t_max()};
                } else {
                    mirror_weight = Color(1.0);
                }
            }
            const Color refracted_weight = refracted ? weight[i] * material.kt : Color(0.0);
            const Color next_weight = weight[i] * mirror_weight;
            if (!is_zero(mirror_weight) && level + 1 < m_scene.max_depth &&
                worth_tracing(next_weight, m_scene.min_weight)) {
                // km·L(r): the mirror ray leaves the hit point itself (no offset; t_min does the work).
                rays[i] = {hits[i].point, mirror_direction(normal[i], to_eye), m_spans.leaving(hits[i].point),
                           m_spans.t_max()};
                weight[i] = next_weight;
                observer.mirror(i, level, rays[i], weight[i]);
                ++counts.reflected;
            } else {
                active[i] = false;
            }
            if (refracted && worth_tracing(refracted_weight, m_scene.min_weight)) {
                observer.transmitted(i, level, refracted_ray, refracted_weight);
                ++counts.reflected;
                refracted_rays[refracted_count] = refracted_ray;
                refracted_weights[refracted_count] = refracted_weight;
                // The path goes on adding to the pixel's sum so far, term by term.
                refracted_radiance[refracted_count] = radiance[i];
                parent[refracted_count++] = i;
            }
        }
        // Each lane's refracted path adds its terms after that lane's local terms and before
        // its mirror path's next segment, as the recursion kt·L(t) + km·L(r) orders them.
        if (refracted_count > 0) {
            int lanes_room[packet_size];
            Observer lanes = observer.for_lanes(parent, refracted_count, lanes_room);
            trace_paths<Convention>(refracted_rays.data(), refracted_weights.data(), refracted_interiors.data(),
                                    refracted_count, level + 1, refracted_radiance.data(), counts, lanes);
            for (int j = 0; j < refracted_count; ++j) radiance[parent[j]] = refracted_radiance[j];
        }
    }
}
}  // namespace whitted
