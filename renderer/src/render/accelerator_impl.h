// SPDX-License-Identifier: MIT
#pragma once

// The accelerator's inside, shared by the files that each hold one of its concerns:
//
// * accelerator_device.cpp: the Embree device, its instruction set, errors and memory;
// * accelerator_frame.cpp: Embree's float frame (far scenes) and the reach Whitted renders;
// * accelerator_build.cpp: the BVH: widened triangles, instances, the analytic shapes;
// * accelerator_exact.cpp: the decision in double on what Embree proposes, one ray at a time;
// * accelerator_packets.cpp: the same queries for packets, one template for every width;
// * accelerator.cpp: Accelerator itself, handing each query to Impl.
//
// Shading normals and materials of a hit come from the shapes (geometry/shapes.h), and
// POV-Ray's own rules from compat/povray/.

#include "compat/povray.h"
#include "core/packet_array.h"
#include "geometry/shapes.h"
#include "render/accelerator.h"
#include "render/accelerator_device.h"

#include <embree3/rtcore.h>

#include <cmath>
#include <cstdint>
#include <deque>
#include <memory>
#include <new>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <sys/mman.h>

#include <tbb/collaborative_call_once.h>

namespace whitted {
namespace accel {

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
    /// Set for nearest_triangle's query: its filter gathers the triangles the double test
    /// accepts there, and the analytic callbacks stand aside.
    struct TriangleCandidates* gathering = nullptr;

