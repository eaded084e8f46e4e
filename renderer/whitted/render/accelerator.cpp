// SPDX-License-Identifier: MIT
#include "whitted/render/accelerator.h"

#include "whitted/compat/povray.h"
#include "whitted/core/packet_array.h"
#include "whitted/geometry/shapes.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <deque>
#include <limits>
#include <memory>
#include <mutex>
#include <new>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>

#include <sys/mman.h>

#include <cstdio>
#include <tuple>

#include <tbb/blocked_range.h>
#include <tbb/collaborative_call_once.h>
#include <tbb/parallel_for.h>

namespace whitted {
namespace {

enum class ShapeKind : uint32_t { triangles, spheres, boxes, cones, instances };

/// Embree's context, extended with the double-precision rays of the query: user-geometry
/// callbacks read them back from the pointer Embree passes them (Embree's ray `id` is the index
/// into `rays`), so spheres and boxes never see the float copies.
struct QueryContext {
    /// `coherent`: the rays are neighbours (a packet), which Embree can traverse together.
    /// Of the `count` rays, those with `active[i]` are queries (all of them if `active` is
    /// null); the others may be stale memory.
    QueryContext(const Ray* query_rays, const bool* active_rays, int ray_count, bool coherent)
        : rays(query_rays), active(active_rays), count(ray_count) {
        rtcInitIntersectContext(&embree);
        if (coherent) embree.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    }

    /// Whether Embree's lane with ray `id` is one of the queries. Embree hands a callback no
    /// empty lane (set_empty_lane gives it no extent), but a callback must not read a stale ray
    /// if some instruction set's code ever did.
    bool is_query(unsigned id) const { return id < unsigned(count) && (!active || active[id]); }

    RTCIntersectContext embree;
    const Ray* rays = nullptr;
    const bool* active = nullptr;
    int count = 0;
    /// Nearest analytic hit so far per ray (double), set by intersect queries before tracing,
    /// and its normal, so it is not computed twice (set with it).
    double best_t[Accelerator::packet_size];
    PacketArray<Vec3, Accelerator::packet_size> best_normal;
    /// Whether that hit's face came from the box edge rule (ShapeHit::edge_tie): another box's
    /// plain hit at the same t then wins over it (analytic_intersect).
    bool best_edge_tie[Accelerator::packet_size];
    /// Whether another sphere or box that looks different (another material or normal) was
    /// met at exactly that t: which of them shows is then POV-Ray's choice (finish_hit,
    /// PovrayTestOrder), not the order Embree met them in.
    bool best_tied[Accelerator::packet_size];
    /// The material and object of the hit held, to tell such a tie from one that looks the same.
    uint32_t best_material[Accelerator::packet_size];
    uint32_t best_object[Accelerator::packet_size];

    /// A query starts with nothing held, up to the ray's own limit.
    void start(int id, const Ray& ray) {
        best_t[id] = ray.t_max;
        best_edge_tie[id] = false;
        best_tied[id] = false;
    }
};

struct AnalyticGeometry {
    ShapeKind kind;
    const Scene* scene;
    Vec3 offset;  ///< Embree's coordinates are world minus this (Impl::choose_frame)
};

/// A sphere's, box's or cone's material and object (Scene::objects index + 1).
std::pair<uint32_t, uint32_t> material_and_object(const Scene& scene, ShapeKind kind, unsigned prim) {
    if (kind == ShapeKind::spheres) return {scene.spheres[prim].material, scene.spheres[prim].object};
    if (kind == ShapeKind::cones) return {scene.cones[prim].material, scene.cones[prim].object};
    return {scene.boxes[prim].material, scene.boxes[prim].object};
}

bool intersect_analytic(const AnalyticGeometry& geometry, unsigned prim, const Ray& ray, double t_max, ShapeHit& hit) {
    if (geometry.kind == ShapeKind::spheres)
        return intersect_sphere(geometry.scene->spheres[prim], ray, ray.t_min, t_max, hit);
    if (geometry.kind == ShapeKind::cones)
        return intersect_cone(geometry.scene->cones[prim], ray, ray.t_min, t_max, hit);
    const Box& box = geometry.scene->boxes[prim];
    return geometry.scene->intersection == Intersection::povray
               ? intersect_box_as_povray(box, ray, ray.t_min, t_max, hit)
               : intersect_box(box, ray, ray.t_min, t_max, hit);
}

/// Whether Scene::objects number `object` (index + 1) is a cylinder or cone.
bool is_cone_object(const Scene& scene, uint32_t object) {
    const ObjectType type = scene.objects[object - 1].type;
    return type == ObjectType::cylinder || type == ObjectType::cone;
}

void analytic_bounds(const RTCBoundsFunctionArguments* args) {
    const auto* geometry = static_cast<const AnalyticGeometry*>(args->geometryUserPtr);
    Vec3 lo, hi;
    if (geometry->kind == ShapeKind::spheres)
        world_bounds(geometry->scene->spheres[args->primID], lo, hi);
    else if (geometry->kind == ShapeKind::cones)
        world_bounds(geometry->scene->cones[args->primID], lo, hi);
    else
        world_bounds(geometry->scene->boxes[args->primID], lo, hi);
    lo -= geometry->offset;
    hi -= geometry->offset;
    // Widen by a relative margin so that float rounding of the bounds never clips a hit.
    const Vec3 pad = (hi - lo) * 1e-6 + Vec3(1e-6);
    lo -= pad;
    hi += pad;
    args->bounds_o->lower_x = std::nextafter(float(lo.x), -INFINITY);
    args->bounds_o->lower_y = std::nextafter(float(lo.y), -INFINITY);
    args->bounds_o->lower_z = std::nextafter(float(lo.z), -INFINITY);
    args->bounds_o->upper_x = std::nextafter(float(hi.x), INFINITY);
    args->bounds_o->upper_y = std::nextafter(float(hi.y), INFINITY);
    args->bounds_o->upper_z = std::nextafter(float(hi.z), INFINITY);
}

void analytic_intersect(const RTCIntersectFunctionNArguments* args) {
    const auto* geometry = static_cast<const AnalyticGeometry*>(args->geometryUserPtr);
    auto* context = reinterpret_cast<QueryContext*>(args->context);
    RTCRayN* rays = RTCRayHitN_RayN(args->rayhit, args->N);
    RTCHitN* hits = RTCRayHitN_HitN(args->rayhit, args->N);
    for (unsigned i = 0; i < args->N; ++i) {
        if (!args->valid[i]) continue;
        const unsigned id = RTCRayN_id(rays, args->N, i);
        if (!context->is_query(id)) continue;
        const Ray& ray = context->rays[id];
        const double limit = std::min(context->best_t[id], double(RTCRayN_tfar(rays, args->N, i)));
        // Up to and including the limit, to see a hit at exactly the t of the one held.
        ShapeHit hit;
        if (!intersect_analytic(*geometry, args->primID, ray, next_up(limit), hit)) continue;
        const auto [material, object] = material_and_object(*geometry->scene, geometry->kind, args->primID);
        if (hit.t == limit) {
            // At a triangle's (float) distance, or at the ray's end: the candidate does not win.
            if (limit != context->best_t[id] || !(limit < ray.t_max)) continue;
            // An exact tie with the sphere or box held: overlapping boxes with faces in one
            // plane, or two equal spheres in one place.
            const Vec3& held = context->best_normal[id];
            // The exact rule: the tie goes to the first object in the file, whatever order
            // Embree met them in (which differs from one instruction set to another). So does a
            // tie with a cone, and a tie that looks the same, under POV-Ray's rules too: its
            // order (PovrayTestOrder) knows spheres and boxes.
            const bool by_object = geometry->scene->intersection == Intersection::exact ||
                                   geometry->kind == ShapeKind::cones ||
                                   is_cone_object(*geometry->scene, context->best_object[id]);
            if (by_object || (material == context->best_material[id] && hit.normal.x == held.x &&
                              hit.normal.y == held.y && hit.normal.z == held.z)) {
                if (object > context->best_object[id]) continue;
            } else {
                // A plain face at the same t replaces a face the edge rule chose (a ray along
                // one box's edge, inside another's top): POV-Ray then tests the other box
                // first, its bounding box being met earlier (bench/generate.py --boxes 1000000,
                // row 383). Where that is the only difference (one material) the rule decides;
                // otherwise finish_hit asks POV-Ray's order (PovrayTestOrder). Rebuilding the
                // order costs a million equal cubes 0.6 s, which ties of one material whose
                // faces differ only by the edge rule need not pay.
                if (!(material == context->best_material[id] && hit.edge_tie != context->best_edge_tie[id]))
                    context->best_tied[id] = true;
                if (!(context->best_edge_tie[id] && !hit.edge_tie)) continue;
            }
        } else {
            context->best_tied[id] = false;
        }
        context->best_t[id] = hit.t;
        context->best_normal[id] = hit.normal;
        context->best_edge_tie[id] = hit.edge_tie;
        context->best_material[id] = material;
        context->best_object[id] = object;
        // Round the float distance up so Embree keeps visiting boxes that may hold a closer hit.
        RTCRayN_tfar(rays, args->N, i) = next_up(float(hit.t));
        RTCHitN_geomID(hits, args->N, i) = args->geomID;
        RTCHitN_primID(hits, args->N, i) = args->primID;
        RTCHitN_instID(hits, args->N, i, 0) = RTC_INVALID_GEOMETRY_ID;
        RTCHitN_u(hits, args->N, i) = 0;
        RTCHitN_v(hits, args->N, i) = 0;
        RTCHitN_Ng_x(hits, args->N, i) = float(hit.normal.x);
        RTCHitN_Ng_y(hits, args->N, i) = float(hit.normal.y);
        RTCHitN_Ng_z(hits, args->N, i) = float(hit.normal.z);
    }
}

void analytic_occluded(const RTCOccludedFunctionNArguments* args) {
    const auto* geometry = static_cast<const AnalyticGeometry*>(args->geometryUserPtr);
    const auto* context = reinterpret_cast<const QueryContext*>(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
        if (!args->valid[i]) continue;
        const unsigned id = RTCRayN_id(args->ray, args->N, i);
        if (!context->is_query(id)) continue;
        const Ray& ray = context->rays[id];
        ShapeHit hit;
        if (intersect_analytic(*geometry, args->primID, ray, ray.t_max, hit))
            RTCRayN_tfar(args->ray, args->N, i) = -INFINITY;  // Embree's mark for "occluded"
    }
}

/// How far apart two surfaces a ray meets at `t` may be found and still be one tie by the exact
/// rule (render.intersection: exact): 64 ulps of the largest coordinate or distance the two
/// distances were computed from. A face lying in a plane is met by both at one t in real
/// numbers, but each distance is rounded its own way; scaled or moved, the rounding differs,
/// and without the window the order of the two would follow it.
double tie_window(const Ray& ray, double t) {
    const Vec3 x = ray.at(t);
    const double largest = std::max({std::fabs(ray.origin.x), std::fabs(ray.origin.y), std::fabs(ray.origin.z),
                                     std::fabs(x.x), std::fabs(x.y), std::fabs(x.z), std::fabs(t)});
    return 64 * std::numeric_limits<double>::epsilon() * largest;
}

/// What triangle_filter needs of a mesh: its triangles, how they are decided
/// (MeshAsPovray) and, for a prototype's mesh, the transform of each instance (by
/// Embree's instance geomID), to take the ray into its space.
struct TriangleGeometry {
    const TriangleMesh* mesh = nullptr;
    bool as_povray = false;
    const std::vector<const Transform*>* instance_transforms = nullptr;
};

/// How far past its edges, in barycentric terms, a triangle still counts as hit by the exact
/// test: far below any ray's float error, and far above double's rounding of u and v, so that
/// a ray along an edge two triangles share meets at least one of them.
constexpr double triangle_edge_margin = 1e-10;

/// The decision on a triangle candidate, made in double from the scene's own float vertices
/// and the double ray: the ray passes inside the triangle and meets it within (t_min, t_max),
/// by the exact test (Möller–Trumbore in double), or by POV-Ray's own where `as_povray`
/// (render.intersection: povray, the rules `whitted check` renders with; MeshAsPovray). That
/// one differs from the exact test where a ray grazes a triangle (POV-Ray's single-precision
/// plane moves the hit along the ray by up to 5e-3, past the shadow window) or passes within
/// about 1e-9 of an edge (POV-Ray's float planes of two neighbours can leave a crack between
/// them, or overlap): the instancing bench tori and the 1M-triangle anchor failed the strict
/// rule at such pixels (docs/pov-model.md §3, "Mesh triangles"; docs/validation.md, "Grazing
/// rays on the instancing bench tori"). It runs as POV-Ray runs it on the converter's mesh2: on
/// the float offsets, with the ray moved by −origin in double (POV-Ray's `translate`); for a
/// prototype's triangle (`instanced`) the ray is in the prototype's space with the world's t,
/// and POV-Ray makes its direction unit length first. Embree's float test only proposes
/// candidates: it is given triangles widened beyond its rounding (Impl::add_mesh), so every
/// triangle the double ray meets is among them, and the widened parts are refused here.
/// hit.normal is (v1 − v0) × (v2 − v0); u and v are set by the exact test only (the smooth
/// normal of POV-Ray's is computed from the point, blended_normal).
bool hit_triangle_in_double(const TriangleMesh& mesh, unsigned prim, const Ray& ray, bool as_povray, bool instanced,
                            ShapeHit& hit) {
    const uint32_t* index = &mesh.indices[3 * size_t(prim)];
    const Vec3 v0 = mesh.vertex(index[0]), v1 = mesh.vertex(index[1]), v2 = mesh.vertex(index[2]);
    if (!as_povray) return intersect_triangle(v0, v1, v2, ray, ray.t_min, ray.t_max, hit, triangle_edge_margin);
    const Vec3 p0 = mesh.offset(index[0]), p1 = mesh.offset(index[1]), p2 = mesh.offset(index[2]);
    const Vec3 origin = ray.origin - mesh.origin;
    double t = 0;
    bool inside = false;
    if (instanced) {
        const Vec3& d = ray.direction;
        const double len = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
        const double inverse = 1.0 / len;
        if (!intersect_mesh2_triangle(p0, p1, p2, origin, {d.x * inverse, d.y * inverse, d.z * inverse}, t, inside))
            return false;
        t /= len;
    } else if (!intersect_mesh2_triangle(p0, p1, p2, origin, ray.direction, t, inside)) {
        return false;
    }
    if (!inside || !(t > ray.t_min && t < ray.t_max)) return false;
    hit.t = t;
    hit.u = hit.v = 0;
    hit.normal = cross(v1 - v0, v2 - v0);
    return true;
}

/// Embree's filter for triangle candidates (hit_triangle_in_double): on the meshes' own
/// geometry where every candidate must be decided as it is met (EmbreeFrame::exact_range);
/// otherwise on the context of shadow rays (whose first accepted candidate ends the search)
/// and of a ray traced again after its nearest candidate was refused.
void triangle_filter(const RTCFilterFunctionNArguments* args) {
    const auto* geometry = static_cast<const TriangleGeometry*>(args->geometryUserPtr);
    const auto* context = reinterpret_cast<const QueryContext*>(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] != -1) continue;
        const unsigned id = RTCRayN_id(args->ray, args->N, i);
        if (!context->is_query(id)) continue;
        const unsigned inst = RTCHitN_instID(args->hit, args->N, i, 0);
        const Ray ray = inst == RTC_INVALID_GEOMETRY_ID
                            ? context->rays[id]
                            : to_object_space(*(*geometry->instance_transforms)[inst], context->rays[id]);
        ShapeHit hit;
        if (!hit_triangle_in_double(*geometry->mesh, RTCHitN_primID(args->hit, args->N, i), ray, geometry->as_povray,
                                    inst != RTC_INVALID_GEOMETRY_ID, hit))
            args->valid[i] = 0;
    }
}

