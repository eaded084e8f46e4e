// SPDX-License-Identifier: MIT
#include "whitted/render/accelerator.h"

#include "whitted/core/packet_array.h"
#include "whitted/geometry/shapes.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <thread>

namespace whitted {
namespace {

enum class ShapeKind : uint32_t { triangles, spheres, boxes };

/// Embree's context, extended with the double-precision rays of the query: user-geometry
/// callbacks read them back from the pointer Embree passes them (Embree's ray `id` is the index
/// into `rays`), so spheres and boxes never see the float copies.
struct QueryContext {
    /// `coherent`: the rays are neighbours (a packet), which Embree can traverse together.
    QueryContext(const Ray* query_rays, bool coherent) : rays(query_rays) {
        rtcInitIntersectContext(&embree);
        if (coherent) embree.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    }

    RTCIntersectContext embree;
    const Ray* rays = nullptr;
    /// Nearest analytic hit so far per ray (double), set by intersect queries before tracing,
    /// and its normal, so it is not computed twice (set with it).
    double best_t[Accelerator::packet_size];
    PacketArray<Vec3, Accelerator::packet_size> best_normal;
};

struct AnalyticGeometry {
    ShapeKind kind;
    const Scene* scene;
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
        const double limit = std::min(context->best_t[id], double(RTCRayN_tfar(rays, args->N, i)));
        ShapeHit hit;
        if (!intersect_analytic(*geometry, args->primID, context->rays[id], limit, hit)) continue;
        context->best_t[id] = hit.t;
        context->best_normal[id] = hit.normal;
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
        const Ray& ray = context->rays[RTCRayN_id(args->ray, args->N, i)];
        ShapeHit hit;
        if (intersect_analytic(*geometry, args->primID, ray, ray.t_max, hit))
            RTCRayN_tfar(args->ray, args->N, i) = -INFINITY;  // Embree's mark for "occluded"
    }
}

/// Embree calls this from C code, where an exception must not pass: keep the first message
/// and throw after the Embree call returns (check_embree).
void record_embree_error(void* user, RTCError code, const char* message) {
    auto* first_error = static_cast<std::string*>(user);
    if (code != RTC_ERROR_NONE && first_error->empty())
        *first_error = code == RTC_ERROR_OUT_OF_MEMORY
                           ? "out of memory while building the BVH"
                           : std::string("Embree: ") + (message ? message : "unknown error");
}

RTCRay make_embree_ray(const Ray& ray, unsigned id) {
    RTCRay r;
    r.org_x = float(ray.origin.x);
    r.org_y = float(ray.origin.y);
    r.org_z = float(ray.origin.z);
    r.dir_x = float(ray.direction.x);
    r.dir_y = float(ray.direction.y);
    r.dir_z = float(ray.direction.z);
    r.tnear = float(ray.t_min);
    r.tfar = float(ray.t_max);
    r.time = 0;
    r.mask = 0xFFFFFFFFu;
    r.id = id;
    r.flags = 0;
    return r;
}

/// Lane i of a 16-wide Embree packet; `id` = i, so callbacks find the double ray again.
void set_lane(RTCRay16& packet, int i, const Ray& ray) {
    packet.org_x[i] = float(ray.origin.x);
    packet.org_y[i] = float(ray.origin.y);
    packet.org_z[i] = float(ray.origin.z);
    packet.dir_x[i] = float(ray.direction.x);
    packet.dir_y[i] = float(ray.direction.y);
    packet.dir_z[i] = float(ray.direction.z);
    packet.tnear[i] = float(ray.t_min);
    packet.tfar[i] = float(ray.t_max);
    packet.time[i] = 0;
    packet.mask[i] = 0xFFFFFFFFu;
    packet.id[i] = unsigned(i);
    packet.flags[i] = 0;
}

Vec3 vertex(const TriangleMesh& mesh, uint32_t index) {
    const float* p = &mesh.positions[4 * size_t(index)];
    return {p[0], p[1], p[2]};
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

}  // namespace

struct Accelerator::Impl {
    const Scene& scene;
    std::string embree_error;  ///< first error Embree reported (see record_embree_error)
    MemoryCount memory;
    RTCDevice device = nullptr;
    RTCScene rtc_scene = nullptr;
    // geomID → what it is: a mesh index, or the sphere/box user geometry.
    std::vector<ShapeKind> kinds;
    std::vector<uint32_t> mesh_of_geometry;
    AnalyticGeometry spheres{ShapeKind::spheres, nullptr};
    AnalyticGeometry boxes{ShapeKind::boxes, nullptr};
    RTCBuildQuality quality = RTC_BUILD_QUALITY_MEDIUM;  ///< of the scene and its meshes (build_quality)

