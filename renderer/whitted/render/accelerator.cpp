// SPDX-License-Identifier: MIT
#include "whitted/render/accelerator.h"

#include "whitted/geometry/shapes.h"

#include <embree3/rtcore.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace whitted {
namespace {

enum class ShapeKind : uint32_t { triangles, spheres, boxes };

/// Embree's context, extended with the double-precision ray: user-geometry callbacks read it
/// back from the pointer Embree passes them, so spheres and boxes never see the float copy.
struct QueryContext {
    RTCIntersectContext embree;
    const Ray* ray = nullptr;
    double best_t = 0;  ///< nearest analytic hit so far (double), for intersect queries
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
    if (args->N != 1 || !args->valid[0]) return;  // we only issue single-ray queries
    const auto* geometry = static_cast<const AnalyticGeometry*>(args->geometryUserPtr);
    auto* context = reinterpret_cast<QueryContext*>(args->context);
    auto* rayhit = reinterpret_cast<RTCRayHit*>(args->rayhit);
    const double limit = std::min(context->best_t, double(rayhit->ray.tfar));
    ShapeHit hit;
    if (!intersect_analytic(*geometry, args->primID, *context->ray, limit, hit)) return;
    context->best_t = hit.t;
    // Round the float distance up so Embree keeps visiting boxes that may hold a closer hit.
    rayhit->ray.tfar = std::nextafter(float(hit.t), INFINITY);
    rayhit->hit.geomID = args->geomID;
    rayhit->hit.primID = args->primID;
    rayhit->hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rayhit->hit.u = rayhit->hit.v = 0;
    rayhit->hit.Ng_x = float(hit.normal.x);
    rayhit->hit.Ng_y = float(hit.normal.y);
    rayhit->hit.Ng_z = float(hit.normal.z);
}

void analytic_occluded(const RTCOccludedFunctionNArguments* args) {
    if (args->N != 1 || !args->valid[0]) return;
    const auto* geometry = static_cast<const AnalyticGeometry*>(args->geometryUserPtr);
    const auto* context = reinterpret_cast<const QueryContext*>(args->context);
    auto* ray = reinterpret_cast<RTCRay*>(args->ray);
    ShapeHit hit;
    if (intersect_analytic(*geometry, args->primID, *context->ray, context->ray->t_max, hit))
        ray->tfar = -INFINITY;  // Embree's mark for "occluded"
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

RTCRay make_embree_ray(const Ray& ray) {
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
    r.id = 0;
    r.flags = 0;
    return r;
}

Vec3 vertex(const TriangleMesh& mesh, uint32_t index) {
    const float* p = &mesh.positions[4 * size_t(index)];
    return {p[0], p[1], p[2]};
}

Vec3 vertex_normal(const TriangleMesh& mesh, uint32_t index) {
    const float* n = &mesh.normals[3 * size_t(index)];
    return {n[0], n[1], n[2]};
}

}  // namespace

struct Accelerator::Impl {
    const Scene& scene;
    std::string embree_error;  ///< first error Embree reported (see record_embree_error)
    RTCDevice device = nullptr;
    RTCScene rtc_scene = nullptr;
    // geomID → what it is: a mesh index, or the sphere/box user geometry.
    std::vector<ShapeKind> kinds;
    std::vector<uint32_t> mesh_of_geometry;
    AnalyticGeometry spheres{ShapeKind::spheres, nullptr};
    AnalyticGeometry boxes{ShapeKind::boxes, nullptr};

    explicit Impl(const Scene& s) : scene(s) {
        spheres.scene = boxes.scene = &scene;
        device = rtcNewDevice("verbose=0");
        if (!device) throw std::runtime_error("cannot create the Embree device");
        rtcSetDeviceErrorFunction(device, record_embree_error, &embree_error);
        rtc_scene = rtcNewScene(device);
        // Medium quality: for 1M triangles HIGH took 2.0 s to build against 0.2 s, for a few
        // percent faster traversal that a single frame cannot win back.
        rtcSetSceneBuildQuality(rtc_scene, RTC_BUILD_QUALITY_MEDIUM);
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

    bool intersect(const Ray& ray, SurfaceHit& out) const {
        QueryContext context;
        rtcInitIntersectContext(&context.embree);
        context.ray = &ray;
        context.best_t = ray.t_max;
        RTCRayHit rayhit;
        rayhit.ray = make_embree_ray(ray);
        rayhit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rayhit.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(rtc_scene, &context.embree, &rayhit);

        bool found = false;
        double t_max = ray.t_max;
        ShapeHit hit;
        if (rayhit.hit.geomID != RTC_INVALID_GEOMETRY_ID) {
            const unsigned geom = rayhit.hit.geomID, prim = rayhit.hit.primID;
            if (kinds[geom] == ShapeKind::triangles) {
                const TriangleMesh& mesh = scene.meshes[mesh_of_geometry[geom]];
                const uint32_t* index = &mesh.indices[3 * size_t(prim)];
                if (!intersect_triangle(vertex(mesh, index[0]), vertex(mesh, index[1]), vertex(mesh, index[2]), ray,
                                        ray.t_min, ray.t_max, hit)) {
                    // Float and double disagree on an edge: keep Embree's answer.
                    hit.t = rayhit.ray.tfar;
                    hit.u = rayhit.hit.u;
                    hit.v = rayhit.hit.v;
                    hit.normal = {rayhit.hit.Ng_x, rayhit.hit.Ng_y, rayhit.hit.Ng_z};
                }
                out.normal = triangle_normal(mesh, prim, hit);
                out.material = mesh.triangle_materials.empty() ? mesh.material : mesh.triangle_materials[prim];
            } else {
                const AnalyticGeometry& geometry = kinds[geom] == ShapeKind::spheres ? spheres : boxes;
                // The callback kept the exact distance; recompute up to it to get that hit's normal.
                if (!intersect_analytic(geometry, prim, ray, std::nextafter(context.best_t, INFINITY), hit)) {
                    hit.t = context.best_t;
                    hit.normal = {rayhit.hit.Ng_x, rayhit.hit.Ng_y, rayhit.hit.Ng_z};
                }
                out.normal = normalize(hit.normal);
                out.material =
                    geometry.kind == ShapeKind::spheres ? scene.spheres[prim].material : scene.boxes[prim].material;
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

    bool occluded(const Ray& ray) const {
        for (const Plane& plane : scene.planes) {
            ShapeHit hit;
            if (intersect_plane(plane, ray, ray.t_min, ray.t_max, hit)) return true;
        }
        QueryContext context;
        rtcInitIntersectContext(&context.embree);
        context.ray = &ray;
        context.best_t = ray.t_max;
        RTCRay r = make_embree_ray(ray);
        rtcOccluded1(rtc_scene, &context.embree, &r);
        return r.tfar < 0;
    }
};

Accelerator::Accelerator(const Scene& scene) : m_impl(std::make_unique<Impl>(scene)) {}
Accelerator::~Accelerator() = default;
bool Accelerator::intersect(const Ray& ray, SurfaceHit& hit) const {
    return m_impl->intersect(ray, hit);
}
bool Accelerator::occluded(const Ray& ray) const {
    return m_impl->occluded(ray);
}

}  // namespace whitted