/// An array for Embree to read (the widened corners, their indices), in anonymous memory that
/// the kernel maps in whole as it is made (MAP_POPULATE) and zeroes. It is written once, front
/// to back, right after: touched a page at a time instead, every 4 KiB is a page fault, and on
/// the virtual machine of docs/performance.md the faults cost more than the writing. Ordinary
/// pages, not transparent huge ones: see `main` (renderer/app/main.cpp) for why.
template <class T>
class MappedArray {
public:
    MappedArray() = default;
    /// `count` elements and `padding` bytes after them (zero, as the whole mapping is).
    MappedArray(size_t count, size_t padding) : m_bytes(count * sizeof(T) + padding) {
        if (m_bytes == 0) return;
        void* memory =
            mmap(nullptr, m_bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_POPULATE, -1, 0);
        if (memory == MAP_FAILED) throw std::bad_alloc();
        m_data = static_cast<T*>(memory);
    }
    MappedArray(MappedArray&& other) noexcept
        : m_data(std::exchange(other.m_data, nullptr)), m_bytes(std::exchange(other.m_bytes, 0)) {}
    MappedArray& operator=(MappedArray&& other) noexcept {
        std::swap(m_data, other.m_data);
        std::swap(m_bytes, other.m_bytes);
        return *this;
    }
    MappedArray(const MappedArray&) = delete;
    MappedArray& operator=(const MappedArray&) = delete;
    ~MappedArray() {
        if (m_data) munmap(m_data, m_bytes);
    }
    T* data() const { return m_data; }

private:
    T* m_data = nullptr;
    size_t m_bytes = 0;
};

/// A corner of a widened triangle moves at most this many margins (widen_triangles).
constexpr double max_corner_move = 64;

/// The corners Embree is given for the triangles of `mesh` (moved by `shift` into Embree's
/// frame), three per triangle, each triangle on its own and widened: its corners moved out
/// from its incentre so that every edge lies `margin` further out (a scaling about the incentre
/// by 1 + margin / inradius, the incentre being an inradius from each edge). A corner's move is
/// capped at max_corner_move margins, since a needle's tip would go far; the capped triangle
/// still holds the original, each corner lying on the line from the incentre through the
/// original one. A degenerate triangle is left as it is: neither test ever hits it.
void widen_triangles(const TriangleMesh& mesh, const Vec3& shift, double margin, float* corners) {
    const double cap = max_corner_move * margin;
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, mesh.triangle_count(), 4096), [&](const tbb::blocked_range<size_t>& range) {
            for (size_t t = range.begin(); t != range.end(); ++t) {
                const uint32_t* index = &mesh.indices[3 * t];
                Vec3 p[3];
                for (int k = 0; k < 3; ++k) p[k] = mesh.vertex(index[k]) + shift;
                const Vec3 ab = p[1] - p[0], ac = p[2] - p[0], bc = p[2] - p[1];
                // Each corner is weighed by the length of the side facing it.
                const double a = std::sqrt(dot(bc, bc)), b = std::sqrt(dot(ac, ac)), c = std::sqrt(dot(ab, ab));
                const double perimeter = a + b + c;
                const double twice_area = length(cross(ab, ac));
                if (twice_area > 0 && margin > 0) {
                    const Vec3 incentre = (p[0] * a + p[1] * b + p[2] * c) * (1.0 / perimeter);
                    const double scale = margin * perimeter / twice_area;  // margin / inradius
                    // The cap is compared squared: a square root only where it applies.
                    for (Vec3& corner : p) {
                        const Vec3 out = corner - incentre;
                        const double squared = dot(out, out);
                        corner += scale * scale * squared <= cap * cap ? out * scale : out * (cap / std::sqrt(squared));
                    }
                }
                float* c3 = corners + 9 * t;
                // A triangle of no area is never hit (the double test refuses it), and many of
                // them at one point abort Embree's builder: NaN corners make Embree leave it out.
                if (!(twice_area > 0)) {
                    std::fill(c3, c3 + 9, std::numeric_limits<float>::quiet_NaN());
                    continue;
                }
                for (int k = 0; k < 3; ++k) {
                    c3[3 * k] = float(p[k].x);
                    c3[3 * k + 1] = float(p[k].y);
                    c3[3 * k + 2] = float(p[k].z);
                }
            }
        });
}