    Impl(const Scene& s, int threads) : scene(s) {
        spheres.scene = boxes.scene = &scene;
        // Embree gets the render's thread count (--threads): its setting limits the whole
        // process's TBB threads (with threads=1 the render ran at half speed), so the two must
        // agree.
        const std::string config = "verbose=0,threads=" + std::to_string(threads);
        device = rtcNewDevice(config.c_str());
        if (!device) throw std::runtime_error("cannot create the Embree device");
        rtcSetDeviceErrorFunction(device, record_embree_error, &embree_error);
        rtcSetDeviceMemoryMonitorFunction(device, count_embree_memory, &memory);
        rtc_scene = rtcNewScene(device);
        quality = build_quality();
        rtcSetSceneBuildQuality(rtc_scene, quality);
        for (uint32_t m = 0; m < scene.meshes.size(); ++m) add_mesh(m);
        if (!scene.spheres.empty()) add_analytic(spheres, scene.spheres.size());
        if (!scene.boxes.empty()) add_analytic(boxes, scene.boxes.size());
        rtcCommitScene(rtc_scene);
        if (!embree_error.empty()) {
            release();
            throw std::runtime_error(embree_error);
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
        size_t triangles = 0;
        for (const TriangleMesh& mesh : scene.meshes) triangles += mesh.triangle_count();
        const double camera_rays = double(scene.width) * scene.height * scene.samples * scene.samples;
        return double(triangles) > camera_rays / 4 ? RTC_BUILD_QUALITY_LOW : RTC_BUILD_QUALITY_MEDIUM;
    }

    void release() {
        if (rtc_scene) rtcReleaseScene(rtc_scene);
        if (device) rtcReleaseDevice(device);
        rtc_scene = nullptr;
        device = nullptr;
    }

    void add_mesh(uint32_t m) {
        const TriangleMesh& mesh = scene.meshes[m];
        RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
        // Shared buffers: Embree reads the scene's own arrays, no copy (positions are padded to 16 bytes).
        rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, mesh.positions.data(), 0,
                                   4 * sizeof(float), mesh.vertex_count());
        rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, mesh.indices.data(), 0,
                                   3 * sizeof(uint32_t), mesh.triangle_count());
        rtcSetGeometryBuildQuality(geometry, quality);  // Embree builds LOW only if both say so
        rtcCommitGeometry(geometry);
        const unsigned id = rtcAttachGeometry(rtc_scene, geometry);
        rtcReleaseGeometry(geometry);
        record(id, ShapeKind::triangles, m);
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

    /// The shading normal at a triangle hit: the face normal, or for smooth meshes the unit
    /// vertex normals blended by barycentric weight and renormalised, as POV-Ray's mesh2 does
    /// (it falls back to the face normal when the three vertex normals are equal).
    Vec3 triangle_normal(const TriangleMesh& mesh, uint32_t prim, const ShapeHit& hit) const {
        if (mesh.normals.empty()) return normalize(hit.normal);
        const uint32_t* index = &mesh.indices[3 * size_t(prim)];
        const Vec3 n0 = vertex_normal(mesh, index[0]), n1 = vertex_normal(mesh, index[1]),
                   n2 = vertex_normal(mesh, index[2]);
        const Vec3 d1 = n0 - n1, d2 = n0 - n2;
        if (dot(d1, d1) <= 1e-10 && dot(d2, d2) <= 1e-10) return normalize(hit.normal);
        const Vec3 blended = n0 * (1.0 - hit.u - hit.v) + n1 * hit.u + n2 * hit.v;
        const double len = length(blended);
        return len > 0 ? blended / len : normalize(hit.normal);
    }

