// SPDX-License-Identifier: MIT
#include "whitted/render/accelerator.h"

#include "whitted/core/packet_array.h"
#include "whitted/geometry/shapes.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <deque>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>

namespace whitted {
namespace {

enum class ShapeKind : uint32_t { triangles, spheres, boxes, instances };

/// A ray taken into an instance's prototype space, in double. The direction is not
/// renormalised, so t along it is the world t: ranges and distances carry over unchanged.
Ray to_object_space(const Ray& ray, const Transform& object_to_world) {
    return {object_to_world.inverse_point(ray.origin), object_to_world.inverse_vector(ray.direction), ray.t_min,
            ray.t_max};
}

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
};

struct AnalyticGeometry {
    ShapeKind kind;
    const Scene* scene;
    Vec3 offset;  ///< Embree's coordinates are world minus this (Impl::choose_frame)
};

bool intersect_analytic(const AnalyticGeometry& geometry, unsigned prim, const Ray& ray, double t_max, ShapeHit& hit) {
    if (geometry.kind == ShapeKind::spheres)
        return intersect_sphere(geometry.scene->spheres[prim], ray, ray.t_min, t_max, hit);
    return intersect_box(geometry.scene->boxes[prim], ray, ray.t_min, t_max, hit);
}

void analytic_bounds(const RTCBoundsFunctionArguments* args) {
    const auto* geometry = static_cast<const AnalyticGeometry*>(args->geometryUserPtr);
    Vec3 lo, hi;
    if (geometry->kind == ShapeKind::spheres)
        world_bounds(geometry->scene->spheres[args->primID], lo, hi);
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
        const double limit = std::min(context->best_t[id], double(RTCRayN_tfar(rays, args->N, i)));
        // Overlapping boxes with coplanar faces can be met at the very same t, one of them on a
        // face the edge rule chose (a ray along one box's edge, inside another's top). POV-Ray
        // then shows the plain face: it tests the other box first, its bounding box being met
        // earlier, and keeps the first of equal hits (bench/generate.py --boxes 1000000, row
        // 383). So a plain hit at the same t replaces an edge-rule one, whatever the order here.
        const bool equal_may_win = context->best_edge_tie[id] && limit == context->best_t[id];
        ShapeHit hit;
        if (!intersect_analytic(*geometry, args->primID, context->rays[id],
                                equal_may_win ? std::nextafter(limit, INFINITY) : limit, hit))
            continue;
        if (equal_may_win && hit.t == limit && hit.edge_tie) continue;
        context->best_t[id] = hit.t;
        context->best_normal[id] = hit.normal;
        context->best_edge_tie[id] = hit.edge_tie;
        // Round the float distance up so Embree keeps visiting boxes that may hold a closer hit.
        RTCRayN_tfar(rays, args->N, i) = std::nextafter(float(hit.t), INFINITY);
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

Vec3 vertex(const TriangleMesh& mesh, uint32_t index) {
    const float* p = &mesh.positions[4 * size_t(index)];
    return {p[0], p[1], p[2]};
}

/// Embree's float test found `prim` of this mesh on some rays; each is kept only if its double
/// ray meets the triangle's plane within (t_min, t_max). Where Embree's coordinates are large
/// its float distances are off by more than the minimum distances (ulp(1e4) ≈ 1e-3, the shadow
/// window), so a surface could find itself again or a blocker at the end of the range be kept
/// or missed; the range is decided in double, as POV-Ray does, and Embree is handed a wider one
/// (EmbreeFrame::exact_range). Only the range: whether the ray passes inside the triangle's
/// edges stays Embree's decision, so a ray through an edge two triangles share is decided as
/// before.
/// What triangle_filter needs of a mesh: its triangles and, for a prototype's mesh, the
/// transform of each instance (by Embree's instance geomID), to take the ray into its space.
struct TriangleGeometry {
    const TriangleMesh* mesh = nullptr;
    const std::vector<const Transform*>* instance_transforms = nullptr;
};

void triangle_filter(const RTCFilterFunctionNArguments* args) {
    const auto* geometry = static_cast<const TriangleGeometry*>(args->geometryUserPtr);
    const TriangleMesh* mesh = geometry->mesh;
    const auto* context = reinterpret_cast<const QueryContext*>(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] != -1) continue;
        const unsigned id = RTCRayN_id(args->ray, args->N, i);
        if (!context->is_query(id)) continue;
        const unsigned inst = RTCHitN_instID(args->hit, args->N, i, 0);
        const Ray ray = inst == RTC_INVALID_GEOMETRY_ID
                            ? context->rays[id]
                            : to_object_space(context->rays[id], *(*geometry->instance_transforms)[inst]);
        const uint32_t* index = &mesh->indices[3 * size_t(RTCHitN_primID(args->hit, args->N, i))];
        ShapeHit hit;
        if (!hit_triangle_plane(vertex(*mesh, index[0]), vertex(*mesh, index[1]), vertex(*mesh, index[2]), ray, hit) ||
            !(hit.t > ray.t_min && hit.t < ray.t_max))
            args->valid[i] = 0;
    }
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