/// The first error Embree reported. Embree calls record_embree_error from C code, where an
/// exception must not pass, and from any render thread: it keeps the message, and the caller
/// throws it once the Embree call has returned (throw_if_failed).
struct EmbreeError {
    std::atomic<bool> failed{false};
    mutable std::mutex mutex;
    std::string message;

    void throw_if_failed(const char* during) const {
        if (!failed.load(std::memory_order_relaxed)) return;
        std::lock_guard lock(mutex);
        throw std::runtime_error(message + " (" + during + ")");
    }
};

void record_embree_error(void* user, RTCError code, const char* message) {
    if (code == RTC_ERROR_NONE) return;
    auto* error = static_cast<EmbreeError*>(user);
    std::lock_guard lock(error->mutex);
    if (error->failed.load()) return;
    error->message = code == RTC_ERROR_OUT_OF_MEMORY ? std::string("Embree ran out of memory")
                                                     : std::string("Embree: ") + (message ? message : "unknown error");
    error->failed.store(true);
}

/// How Embree's float coordinates relate to the world (Impl::choose_frame).
struct EmbreeFrame {
    Vec3 offset;  ///< Embree's coordinates are world minus this
    /// Triangle candidates are re-tested in double (triangle_filter), and Embree is handed a
    /// wider range than the ray's, from 0 to a little past t_max, so that a hit whose float
    /// distance falls just outside the range while its double one is inside still reaches
    /// triangle_filter and the analytic callbacks, which decide the exact range in double.
    bool exact_range = false;

    /// The largest coordinate a ray or a finite shape has in this frame (the camera's included),
    /// and the diagonal of the box that holds them all, the longest distance a ray travels to a
    /// shape: together they bound Embree's float error (Impl::world_triangle_margin).
    double reach = 0, span = 0;

    float t_min(const Ray& ray) const { return exact_range ? 0.0f : float(ray.t_min); }
    float t_max(const Ray& ray) const {
        return exact_range ? next_up(float(ray.t_max * (1 + 1e-6))) : float(ray.t_max);
    }
};

RTCRay make_embree_ray(const Ray& ray, unsigned id, const EmbreeFrame& frame) {
    const Vec3 origin = ray.origin - frame.offset;
    RTCRay r;
    r.org_x = float(origin.x);
    r.org_y = float(origin.y);
    r.org_z = float(origin.z);
    r.dir_x = float(ray.direction.x);
    r.dir_y = float(ray.direction.y);
    r.dir_z = float(ray.direction.z);
    r.tnear = frame.t_min(ray);
    r.tfar = frame.t_max(ray);
    r.time = 0;
    r.mask = 0xFFFFFFFFu;
    r.id = id;
    r.flags = 0;
    return r;
}

/// Lane i of an Embree packet (RTCRay4/8/16) holds `ray`; `id` is the ray's index in the
/// query, so callbacks find the double ray again.
template <class RayPacket>
void set_lane(RayPacket& packet, int i, const Ray& ray, unsigned id, const EmbreeFrame& frame) {
    const Vec3 origin = ray.origin - frame.offset;
    packet.org_x[i] = float(origin.x);
    packet.org_y[i] = float(origin.y);
    packet.org_z[i] = float(origin.z);
    packet.dir_x[i] = float(ray.direction.x);
    packet.dir_y[i] = float(ray.direction.y);
    packet.dir_z[i] = float(ray.direction.z);
    packet.tnear[i] = frame.t_min(ray);
    packet.tfar[i] = frame.t_max(ray);
    packet.time[i] = 0;
    packet.mask[i] = 0xFFFFFFFFu;
    packet.id[i] = id;
    packet.flags[i] = 0;
}

/// A lane with no query in it. Embree's native packet code skips it by its `valid` mask, but
/// where Embree has no native code for the width (rtcIntersect16 without AVX-512) its ray
/// stream filter ignores the mask and traces every lane: so the lane holds a well-formed ray
/// that cannot hit anything, the form Embree itself gives unused lanes (tnear 0, tfar -inf).
template <class RayPacket>
void set_empty_lane(RayPacket& packet, int i, unsigned id) {
    packet.org_x[i] = packet.org_y[i] = packet.org_z[i] = 0;
    packet.dir_x[i] = packet.dir_y[i] = 0;
    packet.dir_z[i] = 1;
    packet.tnear[i] = 0;
    packet.tfar[i] = -INFINITY;
    packet.time[i] = 0;
    packet.mask[i] = 0;
    packet.id[i] = id;
    packet.flags[i] = 0;
}

/// Embree's packet types and calls for W lanes, so that one piece of code serves every width.
template <int W>
struct EmbreePacket;
template <>
struct EmbreePacket<4> {
    using RayHit = RTCRayHit4;
    using Rays = RTCRay4;
    static void intersect(const int* valid, RTCScene scene, RTCIntersectContext* context, RayHit* rays) {
        rtcIntersect4(valid, scene, context, rays);
    }
    static void occluded(const int* valid, RTCScene scene, RTCIntersectContext* context, Rays* rays) {
        rtcOccluded4(valid, scene, context, rays);
    }
};
template <>
struct EmbreePacket<8> {
    using RayHit = RTCRayHit8;
    using Rays = RTCRay8;
    static void intersect(const int* valid, RTCScene scene, RTCIntersectContext* context, RayHit* rays) {
        rtcIntersect8(valid, scene, context, rays);
    }
    static void occluded(const int* valid, RTCScene scene, RTCIntersectContext* context, Rays* rays) {
        rtcOccluded8(valid, scene, context, rays);
    }
};
template <>
struct EmbreePacket<16> {
    using RayHit = RTCRayHit16;
    using Rays = RTCRay16;
    static void intersect(const int* valid, RTCScene scene, RTCIntersectContext* context, RayHit* rays) {
        rtcIntersect16(valid, scene, context, rays);
    }
    static void occluded(const int* valid, RTCScene scene, RTCIntersectContext* context, Rays* rays) {
        rtcOccluded16(valid, scene, context, rays);
    }
};

std::string isa_list() {
    std::string list;
    for (const std::string& name : embree_isa_names()) list += (list.empty() ? "" : ", ") + name;
    return list;
}

/// An Embree device with the render's thread count and, unless `isa` is empty, that instruction
/// set. Throws std::invalid_argument when the CPU cannot run `isa`.
RTCDevice make_device(const std::string& config_start, const std::string& isa) {
    std::string config = config_start;
    if (!isa.empty()) config += ",isa=" + isa;
    RTCDevice device = rtcNewDevice(config.c_str());
    if (device) return device;
    const RTCError code = rtcGetDeviceError(nullptr);
    if (code == RTC_ERROR_UNSUPPORTED_CPU && !isa.empty())
        throw std::invalid_argument("WHITTED_EMBREE_ISA=" + isa + ": this CPU cannot run Embree's " + isa +
                                    " code (unset it to let Embree choose)");
    throw std::runtime_error("cannot create the Embree device (Embree error " + std::to_string(int(code)) + ")");
}

Vec3 vertex_normal(const TriangleMesh& mesh, uint32_t index) {
    const float* n = &mesh.normals[3 * size_t(index)];
    return {n[0], n[1], n[2]};
}

/// Embree's own allocations, counted as they happen (--stats reports the peak: the BVH and
/// its build's scratch memory).
struct MemoryCount {
    std::atomic<int64_t> current{0}, peak{0};
};

bool count_embree_memory(void* user, ssize_t bytes, bool /*post*/) {
    auto* count = static_cast<MemoryCount*>(user);
    const int64_t now = count->current.fetch_add(bytes) + bytes;
    int64_t peak = count->peak.load();
    while (now > peak && !count->peak.compare_exchange_weak(peak, now)) {
    }
    return true;  // never refuse: the limit is the machine's
}

/// The widest packet Embree traverses natively with the device's instruction set. A wider call
/// than that goes through Embree's ray stream filter, which ignores the `valid` mask (hence
/// set_empty_lane) and regroups the rays into packets of the native width itself; calling at
/// the native width keeps Embree on the code that honours the mask. Measured against 16-wide
/// calls through the filter on the same CPU, the two were within a few percent of each other
/// (docs/performance.md). The width changes only the grouping: each ray's answer is
/// recomputed in double, so the pixels are the same for every width.
int native_lane_width(RTCDevice device) {
    if (rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED)) return 16;
    if (rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED)) return 8;
    if (rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_NATIVE_RAY4_SUPPORTED)) return 4;
    return 1;
}

}  // namespace

const std::vector<std::string>& embree_isa_names() {
    static const std::vector<std::string> names = {"sse2", "sse4.2", "avx", "avx2", "avx512"};
    return names;
}

std::string embree_isa_from_environment() {
    const char* value = std::getenv("WHITTED_EMBREE_ISA");
    if (!value || !*value) return "";
    const std::vector<std::string>& names = embree_isa_names();
    if (std::find(names.begin(), names.end(), value) == names.end())
        throw std::invalid_argument(std::string("WHITTED_EMBREE_ISA=") + value +
                                    ": not one of Embree's instruction sets (" + isa_list() +
                                    "); unset it to let Embree choose");
    return value;
}

void require_embree_isa(const std::string& isa) {
    if (isa.empty()) return;  // Embree's own choice: every CPU it starts on can run it
    rtcReleaseDevice(make_device("verbose=0", isa));
}

bool embree_isa_supported(const std::string& isa) {
    try {
        require_embree_isa(isa);
        return true;
    } catch (const std::invalid_argument&) {
        return false;
    }
}

EmbreeInfo embree_info(const std::string& isa) {
    EmbreeInfo info;
    info.version = RTC_VERSION_STRING;
    for (const std::string& name : embree_isa_names())
        if (embree_isa_supported(name)) info.isas.push_back(name);
    info.isa_in_use = !isa.empty() ? isa : info.isas.empty() ? std::string("?") : info.isas.back();
    RTCDevice device = make_device("verbose=0", isa);
    info.lane_width = native_lane_width(device);
    rtcReleaseDevice(device);
    return info;
}