    /// The exact hit for what Embree found on one ray (geom == invalid: nothing), then the planes.
    bool finish_hit(const Ray& ray, unsigned geom, unsigned prim, float u, float v, float t, const Vec3& embree_normal,
                    double best_t, const Vec3& best_normal, SurfaceHit& out) const {
        bool found = false;
        double t_max = ray.t_max;
        ShapeHit hit;
        if (geom != RTC_INVALID_GEOMETRY_ID) {
            if (kinds[geom] == ShapeKind::triangles) {
                const TriangleMesh& mesh = scene.meshes[mesh_of_geometry[geom]];
                const uint32_t* index = &mesh.indices[3 * size_t(prim)];
                if (!intersect_triangle(vertex(mesh, index[0]), vertex(mesh, index[1]), vertex(mesh, index[2]), ray,
                                        ray.t_min, ray.t_max, hit)) {
                    // Float and double disagree on an edge: keep Embree's answer.
                    hit.t = t;
                    hit.u = u;
                    hit.v = v;
                    hit.normal = embree_normal;
                }
                out.normal = triangle_normal(mesh, prim, hit);
                out.material = mesh.triangle_materials.empty() ? mesh.material : mesh.triangle_materials[prim];
            } else {
                // The callback computed this hit in double and kept it.
                hit.t = best_t;
                out.normal = normalize(best_normal);
                out.material =
                    kinds[geom] == ShapeKind::spheres ? scene.spheres[prim].material : scene.boxes[prim].material;
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
                out.normal = plane.normal;
                out.material = plane.material;
                found = true;
            }
        }
        if (found) out.point = ray.at(out.t);
        return found;
    }

    bool intersect(const Ray& ray, SurfaceHit& out) const {
        QueryContext context(&ray, false);
        context.best_t[0] = ray.t_max;
        RTCRayHit rayhit;
        rayhit.ray = make_embree_ray(ray, 0);
        rayhit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rayhit.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(rtc_scene, &context.embree, &rayhit);
        return finish_hit(ray, rayhit.hit.geomID, rayhit.hit.primID, rayhit.hit.u, rayhit.hit.v, rayhit.ray.tfar,
                          {rayhit.hit.Ng_x, rayhit.hit.Ng_y, rayhit.hit.Ng_z}, context.best_t[0],
                          context.best_normal[0], out);
    }

    void intersect_packet(const Ray* rays, const bool* active, int count, SurfaceHit* hits, bool* found) const {
        QueryContext context(rays, true);
        alignas(64) int valid[packet_size];
        alignas(64) RTCRayHit16 packet;
        for (int i = 0; i < packet_size; ++i) {
            valid[i] = (i < count && active[i]) ? -1 : 0;
            if (!valid[i]) continue;  // Embree reads only the valid lanes
            context.best_t[i] = rays[i].t_max;
            set_lane(packet.ray, i, rays[i]);
            packet.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
            packet.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
        }
        rtcIntersect16(valid, rtc_scene, &context.embree, &packet);
        for (int i = 0; i < count; ++i) {
            if (!active[i]) continue;
            found[i] = finish_hit(rays[i], packet.hit.geomID[i], packet.hit.primID[i], packet.hit.u[i], packet.hit.v[i],
                                  packet.ray.tfar[i], {packet.hit.Ng_x[i], packet.hit.Ng_y[i], packet.hit.Ng_z[i]},
                                  context.best_t[i], context.best_normal[i], hits[i]);
        }
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
        QueryContext context(&ray, false);
        RTCRay r = make_embree_ray(ray, 0);
        rtcOccluded1(rtc_scene, &context.embree, &r);
        return r.tfar < 0;
    }

    void occluded_packet(const Ray* rays, const bool* active, int count, bool* blocked) const {
        QueryContext context(rays, true);
        alignas(64) int valid[packet_size];
        alignas(64) RTCRay16 packet;
        int remaining = 0;
        for (int i = 0; i < packet_size; ++i) {
            const bool query = i < count && active[i] && !(blocked[i] = occluded_by_plane(rays[i]));
            valid[i] = query ? -1 : 0;
            remaining += query;
            if (query) set_lane(packet, i, rays[i]);  // Embree reads only the valid lanes
        }
        if (remaining == 0) return;
        rtcOccluded16(valid, rtc_scene, &context.embree, &packet);
        for (int i = 0; i < count; ++i)
            if (valid[i]) blocked[i] = packet.tfar[i] < 0;
    }
};

Accelerator::Accelerator(const Scene& scene, int threads)
    : m_impl(std::make_unique<Impl>(scene,
                                    threads > 0 ? threads : int(std::max(1u, std::thread::hardware_concurrency())))) {}
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