    /// A query starts with nothing held, up to the ray's own limit.
    void start(int id, const Ray& ray) {
        best_t[id] = ray.t_max;
        best_edge_tie[id] = false;
        best_tied[id] = false;
    }
};

/// A triangle the double test accepted (nearest_triangle): its distance, its object and where
/// it is, as finish_hit takes it (Embree's instance geomID or RTC_INVALID_GEOMETRY_ID, geomID,
/// primID).
struct TriangleCandidate {
    double t;
    uint32_t object;
    unsigned inst, geom, prim;
    bool operator<(const TriangleCandidate& o) const {
        return std::tie(t, object, inst, geom, prim) < std::tie(o.t, o.object, o.inst, o.geom, o.prim);
    }
};

/// The triangles gathered by gather_triangles for one ray: the nearest `capacity` of them, a
/// set that does not depend on the order Embree meets them in.
struct TriangleCandidates {
    static constexpr int capacity = 16;
    TriangleCandidate nearest[capacity];
    int count = 0;
    /// Where to find an instance's object: Scene::instances by Impl::mesh_of_geometry.
    const Scene* scene = nullptr;
    const std::vector<uint32_t>* mesh_of_geometry = nullptr;
    void add(const TriangleCandidate& candidate);
};

/// A part of a cone along its axis, one primitive of Embree's (Impl::add_cone_segments): a long
/// slanted cylinder's axis-aligned box is mostly empty, its parts' boxes far less so. Each part
/// tests the whole cone, the same double test, and keeps only the hit whose distance along the
/// axis (ShapeHit::u) is its own: so every hit belongs to exactly one part, as it did to the
/// one cone.
struct ConeSegment {
    uint32_t cone;
    double s_begin, s_end;  ///< the stretch along the axis that the part's box holds
    /// The hits it keeps: owns_from ≤ s < owns_to, which is s_begin ≤ s < s_end but from −∞ for
    /// the first part and to +∞ for the last.
    double owns_from, owns_to;
};

struct AnalyticGeometry {
    ShapeKind kind;
    const Scene* scene;
    Vec3 offset;                        ///< Embree's coordinates are world minus this (Impl::choose_frame)
    std::vector<ConeSegment> segments;  ///< cones: Embree's primitives, parts of Scene::cones
};

/// What triangle_filter needs of a mesh: its triangles, how they are decided
/// (MeshAsPovray) and, for a prototype's mesh, the transform of each instance (by
/// Embree's instance geomID), to take the ray into its space.
struct TriangleGeometry {
    const TriangleMesh* mesh = nullptr;
    bool as_povray = false;
    const std::vector<const Transform*>* instance_transforms = nullptr;
};

/// An array for Embree to read (the widened corners, their indices), in anonymous memory that
/// the kernel maps in whole as it is made (MAP_POPULATE) and zeroes. It is written once, front
/// to back, right after: touched a page at a time instead, every 4 KiB is a page fault, and on
/// the virtual machines of docs/performance.md the faults cost more than the writing. Where the
/// caller has chosen huge pages (use_huge_pages: where a 4 KiB page's first write traps to the
/// hypervisor even after the kernel mapped it), it asks for them instead and is left to fault:
/// one fault per 2 MiB.
template <class T>
class MappedArray {
public:
    MappedArray() = default;
    /// `count` elements and `padding` bytes after them (zero, as the whole mapping is).
    MappedArray(size_t count, size_t padding) : m_bytes(count * sizeof(T) + padding) {
        if (m_bytes == 0) return;
        const bool huge = huge_pages_in_use();
        void* memory = mmap(nullptr, m_bytes, PROT_READ | PROT_WRITE,
                            MAP_PRIVATE | MAP_ANONYMOUS | (huge ? 0 : MAP_POPULATE), -1, 0);
        if (memory == MAP_FAILED) throw std::bad_alloc();
        if (huge) madvise(memory, m_bytes, MADV_HUGEPAGE);
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

/// Embree's callbacks (accelerator_exact.cpp): the bounds and the double tests of the spheres,
/// boxes and cones (user geometry), and the double decision on a triangle candidate.
void analytic_bounds(const RTCBoundsFunctionArguments* args);
/// A sphere's, box's or part of a cone's (ConeSegment: `part`) double test for ray `id` of
/// `context`, as Embree's candidate, or as one of the shapes a scene without a BVH tests on
/// every ray: true when its hit is now the one held (QueryContext::best_t ...), `tfar`
/// (Embree's float end of the ray) then moved just past it.
bool consider_analytic(const AnalyticGeometry& geometry, unsigned part, QueryContext& context, unsigned id,
                       float& tfar);
/// Whether that shape blocks the shadow ray `ray`.
bool analytic_blocks(const AnalyticGeometry& geometry, unsigned part, const Ray& ray);
void analytic_intersect(const RTCIntersectFunctionNArguments* args);
void analytic_occluded(const RTCOccludedFunctionNArguments* args);
void triangle_filter(const RTCFilterFunctionNArguments* args);
void gather_triangles(const RTCFilterFunctionNArguments* args);

}  // namespace accel

struct Accelerator::Impl {
    const Scene& scene;
    std::string isa;
    accel::EmbreeError embree_error;  ///< see record_embree_error
    accel::MemoryCount memory;
    RTCDevice device = nullptr;
    RTCScene rtc_scene = nullptr;
    // geomID → what it is: a mesh index, the sphere/box user geometry, or an instance index.
    std::vector<accel::ShapeKind> kinds;
    std::vector<uint32_t> mesh_of_geometry;
    /// One Embree scene (one BVH) per prototype, placed by the instances; within each, a mesh's
    /// geomID is its index in Prototype::meshes.
    std::vector<RTCScene> prototype_scenes;
    /// Top-level geomID → the instance's transform (null for other geometry), for triangle_filter.
    std::vector<const Transform*> instance_transforms;
    std::deque<accel::TriangleGeometry> filter_data;  ///< triangle_filter's user data, one per mesh (stable addresses)
    /// 0, 1, 2, ... : every mesh's index buffer, its widened triangles having corners of their
    /// own (widen_triangles), for as many triangles as the largest mesh has.
    accel::MappedArray<uint32_t> corner_indices;
    std::vector<accel::MappedArray<float>> widened_corners;  ///< each mesh's (widen_triangles), for Embree
    /// How POV-Ray holds each mesh of the world, and of each prototype.
    std::vector<MeshAsPovray> world_povray;
    std::vector<std::vector<MeshAsPovray>> prototype_povray;
    accel::AnalyticGeometry spheres{accel::ShapeKind::spheres, nullptr, {}, {}};
    accel::AnalyticGeometry boxes{accel::ShapeKind::boxes, nullptr, {}, {}};
    accel::AnalyticGeometry cones{accel::ShapeKind::cones, nullptr, {}, {}};
    RTCBuildQuality quality = RTC_BUILD_QUALITY_MEDIUM;  ///< of the scene and its meshes (build_quality)
    int lane_width = 1;                                  ///< rays per Embree packet call (native_lane_width)
    /// A packet with at most this many rays in use traces them one by one (few_lanes): half the
    /// lane width where the scene has shapes of its own (spheres, boxes, cones: their test, the
    /// callback Embree calls with a packet, goes through its lanes one by one anyway), a
    /// quarter where it has triangles only.
    int single_ray_lanes = 1;
    /// Embree works in float in a frame of its own (choose_frame). Rays, vertices and bounds
    /// are shifted in double before they are rounded, so a scene far from the origin keeps
    /// float's precision relative to its own size; every answer is still recomputed in world
    /// double from the scene's own data.
    accel::EmbreeFrame frame;
    /// POV-Ray's order of testing the spheres and boxes, for rays that meet two at exactly the
    /// same t (tie_order); built on the first such ray, so a scene without ties never pays (a
    /// million equal cubes pay 0.5-0.8 s and 200 MB, docs/performance.md).
    mutable tbb::collaborative_once_flag tie_order_built;
    mutable std::unique_ptr<PovrayTestOrder> tie_order_data;

    /// A scene of at most most_shapes_without_bvh spheres, boxes and cones, and nothing else
    /// but planes, on few rays, has no BVH and no Embree device (worth_no_bvh): every ray tests every shape
    /// (trace, occluded_in_bvh), with the decisions Embree's callbacks make
    /// (consider_analytic, analytic_blocks), which do not depend on the order the shapes are
    /// met in. `direct` lists them: each kind's geomID, as `kinds` knows it, and its count.
    static constexpr size_t most_shapes_without_bvh = 16;
    static constexpr double most_tests_without_bvh = 1 << 21;  ///< shapes × rays (worth_no_bvh)
    struct DirectShapes {
        unsigned id;
        const accel::AnalyticGeometry* geometry;
        unsigned parts;
    };
    std::vector<DirectShapes> direct;
    bool without_bvh = false;