struct Accelerator::Impl {
    const Scene& scene;
    std::string isa;
    EmbreeError embree_error;  ///< see record_embree_error
    MemoryCount memory;
    RTCDevice device = nullptr;
    RTCScene rtc_scene = nullptr;
    // geomID → what it is: a mesh index, the sphere/box user geometry, or an instance index.
    std::vector<ShapeKind> kinds;
    std::vector<uint32_t> mesh_of_geometry;
    /// One Embree scene (one BVH) per prototype, placed by the instances; within each, a mesh's
    /// geomID is its index in Prototype::meshes.
    std::vector<RTCScene> prototype_scenes;
    /// Top-level geomID → the instance's transform (null for other geometry), for triangle_filter.
    std::vector<const Transform*> instance_transforms;
    std::deque<TriangleGeometry> filter_data;  ///< triangle_filter's user data, one per mesh (stable addresses)
    /// 0, 1, 2, ... : every mesh's index buffer, its widened triangles having corners of their
    /// own (widen_triangles), for as many triangles as the largest mesh has.
    MappedArray<uint32_t> corner_indices;
    std::vector<MappedArray<float>> widened_corners;  ///< each mesh's (widen_triangles), for Embree
    /// How POV-Ray holds each mesh of the world, and of each prototype.
    std::vector<MeshAsPovray> world_povray;
    std::vector<std::vector<MeshAsPovray>> prototype_povray;
    AnalyticGeometry spheres{ShapeKind::spheres, nullptr, {}};
    AnalyticGeometry boxes{ShapeKind::boxes, nullptr, {}};
    AnalyticGeometry cones{ShapeKind::cones, nullptr, {}};
    RTCBuildQuality quality = RTC_BUILD_QUALITY_MEDIUM;  ///< of the scene and its meshes (build_quality)
    int lane_width = 1;                                  ///< rays per Embree packet call (native_lane_width)
    /// Embree works in float in a frame of its own (choose_frame). Rays, vertices and bounds
    /// are shifted in double before they are rounded, so a scene far from the origin keeps
    /// float's precision relative to its own size; every answer is still recomputed in world
    /// double from the scene's own data.
    EmbreeFrame frame;
    /// POV-Ray's order of testing the spheres and boxes, for rays that meet two at exactly the
    /// same t (tie_order); built on the first such ray, so a scene without ties never pays (a
    /// million equal cubes pay 0.5-0.8 s and 200 MB, docs/performance.md).
    mutable tbb::collaborative_once_flag tie_order_built;
    mutable std::unique_ptr<PovrayTestOrder> tie_order_data;

    Impl(const Scene& s, int threads, const std::string& instruction_set) : scene(s), isa(instruction_set) {
        spheres.scene = boxes.scene = cones.scene = &scene;
        check_reach();  // before Embree holds anything
        // Embree gets the render's thread count (--threads): its setting limits the whole
        // process's TBB threads (with threads=1 the render ran at half speed), so the two must
        // agree.
        device = make_device("verbose=0,threads=" + std::to_string(threads), isa);
        lane_width = native_lane_width(device);
        rtcSetDeviceErrorFunction(device, record_embree_error, &embree_error);
        rtcSetDeviceMemoryMonitorFunction(device, count_embree_memory, &memory);
        rtc_scene = rtcNewScene(device);
        quality = build_quality();
        rtcSetSceneBuildQuality(rtc_scene, quality);
        // Robust: Embree's watertight triangle test. Its fast one let a ray slip between two
        // triangles of a closed mesh now and then and hit the inside (a black pixel in a lit
        // torus); finish_hit can only refine the candidate Embree proposes, not find a missed one.
        // Context filter: triangle_filter is set on the context of a ray traced again, and of
        // shadow rays (Impl::intersect, Impl::occluded).
        rtcSetSceneFlags(rtc_scene, RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION);
        frame = choose_frame();
        spheres.offset = boxes.offset = cones.offset = frame.offset;
        size_t most_triangles = 0;
        for (const TriangleMesh& mesh : scene.meshes) most_triangles = std::max(most_triangles, mesh.triangle_count());
        for (const Prototype& prototype : scene.prototypes)
            for (const TriangleMesh& mesh : prototype.meshes)
                most_triangles = std::max(most_triangles, mesh.triangle_count());
        corner_indices = MappedArray<uint32_t>(3 * most_triangles, 0);
        for (size_t i = 0; i < 3 * most_triangles; ++i) corner_indices.data()[i] = uint32_t(i);
        for (const TriangleMesh& mesh : scene.meshes) world_povray.emplace_back(mesh, scene.intersection);
        for (const Prototype& prototype : scene.prototypes) {
            prototype_povray.emplace_back();
            for (const TriangleMesh& mesh : prototype.meshes)
                prototype_povray.back().emplace_back(mesh, scene.intersection);
        }
        for (uint32_t m = 0; m < scene.meshes.size(); ++m) {
            const unsigned id = add_mesh(rtc_scene, scene.meshes[m], world_povray[m].decided, Vec3(0.0) - frame.offset,
                                         world_triangle_margin());
            record(id, ShapeKind::triangles, m);
        }
        add_instances();
        if (!scene.spheres.empty()) add_analytic(spheres, scene.spheres.size());
        if (!scene.boxes.empty()) add_analytic(boxes, scene.boxes.size());
        if (!scene.cones.empty()) add_analytic(cones, scene.cones.size());
        rtcCommitScene(rtc_scene);
        try {
            embree_error.throw_if_failed("while building the BVH");
        } catch (...) {
            release();
            throw;
        }
    }

    ~Impl() { release(); }

    const PovrayTestOrder& tie_order() const {
        // The threads that wait help build it (its sorts split work).
        tbb::collaborative_call_once(tie_order_built,
                                     [&] { tie_order_data = std::make_unique<PovrayTestOrder>(scene); });
        return *tie_order_data;
    }