    float t_min(const Ray& ray) const { return exact_range ? 0.0f : float(ray.t_min); }
    float t_max(const Ray& ray) const {
        return exact_range ? std::nextafter(float(ray.t_max * (1 + 1e-6)), INFINITY) : float(ray.t_max);
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
    AnalyticGeometry spheres{ShapeKind::spheres, nullptr, {}};
    AnalyticGeometry boxes{ShapeKind::boxes, nullptr, {}};
    RTCBuildQuality quality = RTC_BUILD_QUALITY_MEDIUM;  ///< of the scene and its meshes (build_quality)
    int lane_width = 1;                                  ///< rays per Embree packet call (native_lane_width)
    /// Embree works in float in a frame of its own (choose_frame). Rays, vertices and bounds
    /// are shifted in double before they are rounded, so a scene far from the origin keeps
    /// float's precision relative to its own size; every answer is still recomputed in world
    /// double from the scene's own data.
    EmbreeFrame frame;

    Impl(const Scene& s, int threads, const std::string& instruction_set) : scene(s), isa(instruction_set) {
        spheres.scene = boxes.scene = &scene;
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
        rtcSetSceneFlags(rtc_scene, RTC_SCENE_FLAG_ROBUST);
        frame = choose_frame();
        spheres.offset = boxes.offset = frame.offset;
        for (uint32_t m = 0; m < scene.meshes.size(); ++m) {
            const unsigned id = add_mesh(rtc_scene, scene.meshes[m], Vec3(0.0) - frame.offset);
            record(id, ShapeKind::triangles, m);
        }
        add_instances();
        if (!scene.spheres.empty()) add_analytic(spheres, scene.spheres.size());
        if (!scene.boxes.empty()) add_analytic(boxes, scene.boxes.size());
        rtcCommitScene(rtc_scene);
        try {
            embree_error.throw_if_failed("while building the BVH");
        } catch (...) {
            release();
            throw;
        }
    }

    ~Impl() { release(); }

    /// A BVH is built once per triangle and traversed once per ray. HIGH quality took 2.0 s to
    /// build 1M triangles against 0.2 s for MEDIUM, for a few percent faster traversal that a
    /// single frame cannot win back. On the 1M-triangle anchor (2 threads, 1280x960) LOW built
    /// in 0.06 s against 0.15 s and rendered 0.02 s (10 %) slower; on the 100k-triangle one the
    /// two came out even, and on the 100 spheres LOW rendered 15-25 % slower (docs/performance.md).
    /// So LOW once the triangles outnumber a quarter of the camera rays. The BVH only changes
    /// the order in which candidates are met: the 1M-triangle image came out bit-identical.
    RTCBuildQuality build_quality() const {
        const size_t triangles = scene.triangle_count();
        const double camera_rays = double(scene.width) * scene.height * scene.samples * scene.samples;
        return double(triangles) > camera_rays / 4 ? RTC_BUILD_QUALITY_LOW : RTC_BUILD_QUALITY_MEDIUM;
    }

    /// The frame: centred on the bounds of the scene's finite shapes when they lie further from
    /// the origin than their half extent (the shifted coordinates then keep at least one more
    /// bit), otherwise the world's, and Embree reads the meshes' own arrays. Where the shifted
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
                lo = min(lo, vertex(mesh, i));
                hi = max(hi, vertex(mesh, i));
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

    /// Attaches a triangle mesh to `target` with its vertices moved by `shift` (Embree's
    /// coordinates: the world minus the frame's offset; a prototype's own, unshifted). Returns
    /// its geomID there.
    unsigned add_mesh(RTCScene target, const TriangleMesh& mesh, const Vec3& shift,
                      const std::vector<const Transform*>* transforms = nullptr) {
        RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
        if (shift == Vec3(0.0)) {
            // Shared buffers: Embree reads the scene's own arrays, no copy (positions are padded to 16 bytes).
            rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, mesh.positions.data(), 0,
                                       4 * sizeof(float), mesh.vertex_count());
        } else {
            auto* local = static_cast<float*>(rtcSetNewGeometryBuffer(
                geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 4 * sizeof(float), mesh.vertex_count()));
            for (uint32_t i = 0; i < mesh.vertex_count(); ++i) {
                const Vec3 p = vertex(mesh, i) + shift;
                local[4 * size_t(i)] = float(p.x);
                local[4 * size_t(i) + 1] = float(p.y);
                local[4 * size_t(i) + 2] = float(p.z);
                local[4 * size_t(i) + 3] = 0.0f;
            }
        }
        rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, mesh.indices.data(), 0,
                                   3 * sizeof(uint32_t), mesh.triangle_count());
        rtcSetGeometryBuildQuality(geometry, quality);  // Embree builds LOW only if both say so
        if (frame.exact_range) {
            filter_data.push_back({&mesh, transforms});
            rtcSetGeometryUserData(geometry, &filter_data.back());
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
        for (const Prototype& prototype : scene.prototypes) {
            RTCScene prototype_scene = rtcNewScene(device);
            prototype_scenes.push_back(prototype_scene);
            rtcSetSceneBuildQuality(prototype_scene, quality);
            rtcSetSceneFlags(prototype_scene, RTC_SCENE_FLAG_ROBUST);  // watertight, as the world's
            for (const TriangleMesh& mesh : prototype.meshes)
                add_mesh(prototype_scene, mesh, Vec3(0.0), &instance_transforms);
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
    /// barycentric weight and renormalised, as POV-Ray's mesh2 does. False where the triangle
    /// is shaded flat, with its face normal: a mesh without normals, three equal vertex normals
    /// (except under render.convention: course) or a blend of length 0.
    bool blended_normal(const TriangleMesh& mesh, uint32_t prim, const ShapeHit& hit, Vec3& out) const {
        if (mesh.normals.empty()) return false;
        const uint32_t* index = &mesh.indices[3 * size_t(prim)];
        const Vec3 n0 = vertex_normal(mesh, index[0]), n1 = vertex_normal(mesh, index[1]),
                   n2 = vertex_normal(mesh, index[2]);
        const Vec3 d1 = n0 - n1, d2 = n0 - n2;
        // The course's convention interpolates always, as its ray tracer does.
        if (dot(d1, d1) <= 1e-10 && dot(d2, d2) <= 1e-10 && scene.convention != Convention::course) return false;
        const Vec3 blended = n0 * (1.0 - hit.u - hit.v) + n1 * hit.u + n2 * hit.v;
        const double len = length(blended);
        if (!(len > 0)) return false;
        out = blended / len;
        return true;
    }

    /// The exact hit on triangle `prim` of `mesh` for a candidate Embree found (u, v, t and
    /// its normal: Embree's, for a ray parallel to the plane in double). False with `retry`
    /// set when the double ray meets its plane outside the range (see finish_hit).
    static bool exact_triangle_hit(const TriangleMesh& mesh, unsigned prim, const Ray& ray, float u, float v, float t,
                                   const Vec3& embree_normal, ShapeHit& hit, bool& retry) {
        const uint32_t* index = &mesh.indices[3 * size_t(prim)];
        const Vec3 v0 = vertex(mesh, index[0]), v1 = vertex(mesh, index[1]), v2 = vertex(mesh, index[2]);
        const bool inside = intersect_triangle(v0, v1, v2, ray, ray.t_min, ray.t_max, hit);
        if (!inside && hit_triangle_plane(v0, v1, v2, ray, hit) && !(hit.t > ray.t_min && hit.t < ray.t_max)) {
            retry = true;
            return false;
        }
        if (!inside && !hit_triangle_plane(v0, v1, v2, ray, hit)) {
            // Float and double disagree on an edge: the hit is taken where the double ray
            // meets the triangle's plane (hit_triangle_plane), not from Embree's float
            // numbers, which differ in the last bits from one instruction set to another.
            // Only a ray parallel to the plane in double is left with Embree's answer.
            hit.t = t;
            hit.u = u;
            hit.v = v;
            hit.normal = embree_normal;
        }
        return true;
    }

    /// The exact hit for what Embree found on one ray (geom == invalid: nothing), then the planes.
    /// `retry` is set, and nothing is found, when Embree's nearest candidate is a triangle that
    /// the double ray meets outside its range: a ray leaving a surface at a grazing angle can
    /// start on (or within rounding of) a neighbouring triangle's plane, which Embree's float
    /// distance puts past t_min while in double it is 0, behind the ray or too near. Such a
    /// candidate is no hit; the caller traces the ray again beyond it (intersect_beyond).
    /// `inst`: Embree's instance geomID when the candidate is a prototype's triangle (`geom` is
    /// then its mesh in the prototype), else RTC_INVALID_GEOMETRY_ID.
    bool finish_hit(const Ray& ray, unsigned inst, unsigned geom, unsigned prim, float u, float v, float t,
                    const Vec3& embree_normal, double best_t, const Vec3& best_normal, SurfaceHit& out,
                    bool& retry) const {
        retry = false;
        bool found = false;
        double t_max = ray.t_max;
        ShapeHit hit;
        if (geom != RTC_INVALID_GEOMETRY_ID) {
            if (inst != RTC_INVALID_GEOMETRY_ID) {
                // A prototype's triangle, tested in double in the prototype's space (Embree's
                // normal is in that space too), its normals then taken to the world with the
                // inverse transpose. A plain copy's face normal is (v1 − v0) × (v2 − v0) of the
                // world vertices, which is the transformed one times the sign of the determinant.
                const Instance& instance = scene.instances[mesh_of_geometry[inst]];
                const Transform& to_world = instance.object_to_world;
                const TriangleMesh& mesh = scene.prototypes[instance.prototype].meshes[geom];
                if (!exact_triangle_hit(mesh, prim, to_object_space(ray, to_world), u, v, t, embree_normal, hit, retry))
                    return false;
                const double handedness = to_world.determinant() < 0 ? -1.0 : 1.0;
                out.geometric_normal = normalize(to_world.apply_normal(hit.normal)) * handedness;
                Vec3 smooth;
                out.normal = blended_normal(mesh, prim, hit, smooth) ? normalize(to_world.apply_normal(smooth))
                                                                     : out.geometric_normal;
                out.material = instance.material != Instance::no_material ? instance.material
                               : mesh.triangle_materials.empty()          ? mesh.material
                                                                          : mesh.triangle_materials[prim];
                out.object = instance.object;
            } else if (kinds[geom] == ShapeKind::triangles) {
                const TriangleMesh& mesh = scene.meshes[mesh_of_geometry[geom]];
                if (!exact_triangle_hit(mesh, prim, ray, u, v, t, embree_normal, hit, retry)) return false;
                out.geometric_normal = normalize(hit.normal);
                Vec3 smooth;
                out.normal = blended_normal(mesh, prim, hit, smooth) ? smooth : out.geometric_normal;
                out.material = mesh.triangle_materials.empty() ? mesh.material : mesh.triangle_materials[prim];
                out.object = mesh.object;
            } else {
                // The callback computed this hit in double and kept it.
                hit.t = best_t;
                out.normal = out.geometric_normal = normalize(best_normal);
                if (kinds[geom] == ShapeKind::spheres)
                    out.material = scene.spheres[prim].material, out.object = scene.spheres[prim].object;
                else
                    out.material = scene.boxes[prim].material, out.object = scene.boxes[prim].object;
            }
            out.t = hit.t;
            t_max = hit.t;
            found = true;
        }
        for (const Plane& plane : scene.planes) {
            ShapeHit plane_hit;
            if (intersect_plane(plane, ray, ray.t_min, t_max, plane_hit)) {
                t_max = plane_hit.t;
                out.t = plane_hit.t;
                out.normal = out.geometric_normal = plane.normal;
                out.material = plane.material;
                out.object = plane.object;
                found = true;
            }
        }
        if (found) out.point = ray.at(out.t);
        return found;
    }

    bool intersect(const Ray& ray, SurfaceHit& out) const { return intersect_beyond(ray, -1.0f, out); }

    /// intersect(), with Embree's float range starting past `rejected` (a candidate distance
    /// finish_hit refused; negative: none). Embree returns its nearest candidate, so every
    /// other candidate lies at or past that float distance, and starting just past it loses
    /// none but exact ties. The double range, and the planes, are still decided against `ray`.
    bool intersect_beyond(const Ray& ray, float rejected, SurfaceHit& out) const {
        for (int attempt = 0;; ++attempt) {
            QueryContext context(&ray, nullptr, 1, false);
            context.best_t[0] = ray.t_max;
            context.best_edge_tie[0] = false;
            RTCRayHit rayhit;
            rayhit.ray = make_embree_ray(ray, 0, frame);
            if (rejected >= 0) rayhit.ray.tnear = std::max(rayhit.ray.tnear, std::nextafter(rejected, INFINITY));
            rayhit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
            rayhit.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
            rtcIntersect1(rtc_scene, &context.embree, &rayhit);
            bool retry = false;
            const bool found =
                finish_hit(ray, rayhit.hit.instID[0], rayhit.hit.geomID, rayhit.hit.primID, rayhit.hit.u, rayhit.hit.v,
                           rayhit.ray.tfar, {rayhit.hit.Ng_x, rayhit.hit.Ng_y, rayhit.hit.Ng_z}, context.best_t[0],
                           context.best_normal[0], out, retry);
            // A bounded number of refusals in a row (a fan of grazing neighbours); past it the
            // planes alone answer, as if the triangles had been missed.
            if (!retry) return found;
            rejected = rayhit.ray.tfar;
            if (attempt == max_refused_candidates)
                return finish_hit(ray, RTC_INVALID_GEOMETRY_ID, RTC_INVALID_GEOMETRY_ID, 0, 0, 0, 0, {}, 0, {}, out,
                                  retry);
        }
    }
    static constexpr int max_refused_candidates = 8;

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
                context.best_t[i] = rays[i].t_max;
                context.best_edge_tie[i] = false;
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
                                  packet.hit.u[lane], packet.hit.v[lane], packet.ray.tfar[lane],
                                  {packet.hit.Ng_x[lane], packet.hit.Ng_y[lane], packet.hit.Ng_z[lane]},
                                  context.best_t[i], context.best_normal[i], hits[i], retry);
            if (retry) found[i] = intersect_beyond(rays[i], packet.ray.tfar[lane], hits[i]);
        }
    }

    void intersect_packet(const Ray* rays, const bool* active, int count, SurfaceHit* hits, bool* found) const {
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

    bool occluded(const Ray& ray) const {
        if (occluded_by_plane(ray)) return true;
        QueryContext context(&ray, nullptr, 1, false);
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
        // Planes first (no BVH): a ray a plane blocks needs no Embree query.
        bool query[packet_size];
        for (int i = 0; i < count; ++i) query[i] = active[i] && !(blocked[i] = occluded_by_plane(rays[i]));
        QueryContext context(rays, query, count, true);
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