    // The build (accelerator_build.cpp).
    Impl(const Scene& s, int threads, const std::string& instruction_set, BvhChoice bvh);
    bool worth_no_bvh() const;
    ~Impl() { release(); }
    void release();
    RTCBuildQuality build_quality() const;
    /// Embree's float error, in units of 2^-24 (reach + span), that triangles are widened by.
    static constexpr double margin_ulps = 16;
    double world_triangle_margin() const;
    unsigned add_mesh(RTCScene target, const TriangleMesh& mesh, bool as_povray, const Vec3& shift, double margin,
                      const std::vector<const Transform*>* transforms = nullptr);
    void add_instances();
    void add_analytic(accel::AnalyticGeometry& user, size_t count);
    void add_cone_segments();
    void record(unsigned id, accel::ShapeKind kind, uint32_t mesh);

    // The frame and the reach (accelerator_frame.cpp).
    /// How far from the origin a finite shape may reach (check_reach).
    static constexpr double max_reach = 1e15;
    /// Where rays may start in a prototype's own space (check_reach): a tenth of Embree's limit.
    static constexpr double max_instance_origin = 1e17;
    void check_reach();
    accel::EmbreeFrame choose_frame() const;
    /// check_reach's bounds, each on every axis: every finite shape lies within
    /// finite_shapes_reach of the origin, and its rule holds for rays starting within rule_origins.
    double finite_shapes_reach = 0, rule_origins = 0;
    /// Whether the scene has what the rule is for: an instance, or a sphere, box or cone with a
    /// transform. Without one, Embree takes the world's rays as they are (a plane's far hits stay
    /// well within its 1.8e19), and every answer is the double test's on the ray itself.
    bool rule_applies = false;
    bool starts_afar(const Ray& ray) const;
    bool toward_finite_shapes(const Ray& ray, Ray& near, double& skipped) const;

    // The exact decision, one ray at a time (accelerator_exact.cpp).
    const PovrayTestOrder& tie_order() const;
    bool finish_hit(const Ray& ray, unsigned inst, unsigned geom, unsigned prim, double best_t, const Vec3& best_normal,
                    bool tied, HitParts parts, SurfaceHit& out, bool& retry) const;
    void nearest_triangle(const Ray& ray, double t, unsigned& inst, unsigned& geom, unsigned& prim) const;
    double triangle_stray(double t) const;
    bool may_meet_another_object(const Ray& ray, unsigned top, double t) const;

    /// Where a triangle's hit may tie with another object's triangle (find_tie_neighbours): for
    /// each top-level geomID (a mesh of the world or an instance), the world boxes of the other
    /// such geometries that come within 2 tie_neighbour_margin of its own, from
    /// tie_neighbours[tie_neighbours_start[id]] up to tie_neighbours[tie_neighbours_start[id + 1]].
    struct WorldBox {
        Vec3 lo, hi;
    };
    std::vector<uint32_t> tie_neighbours_start;
    std::vector<WorldBox> tie_neighbours;
    double tie_neighbour_margin = 0;
    void find_tie_neighbours();
    bool intersect(const Ray& ray, SurfaceHit& out, HitParts parts) const;
    bool intersect_from_here(const Ray& ray, SurfaceHit& out, HitParts parts) const;
    bool intersect_from_afar(const Ray& ray, SurfaceHit& out, HitParts parts) const;
    bool intersect_again(const Ray& ray, SurfaceHit& out, HitParts parts) const;
    bool trace(const Ray& ray, RTCFilterFunctionN filter, HitParts parts, SurfaceHit& out, bool& retry) const;
    bool occluded(const Ray& ray) const;
    bool occluded_in_bvh(const Ray& ray) const;

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
    RTCFilterFunctionN shadow_filter() const { return frame.exact_range ? nullptr : accel::triangle_filter; }

    // Packets (accelerator_packets.cpp).
    template <class Lanes>
    bool in_native_groups(int count, Lanes&& lanes) const;
    template <int W>
    void intersect_lanes(accel::QueryContext& context, const Ray* rays, const bool* query, int first, int count,
                         HitParts parts, SurfaceHit* hits, bool* found) const;
    template <int W>
    void occluded_lanes(accel::QueryContext& context, const Ray* rays, const bool* query, int first, int count,
                        bool* blocked) const;
    template <class Alone>
    const bool* without_rays_from_afar(const Ray* rays, const bool* active, int count, bool* kept, Alone&& alone) const;
    void intersect_packet(const Ray* rays, const bool* active, int count, SurfaceHit* hits, bool* found,
                          HitParts parts) const;
    void occluded_packet(const Ray* rays, const bool* active, int count, bool* blocked) const;
};

}  // namespace whitted