    /// Embree keeps bounds and rays in float and stops the program (an assertion) on a ray whose
    /// origin lies beyond about 1.8e19, or on bounds it cannot order; its rays start on the
    /// shapes. So a finite shape reaching beyond ±max_reach is refused, naming the object.
    static constexpr double max_reach = 1e15;
    void check_reach() {
        const auto reach = [](const Vec3& lo, const Vec3& hi) {
            return std::max(
                {std::fabs(lo.x), std::fabs(lo.y), std::fabs(lo.z), std::fabs(hi.x), std::fabs(hi.y), std::fabs(hi.z)});
        };
        double finite_reach = 0;  // of every finite shape, in world space
        const auto check = [&](uint32_t object, double reached) {
            finite_reach = std::max(finite_reach, reached);
            if (reached <= max_reach) return;  // NaN is refused too
            const SourceLocation where = object > 0 && object <= scene.objects.size()
                                             ? scene.objects[object - 1].where
                                             : SourceLocation{scene.path, 0, 0};
            const char* kind =
                object > 0 && object <= scene.objects.size() ? to_string(scene.objects[object - 1].type) : "object";
            char distance[32];
            std::snprintf(distance, sizeof distance, "%g", reached);
            throw InputError(where, std::string(kind) + " reaches " + distance +
                                        " from the origin in world space; Whitted renders shapes within 1e15 of it");
        };
        Vec3 lo, hi;
        for (const Sphere& sphere : scene.spheres) world_bounds(sphere, lo, hi), check(sphere.object, reach(lo, hi));
        for (const Box& box : scene.boxes) world_bounds(box, lo, hi), check(box.object, reach(lo, hi));
        for (const Cone& cone : scene.cones) world_bounds(cone, lo, hi), check(cone.object, reach(lo, hi));
        for (const TriangleMesh& mesh : scene.meshes) {
            double reached = 0;
            for (uint32_t i = 0; i < mesh.vertex_count(); ++i) {
                const Vec3 v = mesh.vertex(i);
                reached = std::max({reached, std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)});
            }
            check(mesh.object, reached);
        }
        for (const Instance& instance : scene.instances) {
            const Prototype& prototype = scene.prototypes[instance.prototype];
            double reached = 0;
            for (int corner = 0; corner < 8; ++corner) {
                const Vec3 p = instance.object_to_world.apply_point({corner & 1 ? prototype.hi.x : prototype.lo.x,
                                                                     corner & 2 ? prototype.hi.y : prototype.lo.y,
                                                                     corner & 4 ? prototype.hi.z : prototype.lo.z});
                reached = std::max({reached, std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)});
            }
            check(instance.object, reached);
        }
        // An instance is traced in its prototype's own space: Embree takes each ray there, in
        // float, and stops the program on an origin beyond about 1.8e18 there too. Rays start at
        // the camera and on the finite shapes (a plane's far hits aside), so a bound on where
        // they start, taken into the prototype's space, bounds its origins: a prototype shrunk
        // by 1e-20 under a camera 5 away gave origins of 5e20. Such an instance is refused.
        const Camera& camera = scene.camera;
        const auto largest = [](const Vec3& v) { return std::max({std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)}); };
        const double origins = std::max(finite_reach, largest(camera.eye) + largest(camera.right) + largest(camera.up));
        // A ray starting beyond that (on a plane's far hit, or one from there) is taken up to the
        // finite shapes before it is traced (intersect, occluded): the rule holds for it too.
        finite_shapes_reach = finite_reach;
        rule_origins = origins;
        const auto transformed = [](const auto& shape) { return bool(shape.object_to_world); };
        rule_applies = !scene.instances.empty() ||
                       std::any_of(scene.spheres.begin(), scene.spheres.end(), transformed) ||
                       std::any_of(scene.boxes.begin(), scene.boxes.end(), transformed) ||
                       std::any_of(scene.cones.begin(), scene.cones.end(), transformed);
        // How far from the origin of an object's own space the rays start there.
        const auto origins_in_own_space = [&](const Transform& to_world) {
            const double shrink = largest(to_world.inverse_vector({1, 0, 0})) +
                                  largest(to_world.inverse_vector({0, 1, 0})) +
                                  largest(to_world.inverse_vector({0, 0, 1}));
            return shrink * origins + largest(to_world.inverse_point({0, 0, 0}));
        };
        // A sphere, box or cone with a transform is intersected in its own space too, in double:
        // where rays start beyond 1e17 there, a double no longer places a hit on a shape of size 1
        // (its spacing is 16 at 1e17), so a box flattened by 1e-30 under a camera 5 away, or a
        // sphere of radius 1e30 scaled by 1e-30, drew something else than POV-Ray (48 % and 80 %
        // of the pixels alike). The instances' rule (below) refuses them, naming the object.
        const auto check_own_space = [&](const SharedTransform& to_world, const Vec3& own_lo, const Vec3& own_hi,
                                         uint32_t object) {
            if (!to_world) return;
            const SourceLocation where = object > 0 && object <= scene.objects.size()
                                             ? scene.objects[object - 1].where
                                             : SourceLocation{scene.path, 0, 0};
            const std::string kind =
                object > 0 && object <= scene.objects.size() ? to_string(scene.objects[object - 1].type) : "object";
            char figure[32];
            const double own_reach = std::max(largest(own_lo), largest(own_hi));
            if (!(own_reach <= max_reach)) {
                std::snprintf(figure, sizeof figure, "%g", own_reach);
                throw InputError(where, kind + " reaches " + figure +
                                            " from the origin of its own space (before its transform); Whitted "
                                            "renders shapes within 1e15 of it (give the shape its size in its own "
                                            "numbers, not through the transform)");
            }
            const double in_own_space = origins_in_own_space(*to_world);
            if (!(in_own_space <= max_instance_origin)) {
                std::snprintf(figure, sizeof figure, "%g", in_own_space);
                throw InputError(where, kind + ": its transform shrinks or flattens it so far that rays reach " +
                                            figure +
                                            " in its own space; Whitted keeps them within 1e17 (give the shape "
                                            "its size in its own numbers, not through the transform)");
            }
        };
        for (const Sphere& sphere : scene.spheres)
            check_own_space(sphere.object_to_world, sphere.center - Vec3(sphere.radius),
                            sphere.center + Vec3(sphere.radius), sphere.object);
        for (const Box& box : scene.boxes) check_own_space(box.object_to_world, box.min, box.max, box.object);
        for (const Cone& cone : scene.cones) {
            Cone own = cone;
            own.object_to_world = nullptr;
            world_bounds(own, lo, hi);
            check_own_space(cone.object_to_world, lo, hi, cone.object);
        }
        for (const Instance& instance : scene.instances) {
            const Prototype& prototype = scene.prototypes[instance.prototype];
            const Transform& to_world = instance.object_to_world;
            const double in_prototype = origins_in_own_space(to_world);
            // The other way: a prototype of ±1e-20 enlarged by 1e20 aborted in Embree too (its rays'
            // directions shrink by as much in its space), while 1e19 rendered.
            const double grow = largest(to_world.apply_vector({1, 0, 0})) + largest(to_world.apply_vector({0, 1, 0})) +
                                largest(to_world.apply_vector({0, 0, 1}));
            const double prototype_reach = std::max(largest(prototype.lo), largest(prototype.hi));
            const SourceLocation where = instance.object > 0 && instance.object <= scene.objects.size()
                                             ? scene.objects[instance.object - 1].where
                                             : SourceLocation{scene.path, 0, 0};
            char figure[32];
            if (!(prototype_reach <= max_reach)) {
                std::snprintf(figure, sizeof figure, "%g", prototype_reach);
                throw InputError(where, std::string("instance: its prototype reaches ") + figure +
                                            " from the origin of its own space; Whitted renders prototypes within "
                                            "1e15 of it (scale its triangles down and the instance up)");
            }
            if (!(grow <= max_instance_origin)) {
                std::snprintf(figure, sizeof figure, "%g", grow);
                throw InputError(where, std::string("instance: its transform enlarges the prototype ") + figure +
                                            " times; Whitted renders instances enlarged up to 1e17 times (scale the "
                                            "prototype's triangles up instead)");
            }
            if (!(in_prototype <= max_instance_origin)) {
                std::snprintf(figure, sizeof figure, "%g", in_prototype);
                throw InputError(where, std::string("instance: its transform shrinks the prototype so far that rays "
                                                    "reach ") +
                                            figure +
                                            " in the prototype's own space; Whitted keeps them within 1e17 (scale "
                                            "the prototype's triangles down instead)");
            }
        }
    }
    /// Where rays may start in a prototype's own space (check_reach): a tenth of Embree's limit.
    static constexpr double max_instance_origin = 1e17;
    /// check_reach's bounds, each on every axis: every finite shape lies within
    /// finite_shapes_reach of the origin, and its rule holds for rays starting within rule_origins.
    double finite_shapes_reach = 0, rule_origins = 0;
    /// Whether the scene has what the rule is for: an instance, or a sphere, box or cone with a
    /// transform. Without one, Embree takes the world's rays as they are (a plane's far hits stay
    /// well within its 1.8e19), and every answer is the double test's on the ray itself.
    bool rule_applies = false;

    /// Whether `ray` starts where check_reach's rule does not reach: only a plane's far hits
    /// (up to RaySpans::far_t_max = 1e16 from the eye, and further after bounces between planes)
    /// and the rays from them start there. Embree takes such an origin in float, and an
    /// instance or a transformed shape takes it into its own space, however much it shrinks
    /// there: the shadow ray from a floor's hit 1e11 away gave Embree an origin of 1e19 in the
    /// space of an instance scaled by 1e-8 (an abort).
    bool starts_afar(const Ray& ray) const {
        return rule_applies &&
               std::max({std::fabs(ray.origin.x), std::fabs(ray.origin.y), std::fabs(ray.origin.z)}) > rule_origins;
    }

    /// `ray` (starting afar) from where it enters the cube that holds every finite shape: its
    /// origin moved along it by `skipped`, its range shortened by as much. False when it does not
    /// meet the cube within its range: no finite shape can be on it. The new origin is put inside
    /// the cube (its rounding, an ulp of the far origin, is the ray's own uncertainty), so the
    /// rule bounds it.
    bool toward_finite_shapes(const Ray& ray, Ray& near, double& skipped) const {
        const double cube = finite_shapes_reach;
        double enter = 0, leave = ray.t_max;
        const double origin[3] = {ray.origin.x, ray.origin.y, ray.origin.z};
        const double direction[3] = {ray.direction.x, ray.direction.y, ray.direction.z};
        for (int axis = 0; axis < 3; ++axis) {
            if (direction[axis] == 0) {
                if (!(std::fabs(origin[axis]) <= cube)) return false;
                continue;
            }
            double a = (-cube - origin[axis]) / direction[axis], b = (cube - origin[axis]) / direction[axis];
            if (a > b) std::swap(a, b);
            enter = std::max(enter, a);
            leave = std::min(leave, b);
        }
        if (!(enter <= leave) || !(leave > ray.t_min)) return false;
        // A little before the cube, so that a shape on its face is still ahead of `near`.
        const double margin = 1e-6 * cube, outer = cube + 2 * margin;
        skipped = std::max(0.0, enter - margin);
        const Vec3 at = ray.at(skipped);
        near.origin =
            Vec3(std::clamp(at.x, -outer, outer), std::clamp(at.y, -outer, outer), std::clamp(at.z, -outer, outer));
        near.direction = ray.direction;
        near.t_min = std::max(ray.t_min - enter, 0.0);
        near.t_max = ray.t_max - enter;
        return true;
    }

    /// A BVH is built once per triangle and traversed once per ray. HIGH quality took 2.0 s to
    /// build 1M triangles against 0.2 s for MEDIUM, for a few percent faster traversal that a
    /// single frame cannot win back. On the 1M-triangle anchor (2 threads, 1280x960) LOW built
    /// in 0.06 s against 0.15 s and rendered 0.02 s (10 %) slower; on the 100k-triangle one the
    /// two came out even, and on the 100 spheres LOW rendered 15-25 % slower (docs/performance.md).
    /// So LOW once the triangles outnumber a quarter of the camera rays. Spheres and boxes count
    /// half: a candidate costs more to test there (a callback in double), so a poorer BVH costs
    /// more per ray; at 640x480, LOW saved 0.2 s of 0.48 s building a million spheres (or boxes)
    /// and cost 0.03 s of render, while at 100k the two came out even. The BVH only changes the
    /// order in which candidates are met: those images came out bit-identical.
    RTCBuildQuality build_quality() const {
        const double primitives = double(scene.triangle_count()) +
                                  0.5 * double(scene.spheres.size() + scene.boxes.size() + scene.cones.size());
        const double camera_rays = double(scene.width) * scene.height * scene.samples * scene.samples;
        return primitives > camera_rays / 4 ? RTC_BUILD_QUALITY_LOW : RTC_BUILD_QUALITY_MEDIUM;
    }

    /// The frame: centred on the bounds of the scene's finite shapes when they lie further from
    /// the origin than their half extent (the shifted coordinates then keep at least one more
    /// bit), otherwise the world's; widen_triangles writes Embree's corners in it. Where the shifted
    /// coordinates still reach M, Embree's float distances may be off by some ulp(M), 2^-23 M
    /// each: once 16 of them exceed a quarter of the smallest minimum distance (surface_t_min,
    /// 1e-4), that is from M ≈ 13 on, the range of each triangle candidate is decided in double
    /// (EmbreeFrame::exact_range). Below that Embree's range decision stands: it cannot move a
    /// hit across 1e-4 or the shadow window's 1e-3, and the filter's call per candidate cost the
    /// 100k-triangle anchor 35 % (docs/validation.md, "Far from the origin").
    EmbreeFrame choose_frame() const {
        constexpr double inf = std::numeric_limits<double>::infinity();
        Vec3 lo(inf), hi(-inf);
        for (const TriangleMesh& mesh : scene.meshes)
            for (uint32_t i = 0; i < mesh.vertex_count(); ++i) {
                lo = min(lo, mesh.vertex(i));
                hi = max(hi, mesh.vertex(i));
            }
        for (const Sphere& sphere : scene.spheres) {
            Vec3 a, b;
            world_bounds(sphere, a, b);
            lo = min(lo, a), hi = max(hi, b);
        }
        for (const Box& box : scene.boxes) {
            Vec3 a, b;
            world_bounds(box, a, b);
            lo = min(lo, a), hi = max(hi, b);
        }
        for (const Cone& cone : scene.cones) {
            Vec3 a, b;
            world_bounds(cone, a, b);
            lo = min(lo, a), hi = max(hi, b);
        }
        // An instance's float errors come from Embree's world-space ray (the frame's reach) and
        // from its prototype-space triangles, which the transform scales (at most by the largest
        // absolute row sum of its linear part).
        double local_reach = 0;
        for (const Instance& instance : scene.instances) {
            const Prototype& prototype = scene.prototypes[instance.prototype];
            for (int corner = 0; corner < 8; ++corner) {
                const Vec3 p = instance.object_to_world.apply_point({corner & 1 ? prototype.hi.x : prototype.lo.x,
                                                                     corner & 2 ? prototype.hi.y : prototype.lo.y,
                                                                     corner & 4 ? prototype.hi.z : prototype.lo.z});
                lo = min(lo, p), hi = max(hi, p);
            }
            const auto& m = instance.object_to_world.rows();
            double norm = 0;
            for (int row = 0; row < 3; ++row)
                norm = std::max(norm, std::fabs(m[4 * row]) + std::fabs(m[4 * row + 1]) + std::fabs(m[4 * row + 2]));
            local_reach =
                std::max({local_reach, norm * std::max({std::fabs(prototype.lo.x), std::fabs(prototype.lo.y),
                                                        std::fabs(prototype.lo.z), std::fabs(prototype.hi.x),
                                                        std::fabs(prototype.hi.y), std::fabs(prototype.hi.z)})});
        }
        EmbreeFrame chosen;
        if (!(lo.x <= hi.x)) return chosen;  // no finite shape: Embree has nothing to find
        const Vec3 centre = (lo + hi) * 0.5, half = (hi - lo) * 0.5;
        const double far = std::max({std::fabs(centre.x), std::fabs(centre.y), std::fabs(centre.z)});
        const double size = std::max({half.x, half.y, half.z});
        if (std::isfinite(far) && far > size) chosen.offset = centre;
        const Vec3 a = lo - chosen.offset, b = hi - chosen.offset;
        const double reach = std::max({std::fabs(a.x), std::fabs(a.y), std::fabs(a.z), std::fabs(b.x), std::fabs(b.y),
                                       std::fabs(b.z), local_reach});
        chosen.exact_range = !(16 * std::ldexp(reach, -23) < ray_limits::surface_t_min / 4);
        // Camera rays start at the eye, or across the image plane for an orthographic camera.
        const Camera& camera = scene.camera;
        const auto magnitude = [](const Vec3& v) { return Vec3(std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)); };
        const Vec3 screen = (magnitude(camera.right) + magnitude(camera.up)) * 0.5;
        const Vec3 all_lo = min(a, camera.eye - chosen.offset - screen),
                   all_hi = max(b, camera.eye - chosen.offset + screen);
        chosen.reach = std::max({reach, std::fabs(all_lo.x), std::fabs(all_lo.y), std::fabs(all_lo.z),
                                 std::fabs(all_hi.x), std::fabs(all_hi.y), std::fabs(all_hi.z)});
        chosen.span = length(all_hi - all_lo);
        return chosen;
    }

    void release() {
        if (rtc_scene) rtcReleaseScene(rtc_scene);
        for (RTCScene prototype : prototype_scenes) rtcReleaseScene(prototype);
        prototype_scenes.clear();
        if (device) rtcReleaseDevice(device);
        rtc_scene = nullptr;
        device = nullptr;
    }

    /// How far Embree's float test may stray from the double ray, as a distance at a triangle
    /// of the world: its ray's origin and direction rounded to float (an ulp of the origin's
    /// coordinates, and of t for the direction) and its watertight test's float arithmetic on
    /// the corners and the origin (a few ulps of their coordinates) are each at most
    /// 2^-24 (reach + span) in Embree's frame (EmbreeFrame). The triangles are widened by
    /// margin_ulps of those, so that every triangle the double ray meets is among Embree's
    /// candidates (hit_triangle_in_double decides), unless the ray runs almost in its plane
    /// across an edge, where the widening seen along the ray shrinks (docs/validation.md).
    /// Accelerator.EveryTriangleTheDoubleTestAcceptsIsFound finds rays that slip through with
    /// 2 ulps and none with 4: 16 leaves a factor of 4. Not more, because the widening grows with
    /// the scene while the triangles do not: with 64, the 10,000 tori of `bench/generate.py
    /// --instances 10000` were widened by half their inradius, and the candidates Embree then
    /// proposed and the double test refused cost 70 % more render time (docs/performance.md).
    static constexpr double margin_ulps = 16;
    double world_triangle_margin() const { return margin_ulps * std::ldexp(frame.reach + frame.span, -24); }

    /// Attaches a triangle mesh to `target` with its vertices moved by `shift` (Embree's
    /// coordinates: the world minus the frame's offset; a prototype's own, unshifted) and its
    /// triangles widened by `margin` (widen_triangles). Returns its geomID there.
    unsigned add_mesh(RTCScene target, const TriangleMesh& mesh, bool as_povray, const Vec3& shift, double margin,
                      const std::vector<const Transform*>* transforms = nullptr) {
        RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
        const size_t corners = 3 * mesh.triangle_count();
        // Embree reads the last corner with a 16-byte load: 4 bytes of (zero) padding follow it.
        widened_corners.emplace_back(3 * corners, sizeof(float));
        float* local = widened_corners.back().data();
        if (local) widen_triangles(mesh, shift, margin, local);
        rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, local, 0, 3 * sizeof(float),
                                   corners);
        rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, corner_indices.data(), 0,
                                   3 * sizeof(uint32_t), mesh.triangle_count());
        rtcSetGeometryBuildQuality(geometry, quality);  // Embree builds LOW only if both say so
        filter_data.push_back({&mesh, as_povray, transforms});
        rtcSetGeometryUserData(geometry, &filter_data.back());
        if (frame.exact_range) {
            rtcSetGeometryIntersectFilterFunction(geometry, triangle_filter);
            rtcSetGeometryOccludedFilterFunction(geometry, triangle_filter);
        }
        rtcCommitGeometry(geometry);
        const unsigned id = rtcAttachGeometry(target, geometry);
        rtcReleaseGeometry(geometry);
        return id;
    }

    /// One Embree scene per prototype, built once, and one Embree instance per placement: the
    /// triangles are stored (and their BVH built) once however many times they are placed.
    /// Embree holds each instance's transform in float, with the frame's offset taken off; it
    /// only proposes candidates, and finish_hit decides each in double from the scene's own
    /// transform.
    void add_instances() {
        if (scene.instances.empty()) return;
        // A prototype's triangles are widened in its own space: by the world's margin taken back
        // through the instance that shrinks it most (the Frobenius norm of the inverse's linear
        // part bounds how far a world distance goes), plus the rounding of Embree's float
        // transform of the ray and of the prototype's own coordinates.
        std::vector<double> stretch(scene.prototypes.size(), 0.0);
        for (const Instance& instance : scene.instances) {
            const Transform& t = instance.object_to_world;
            const Vec3 x = t.inverse_vector({1, 0, 0}), y = t.inverse_vector({0, 1, 0}),
                       z = t.inverse_vector({0, 0, 1});
            stretch[instance.prototype] =
                std::max(stretch[instance.prototype], std::sqrt(dot(x, x) + dot(y, y) + dot(z, z)));
        }
        for (uint32_t p = 0; p < scene.prototypes.size(); ++p) {
            const Prototype& prototype = scene.prototypes[p];
            const double own =
                std::max({std::fabs(prototype.lo.x), std::fabs(prototype.lo.y), std::fabs(prototype.lo.z),
                          std::fabs(prototype.hi.x), std::fabs(prototype.hi.y), std::fabs(prototype.hi.z)});
            const double margin = stretch[p] * world_triangle_margin() + margin_ulps * std::ldexp(2 * own, -24);
            RTCScene prototype_scene = rtcNewScene(device);
            prototype_scenes.push_back(prototype_scene);
            rtcSetSceneBuildQuality(prototype_scene, quality);
            // Watertight and with the context filter, as the world's.
            rtcSetSceneFlags(prototype_scene, RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION);
            for (size_t g = 0; g < prototype.meshes.size(); ++g)
                add_mesh(prototype_scene, prototype.meshes[g], prototype_povray[p][g].decided, Vec3(0.0),
                         std::isfinite(margin) ? margin : 0.0, &instance_transforms);
            rtcCommitScene(prototype_scene);
        }
        for (uint32_t i = 0; i < scene.instances.size(); ++i) {
            const Instance& instance = scene.instances[i];
            RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_INSTANCE);
            rtcSetGeometryInstancedScene(geometry, prototype_scenes[instance.prototype]);
            rtcSetGeometryTimeStepCount(geometry, 1);
            const auto& m = instance.object_to_world.rows();
            const float rows[12] = {float(m[0]), float(m[1]), float(m[2]),  float(m[3] - frame.offset.x),
                                    float(m[4]), float(m[5]), float(m[6]),  float(m[7] - frame.offset.y),
                                    float(m[8]), float(m[9]), float(m[10]), float(m[11] - frame.offset.z)};
            rtcSetGeometryTransform(geometry, 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, rows);
            rtcCommitGeometry(geometry);
            const unsigned id = rtcAttachGeometry(rtc_scene, geometry);
            rtcReleaseGeometry(geometry);
            record(id, ShapeKind::instances, i);
            if (instance_transforms.size() <= id) instance_transforms.resize(id + 1, nullptr);
            instance_transforms[id] = &instance.object_to_world;
        }
    }

    void add_analytic(AnalyticGeometry& user, size_t count) {
        RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER);
        rtcSetGeometryUserPrimitiveCount(geometry, static_cast<unsigned>(count));
        rtcSetGeometryUserData(geometry, &user);
        rtcSetGeometryBoundsFunction(geometry, analytic_bounds, nullptr);
        rtcSetGeometryIntersectFunction(geometry, analytic_intersect);
        rtcSetGeometryOccludedFunction(geometry, analytic_occluded);
        rtcCommitGeometry(geometry);
        const unsigned id = rtcAttachGeometry(rtc_scene, geometry);
        rtcReleaseGeometry(geometry);
        record(id, user.kind, 0);
    }

    void record(unsigned id, ShapeKind kind, uint32_t mesh) {
        if (kinds.size() <= id) kinds.resize(id + 1), mesh_of_geometry.resize(id + 1);
        kinds[id] = kind;
        mesh_of_geometry[id] = mesh;
    }

    /// The smooth shading normal at a triangle hit: the unit vertex normals blended by
    /// barycentric weight and renormalised, as POV-Ray's mesh2 does; for a mesh decided as
    /// POV-Ray decides it (`povray.decided`), computed POV-Ray's way at `point`, the hit in the
    /// mesh's space, from the normals as POV-Ray holds them (mesh2_smooth_normal). False where
    /// the triangle is shaded flat, with its face normal: a mesh without normals, three equal
    /// vertex normals (except under render.convention: course) or a blend of length 0.
    bool blended_normal(const TriangleMesh& mesh, uint32_t prim, const ShapeHit& hit, const MeshAsPovray& povray,
                        const Vec3& point, Vec3& out) const {
        if (mesh.normals.empty()) return false;
        const uint32_t* index = &mesh.indices[3 * size_t(prim)];
        const Vec3 n0 = vertex_normal(mesh, index[0]), n1 = vertex_normal(mesh, index[1]),
                   n2 = vertex_normal(mesh, index[2]);
        const Vec3 d1 = n0 - n1, d2 = n0 - n2;
        // The course's convention interpolates always, as its ray tracer does.
        if (dot(d1, d1) <= 1e-10 && dot(d2, d2) <= 1e-10 && scene.convention != Convention::course) return false;
        const auto as_read = [&](uint32_t i) {
            const float* n = &povray.normals[3 * size_t(i)];
            return Vec3(n[0], n[1], n[2]);
        };
        const Vec3 blended =
            povray.decided
                ? mesh2_smooth_normal(mesh.offset(index[0]), mesh.offset(index[1]), mesh.offset(index[2]),
                                      as_read(index[0]), as_read(index[1]), as_read(index[2]), point - mesh.origin)
                : n0 * (1.0 - hit.u - hit.v) + n1 * hit.u + n2 * hit.v;
        const double len = length(blended);
        if (!(len > 0)) return false;
        out = blended / len;
        return true;
    }

    /// The exact hit for what Embree found on one ray (geom == invalid: nothing), then the planes.
    /// `retry` is set, and nothing is found, when Embree's nearest candidate is a triangle that
    /// the double test refuses (hit_triangle_in_double): the ray passes through the widened
    /// margin only, or meets the plane outside the range (a ray leaving a surface at a grazing
    /// angle can start on, or within rounding of, a neighbouring triangle's plane, which Embree's
    /// float distance puts past t_min while in double it is 0, behind the ray or too near). The
    /// caller traces the ray again with the double test as Embree's filter (intersect_again).
    /// `inst`: Embree's instance geomID when the candidate is a prototype's triangle (`geom` is
    /// then its mesh in the prototype), else RTC_INVALID_GEOMETRY_ID.
    bool finish_hit(const Ray& ray, unsigned inst, unsigned geom, unsigned prim, double best_t, const Vec3& best_normal,
                    bool tied, SurfaceHit& out, bool& retry) const {
        retry = false;
        bool found = false;
        double t_max = ray.t_max;
        ShapeHit hit;
        if (geom != RTC_INVALID_GEOMETRY_ID) {
            if (inst != RTC_INVALID_GEOMETRY_ID) {
                // A prototype's triangle, tested in double in the prototype's space, its normals
                // then taken to the world with the inverse transpose. A plain copy's face
                // normal is (v1 − v0) × (v2 − v0) of the world vertices, which is the
                // transformed one times the sign of the determinant.
                const Instance& instance = scene.instances[mesh_of_geometry[inst]];
                const Transform& to_world = instance.object_to_world;
                const TriangleMesh& mesh = scene.prototypes[instance.prototype].meshes[geom];
                const MeshAsPovray& povray = prototype_povray[instance.prototype][geom];
                if (!hit_triangle_in_double(mesh, prim, to_object_space(to_world, ray), povray.decided, true, hit))
                    return retry = true, false;
                const double handedness = to_world.determinant() < 0 ? -1.0 : 1.0;
                out.geometric_normal = normalize(to_world.apply_normal(hit.normal)) * handedness;
                Vec3 smooth;
                // POV-Ray takes the world point back into the mesh's space for its normal.
                out.normal = blended_normal(mesh, prim, hit, povray, to_world.inverse_point(ray.at(hit.t)), smooth)
                                 ? normalize(to_world.apply_normal(smooth))
                                 : out.geometric_normal;
                out.material = instance.material != Instance::no_material ? instance.material
                               : mesh.triangle_materials.empty()          ? mesh.material
                                                                          : mesh.triangle_materials[prim];
                out.object = instance.object;
            } else if (kinds[geom] == ShapeKind::triangles) {
                const TriangleMesh& mesh = scene.meshes[mesh_of_geometry[geom]];
                const MeshAsPovray& povray = world_povray[mesh_of_geometry[geom]];
                if (!hit_triangle_in_double(mesh, prim, ray, povray.decided, false, hit)) return retry = true, false;
                out.geometric_normal = normalize(hit.normal);
                Vec3 smooth;
                out.normal =
                    blended_normal(mesh, prim, hit, povray, ray.at(hit.t), smooth) ? smooth : out.geometric_normal;
                out.material = mesh.triangle_materials.empty() ? mesh.material : mesh.triangle_materials[prim];
                out.object = mesh.object;
            } else {
                // The callback computed this hit in double and kept it; of several at exactly
                // that t, the one POV-Ray tests first shows (PovrayTestOrder).
                hit.t = best_t;
                Vec3 normal = best_normal;
                ShapeKind kind = kinds[geom];
                PovrayTestOrder::Found first;
                if (tied && tie_order().nearest(ray, first, best_t) && first.hit.t == best_t)
                    kind = first.sphere ? ShapeKind::spheres : ShapeKind::boxes, prim = first.index,
                    normal = first.hit.normal;
                out.normal = out.geometric_normal = normalize(normal);
                std::tie(out.material, out.object) = material_and_object(scene, kind, prim);
            }
            out.t = hit.t;
            t_max = hit.t;
            found = true;
        }
        // A tie between a plane and the shape found (the bottom of a box standing on the floor,
        // met by a ray inside the box), by the exact rule: the two distances within tie_window
        // of each other (a tie in real numbers that rounding split) and the first object in the
        // file keeps it. Under POV-Ray's rules the plane keeps a tie within an ulp, as POV-Ray
        // shows it there (docs/pov-model.md §3, "A plane keeps a tie"). Among the planes the
        // first one keeps it either way.
        const bool povray = scene.intersection == Intersection::povray;
        bool plane_found = false;
        for (const Plane& plane : scene.planes) {
            const double window = found && !povray ? tie_window(ray, t_max) : 0.0;
            const double limit = found && povray && !plane_found ? next_up(t_max) : t_max + window;
            ShapeHit plane_hit;
            if (!intersect_plane(plane, ray, ray.t_min, limit, plane_hit)) continue;
            if (!povray && found && !(plane_hit.t < t_max - window) && plane.object > out.object) continue;
            t_max = plane_hit.t;
            out.t = plane_hit.t;
            out.normal = out.geometric_normal = plane.normal;
            out.material = plane.material;
            out.object = plane.object;
            found = plane_found = true;
        }
        if (found) out.point = ray.at(out.t);
        return found;
    }

    /// The nearest hit on `ray`: Embree's nearest candidate, when the double test accepts it.
    bool intersect(const Ray& ray, SurfaceHit& out) const {
        return starts_afar(ray) ? intersect_from_afar(ray, out) : intersect_from_here(ray, out);
    }

    /// intersect for a ray that does not start afar (or has been brought near).
    bool intersect_from_here(const Ray& ray, SurfaceHit& out) const {
        bool retry = false;
        const bool found = trace(ray, nullptr, out, retry);
        return retry ? intersect_again(ray, out) : found;
    }

    /// intersect for a ray that starts_afar: a plane it meets before it reaches the finite
    /// shapes' cube, else what it meets from there on (toward_finite_shapes).
    bool intersect_from_afar(const Ray& ray, SurfaceHit& out) const {
        Ray near;
        double skipped = 0;
        bool retry = false;
        if (!toward_finite_shapes(ray, near, skipped))
            return finish_hit(ray, RTC_INVALID_GEOMETRY_ID, RTC_INVALID_GEOMETRY_ID, 0, 0, {}, false, out, retry);
        Ray before = ray;
        before.t_max = std::min(ray.t_max, skipped);
        if (before.t_max > before.t_min &&
            finish_hit(before, RTC_INVALID_GEOMETRY_ID, RTC_INVALID_GEOMETRY_ID, 0, 0, {}, false, out, retry))
            return true;
        if (!intersect_from_here(near, out)) return false;
        out.t += skipped;
        return true;
    }

    /// The nearest hit on a ray whose nearest candidate the double test refused (finish_hit):
    /// traced again with that test as Embree's filter, so that Embree goes on past every
    /// refused candidate to the nearest accepted one. Only such rays pay for the filter's call
    /// per candidate (a few percent of the rays that meet a mesh, those near an edge).
    bool intersect_again(const Ray& ray, SurfaceHit& out) const {
        bool retry = false;
        const bool found = trace(ray, triangle_filter, out, retry);
        if (!retry) return found;
        // Not expected (the filter refuses what finish_hit would); if it came, the planes answer.
        return finish_hit(ray, RTC_INVALID_GEOMETRY_ID, RTC_INVALID_GEOMETRY_ID, 0, 0, {}, false, out, retry);
    }

    /// One Embree query for `ray` with `filter` on its context (null: none), and finish_hit.
    bool trace(const Ray& ray, RTCFilterFunctionN filter, SurfaceHit& out, bool& retry) const {
        QueryContext context(&ray, nullptr, 1, false);
        context.embree.filter = filter;
        context.start(0, ray);
        RTCRayHit rayhit;
        rayhit.ray = make_embree_ray(ray, 0, frame);
        rayhit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rayhit.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(rtc_scene, &context.embree, &rayhit);
        return finish_hit(ray, rayhit.hit.instID[0], rayhit.hit.geomID, rayhit.hit.primID, context.best_t[0],
                          context.best_normal[0], context.best_tied[0], out, retry);
    }

    /// Calls `lanes.operator()<W>(first)` for first = 0, W, 2W, ... < count, with W the native
    /// lane_width, so that each packet query is written once for every width. False when
    /// Embree has no packets (lane_width 1): the caller then traces the rays one by one.
    template <class Lanes>
    bool in_native_groups(int count, Lanes&& lanes) const {
        const auto groups = [&]<int W>() {
            for (int first = 0; first < count; first += W) lanes.template operator()<W>(first);
        };
        // With instances, 8 lanes at most: Embree 3.13.5's 16-wide (AVX-512) occlusion traversal
        // of instances did not return on our CPU (the render of tests/pov/instance_placements.yaml
        // hung inside rtcOccluded16), while its 8-wide one, on the same device, is right. Only the
        // grouping changes; every answer is recomputed in double, so the pixels do not.
        const int width = lane_width == 16 && !scene.instances.empty() ? 8 : lane_width;
        switch (width) {
            case 16:
                groups.template operator()<16>();
                return true;
            case 8:
                groups.template operator()<8>();
                return true;
            case 4:
                groups.template operator()<4>();
                return true;
            default:
                return false;
        }
    }

    /// Rays [first, first + W) of a packet through Embree's W-wide call. Every lane is written:
    /// a query, or an empty lane (set_empty_lane).
    template <int W>
    void intersect_lanes(QueryContext& context, const Ray* rays, const bool* query, int first, int count,
                         SurfaceHit* hits, bool* found) const {
        alignas(64) int valid[W];
        alignas(64) typename EmbreePacket<W>::RayHit packet;
        bool any = false;
        for (int lane = 0; lane < W; ++lane) {
            const int i = first + lane;
            const bool is_query = i < count && query[i];
            valid[lane] = is_query ? -1 : 0;
            any |= is_query;
            if (is_query) {
                context.start(i, rays[i]);
                set_lane(packet.ray, lane, rays[i], unsigned(i), frame);
            } else {
                set_empty_lane(packet.ray, lane, unsigned(i));
            }
            packet.hit.geomID[lane] = RTC_INVALID_GEOMETRY_ID;
            packet.hit.instID[0][lane] = RTC_INVALID_GEOMETRY_ID;
        }
        if (!any) return;
        EmbreePacket<W>::intersect(valid, rtc_scene, &context.embree, &packet);
        for (int lane = 0; lane < W; ++lane) {
            const int i = first + lane;
            if (!valid[lane]) continue;
            bool retry = false;
            found[i] = finish_hit(rays[i], packet.hit.instID[0][lane], packet.hit.geomID[lane], packet.hit.primID[lane],
                                  context.best_t[i], context.best_normal[i], context.best_tied[i], hits[i], retry);
            if (retry) found[i] = intersect_again(rays[i], hits[i]);
        }
    }

    void intersect_packet(const Ray* rays, const bool* active, int count, SurfaceHit* hits, bool* found) const {
        bool from_here[packet_size];
        active = without_rays_from_afar(rays, active, count, from_here,
                                        [&](int i) { found[i] = intersect_from_afar(rays[i], hits[i]); });
        // One ray (a refracted path) goes through Embree's single-ray traversal: a W-wide packet
        // with one lane in use walks the same nodes at W lanes' cost.
        if (count == 1) {
            if (active[0]) found[0] = intersect(rays[0], hits[0]);
            embree_error.throw_if_failed("while tracing rays");
            return;
        }
        QueryContext context(rays, active, count, true);
        const bool traced = in_native_groups(
            count, [&]<int W>(int first) { intersect_lanes<W>(context, rays, active, first, count, hits, found); });
        if (!traced)
            for (int i = 0; i < count; ++i)
                if (active[i]) found[i] = intersect(rays[i], hits[i]);
        embree_error.throw_if_failed("while tracing rays");
    }

    bool occluded_by_plane(const Ray& ray) const {
        for (const Plane& plane : scene.planes) {
            ShapeHit hit;
            if (intersect_plane(plane, ray, ray.t_min, ray.t_max, hit)) return true;
        }
        return false;
    }

    /// A shadow ray's triangle candidates are decided by the double test as Embree meets them
    /// (triangle_filter): the first it accepts ends the search, so the filter is called about
    /// once per blocked ray. With exact_range the meshes carry the filter themselves.
    RTCFilterFunctionN shadow_filter() const { return frame.exact_range ? nullptr : triangle_filter; }

    /// `active`, unless some of those rays starts_afar: each of them is answered by `alone(i)`
    /// and the others' flags copied to `kept`, which is returned. Only rays from a plane's far
    /// hits take that path; every other ray's packet is the same.
    template <class Alone>
    const bool* without_rays_from_afar(const Ray* rays, const bool* active, int count, bool* kept,
                                       Alone&& alone) const {
        bool any = false;
        for (int i = 0; i < count; ++i) any |= active[i] && starts_afar(rays[i]);
        if (!any) return active;
        for (int i = 0; i < count; ++i) {
            kept[i] = active[i] && !starts_afar(rays[i]);
            if (active[i] && !kept[i]) alone(i);
        }
        return kept;
    }

    bool occluded(const Ray& ray) const {
        if (occluded_by_plane(ray)) return true;
        if (starts_afar(ray)) {
            Ray near;
            double skipped = 0;
            return toward_finite_shapes(ray, near, skipped) && near.t_max > near.t_min && occluded_in_bvh(near);
        }
        return occluded_in_bvh(ray);
    }

    /// Embree's answer for a shadow ray, the planes aside.
    bool occluded_in_bvh(const Ray& ray) const {
        QueryContext context(&ray, nullptr, 1, false);
        context.embree.filter = shadow_filter();
        RTCRay r = make_embree_ray(ray, 0, frame);
        rtcOccluded1(rtc_scene, &context.embree, &r);
        return r.tfar < 0;
    }

    /// Shadow rays [first, first + W) through Embree's W-wide call; every lane is written.
    template <int W>
    void occluded_lanes(QueryContext& context, const Ray* rays, const bool* query, int first, int count,
                        bool* blocked) const {
        alignas(64) int valid[W];
        alignas(64) typename EmbreePacket<W>::Rays packet;
        bool any = false;
        for (int lane = 0; lane < W; ++lane) {
            const int i = first + lane;
            const bool is_query = i < count && query[i];
            valid[lane] = is_query ? -1 : 0;
            any |= is_query;
            if (is_query)
                set_lane(packet, lane, rays[i], unsigned(i), frame);
            else
                set_empty_lane(packet, lane, unsigned(i));
        }
        if (!any) return;
        EmbreePacket<W>::occluded(valid, rtc_scene, &context.embree, &packet);
        for (int lane = 0; lane < W; ++lane)
            if (valid[lane]) blocked[first + lane] = packet.tfar[lane] < 0;
    }

    void occluded_packet(const Ray* rays, const bool* active, int count, bool* blocked) const {
        bool from_here[packet_size];
        active = without_rays_from_afar(rays, active, count, from_here, [&](int i) { blocked[i] = occluded(rays[i]); });
        if (count == 1) {  // one ray, as in intersect_packet
            if (active[0]) blocked[0] = occluded(rays[0]);
            embree_error.throw_if_failed("while tracing shadow rays");
            return;
        }
        // Planes first (no BVH): a ray a plane blocks needs no Embree query.
        bool query[packet_size];
        for (int i = 0; i < count; ++i) query[i] = active[i] && !(blocked[i] = occluded_by_plane(rays[i]));
        QueryContext context(rays, query, count, true);
        context.embree.filter = shadow_filter();
        const bool traced = in_native_groups(
            count, [&]<int W>(int first) { occluded_lanes<W>(context, rays, query, first, count, blocked); });
        if (!traced)
            for (int i = 0; i < count; ++i)
                if (query[i]) blocked[i] = occluded(rays[i]);
        embree_error.throw_if_failed("while tracing shadow rays");
    }
};

Accelerator::Accelerator(const Scene& scene, int threads)
    : Accelerator(scene, threads, embree_isa_from_environment()) {}
Accelerator::Accelerator(const Scene& scene, int threads, const std::string& isa)
    : m_impl(std::make_unique<Impl>(
          scene, threads > 0 ? threads : int(std::max(1u, std::thread::hardware_concurrency())), isa)) {}
int Accelerator::lane_width() const {
    return m_impl->lane_width;
}
const std::string& Accelerator::isa() const {
    return m_impl->isa;
}
Accelerator::~Accelerator() = default;
size_t Accelerator::peak_embree_bytes() const {
    return size_t(std::max<int64_t>(0, m_impl->memory.peak.load()));
}
size_t Accelerator::embree_bytes() const {
    return size_t(std::max<int64_t>(0, m_impl->memory.current.load()));
}
bool Accelerator::intersect(const Ray& ray, SurfaceHit& hit) const {
    return m_impl->intersect(ray, hit);
}
bool Accelerator::occluded(const Ray& ray) const {
    return m_impl->occluded(ray);
}

void Accelerator::intersect_packet(const Ray* rays, const bool* active, int count, SurfaceHit* hits,
                                   bool* found) const {
    m_impl->intersect_packet(rays, active, count, hits, found);
}
void Accelerator::occluded_packet(const Ray* rays, const bool* active, int count, bool* blocked) const {
    m_impl->occluded_packet(rays, active, count, blocked);
}

}  // namespace whitted
