// SPDX-License-Identifier: MIT
// The BVH Embree traverses: each mesh's triangles widened beyond Embree's float error (so the
// double decision sees every triangle the ray meets), one BVH per prototype placed by its
// instances, and the spheres, boxes and cones as user geometry.
#include "render/accelerator_impl.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

namespace whitted {

using namespace accel;

namespace {

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

}  // namespace

Accelerator::Impl::Impl(const Scene& s, int threads, const std::string& instruction_set, BvhChoice bvh)
    : scene(s), isa(instruction_set) {
    spheres.scene = boxes.scene = cones.scene = &scene;
    check_reach();  // before Embree holds anything
    // Without a BVH too, the frame gives each ray the end Embree would have given it.
    frame = choose_frame();
    spheres.offset = boxes.offset = cones.offset = frame.offset;
    if (bvh == BvhChoice::when_worthwhile && worth_no_bvh()) {
        // A few spheres, boxes and cones: each ray tests them all (direct), with no Embree
        // device.
        if (!isa.empty()) require_embree_isa(isa);  // a setting the CPU cannot run is still an error
        without_bvh = true;
        // A cone is one part: the parts are for Embree's boxes, and each hit is the whole
        // cone's either way (ConeSegment).
        constexpr double inf = std::numeric_limits<double>::infinity();
        for (uint32_t c = 0; c < scene.cones.size(); ++c)
            cones.segments.push_back({c, 0.0, scene.cones[c].height, -inf, inf});
        const std::pair<const accel::AnalyticGeometry*, size_t> kinds_present[] = {
            {&spheres, scene.spheres.size()}, {&boxes, scene.boxes.size()}, {&cones, cones.segments.size()}};
        unsigned id = 0;
        for (const auto& [shapes, count] : kinds_present) {
            if (count == 0) continue;
            direct.push_back({id, shapes, unsigned(count)});
            record(id++, shapes->kind, 0);
        }
        return;
    }
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
    size_t most_triangles = 0;
    for (const TriangleMesh& mesh : scene.meshes) most_triangles = std::max(most_triangles, mesh.triangle_count());
    for (const Prototype& prototype : scene.prototypes)
        for (const TriangleMesh& mesh : prototype.meshes)
            most_triangles = std::max(most_triangles, mesh.triangle_count());
    corner_indices = MappedArray<uint32_t>(3 * most_triangles, 0);
    // Each triangle's own three corners (widen_triangles writes them in order), on every core.
    tbb::parallel_for(tbb::blocked_range<size_t>(0, 3 * most_triangles, 3 * 16384),
                      [indices = corner_indices.data()](const tbb::blocked_range<size_t>& range) {
                          for (size_t i = range.begin(); i != range.end(); ++i) indices[i] = uint32_t(i);
                      });
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
    find_tie_neighbours();
    if (!scene.spheres.empty()) add_analytic(spheres, scene.spheres.size());
    if (!scene.boxes.empty()) add_analytic(boxes, scene.boxes.size());
    if (!scene.cones.empty()) add_cone_segments();
    const bool own_shapes = !scene.spheres.empty() || !scene.boxes.empty() || !scene.cones.empty();
    single_ray_lanes = std::max(1, own_shapes ? lane_width / 2 : lane_width / 4);
    rtcCommitScene(rtc_scene);
    try {
        embree_error.throw_if_failed("while building the BVH");
    } catch (...) {
        release();
        throw;
    }
}

/// Whether the scene is a few spheres, boxes and cones (and planes, never in the BVH) and
/// nothing else, on few enough rays that testing every shape on each costs less than Embree
/// would: loading it, making its device and committing the scene take 5-6 ms of a process on
/// the machines of docs/performance.md ("Start-up"), while each ray's test of every shape
/// costs about 2 ns more per shape than Embree's packets (2 threads). The rays are reckoned
/// as the camera's and one shadow ray per light from each of their hits.
bool Accelerator::Impl::worth_no_bvh() const {
    const size_t shapes = scene.spheres.size() + scene.boxes.size() + scene.cones.size();
    if (!scene.meshes.empty() || !scene.instances.empty() || !scene.prototypes.empty() ||
        shapes > most_shapes_without_bvh)
        return false;
    const double rays =
        double(scene.width) * scene.height * scene.samples * scene.samples * (1.0 + double(scene.lights.size()));
    return double(shapes) * rays <= most_tests_without_bvh;
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
RTCBuildQuality Accelerator::Impl::build_quality() const {
    const double primitives =
        double(scene.triangle_count()) + 0.5 * double(scene.spheres.size() + scene.boxes.size() + scene.cones.size());
    const double camera_rays = double(scene.width) * scene.height * scene.samples * scene.samples;
    return primitives > camera_rays / 4 ? RTC_BUILD_QUALITY_LOW : RTC_BUILD_QUALITY_MEDIUM;
}

void Accelerator::Impl::release() {
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
double Accelerator::Impl::world_triangle_margin() const {
    return margin_ulps * std::ldexp(frame.reach + frame.span, -24);
}

/// Attaches a triangle mesh to `target` with its vertices moved by `shift` (Embree's
/// coordinates: the world minus the frame's offset; a prototype's own, unshifted) and its
/// triangles widened by `margin` (widen_triangles). Returns its geomID there.
unsigned Accelerator::Impl::add_mesh(RTCScene target, const TriangleMesh& mesh, bool as_povray, const Vec3& shift,
                                     double margin, const std::vector<const Transform*>* transforms) {
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
void Accelerator::Impl::add_instances() {
    if (scene.instances.empty()) return;
    // A prototype's triangles are widened in its own space: by the world's margin taken back
    // through the instance that shrinks it most (the Frobenius norm of the inverse's linear
    // part bounds how far a world distance goes), plus the rounding of Embree's float
    // transform of the ray and of the prototype's own coordinates.
    std::vector<double> stretch(scene.prototypes.size(), 0.0);
    for (const Instance& instance : scene.instances) {
        const Transform& t = instance.object_to_world;
        const Vec3 x = t.inverse_vector({1, 0, 0}), y = t.inverse_vector({0, 1, 0}), z = t.inverse_vector({0, 0, 1});
        stretch[instance.prototype] =
            std::max(stretch[instance.prototype], std::sqrt(dot(x, x) + dot(y, y) + dot(z, z)));
    }
    for (uint32_t p = 0; p < scene.prototypes.size(); ++p) {
        const Prototype& prototype = scene.prototypes[p];
        const double own = std::max({std::fabs(prototype.lo.x), std::fabs(prototype.lo.y), std::fabs(prototype.lo.z),
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

/// Which meshes and instances come near enough each other that a ray may meet two of them
/// within the float error nearest_triangle settles: their world boxes, each grown by
/// tie_neighbour_margin, overlap. A sweep along the scene's longest axis finds the pairs. The
/// margin is the window nearest_triangle gathers over (triangle_stray) for a ray of unit
/// direction that has come the scene's span, twice over; a ray whose window is wider is
/// settled whatever its neighbours (may_meet_another_object).
void Accelerator::Impl::find_tie_neighbours() {
    tie_neighbour_margin = 2 * (std::ldexp(frame.reach + frame.span, -14) + 1e-6 * frame.span);
    constexpr double inf = std::numeric_limits<double>::infinity();
    std::vector<WorldBox> box(kinds.size(), WorldBox{Vec3(inf), Vec3(-inf)});
    std::vector<uint32_t> top;  // the top-level geomIDs of triangles
    for (uint32_t id = 0; id < kinds.size(); ++id) {
        WorldBox& b = box[id];
        const auto take = [&b](const Vec3& p) { b.lo = min(b.lo, p), b.hi = max(b.hi, p); };
        if (kinds[id] == ShapeKind::triangles) {
            const TriangleMesh& mesh = scene.meshes[mesh_of_geometry[id]];
            for (size_t v = 0; v < mesh.vertex_count(); ++v) take(mesh.vertex(v));
        } else if (kinds[id] == ShapeKind::instances) {
            const Instance& instance = scene.instances[mesh_of_geometry[id]];
            const Prototype& prototype = scene.prototypes[instance.prototype];
            for (int corner = 0; corner < 8; ++corner)
                take(instance.object_to_world.apply_point({corner & 1 ? prototype.hi.x : prototype.lo.x,
                                                           corner & 2 ? prototype.hi.y : prototype.lo.y,
                                                           corner & 4 ? prototype.hi.z : prototype.lo.z}));
        } else {
            continue;
        }
        // The corners were rounded in double: a relative pad far above that.
        const double pad = 1e-9 * std::max({std::fabs(b.lo.x), std::fabs(b.lo.y), std::fabs(b.lo.z), std::fabs(b.hi.x),
                                            std::fabs(b.hi.y), std::fabs(b.hi.z)});
        b.lo -= Vec3(pad), b.hi += Vec3(pad);
        if (b.lo.x <= b.hi.x) top.push_back(id);  // a mesh of no vertex has no box
    }
    // Sweep along the axis the boxes spread furthest on, so that few pairs are looked at.
    Vec3 lo(inf), hi(-inf);
    for (uint32_t id : top) lo = min(lo, box[id].lo), hi = max(hi, box[id].hi);
    const Vec3 spread = hi - lo;
    const int axis = spread.x >= spread.y && spread.x >= spread.z ? 0 : spread.y >= spread.z ? 1 : 2;
    const auto along = [axis](const Vec3& p) { return axis == 0 ? p.x : axis == 1 ? p.y : p.z; };
    std::sort(top.begin(), top.end(), [&](uint32_t a, uint32_t b) {
        const double a_lo = along(box[a].lo), b_lo = along(box[b].lo);
        return a_lo != b_lo ? a_lo < b_lo : a < b;
    });
    const double grow = 2 * tie_neighbour_margin;
    std::vector<std::pair<uint32_t, uint32_t>> pairs;
    for (size_t i = 0; i < top.size(); ++i) {
        const WorldBox& a = box[top[i]];
        for (size_t j = i + 1; j < top.size() && along(box[top[j]].lo) <= along(a.hi) + grow; ++j) {
            const WorldBox& b = box[top[j]];
            if (b.lo.x <= a.hi.x + grow && a.lo.x <= b.hi.x + grow && b.lo.y <= a.hi.y + grow &&
                a.lo.y <= b.hi.y + grow && b.lo.z <= a.hi.z + grow && a.lo.z <= b.hi.z + grow)
                pairs.emplace_back(top[i], top[j]), pairs.emplace_back(top[j], top[i]);
        }
    }
    std::sort(pairs.begin(), pairs.end());
    tie_neighbours_start.assign(kinds.size() + 1, 0);
    for (const auto& pair : pairs) ++tie_neighbours_start[pair.first + 1];
    for (size_t id = 0; id < kinds.size(); ++id) tie_neighbours_start[id + 1] += tie_neighbours_start[id];
    tie_neighbours.reserve(pairs.size());
    for (const auto& pair : pairs) tie_neighbours.push_back(box[pair.second]);
}

void Accelerator::Impl::add_analytic(AnalyticGeometry& user, size_t count) {
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

/// The cones as Embree's primitives, each cut along its axis into parts (ConeSegment) about
/// four widest radii long, at most eight. On SPD rings (4200 slanted cylinders 15 radii long:
/// three parts each) a part of two radii or of eight came out no faster than the whole cylinder,
/// four about 8 % faster (bench/log.md): each part a ray's box test passes tests the whole cone.
void Accelerator::Impl::add_cone_segments() {
    constexpr double length_in_radii = 4;
    constexpr int max_cone_segments = 8;
    for (uint32_t c = 0; c < scene.cones.size(); ++c) {
        const Cone& cone = scene.cones[c];
        const double widest = std::max(cone.base_radius, cone.cap_radius);
        const double parts = widest > 0 ? cone.height / (length_in_radii * widest) : 1.0;
        const int count = parts >= max_cone_segments ? max_cone_segments : parts >= 2 ? int(parts) : 1;
        constexpr double inf = std::numeric_limits<double>::infinity();
        double begin = 0;
        for (int k = 0; k < count; ++k) {
            const double end = k + 1 == count ? cone.height : cone.height * (double(k + 1) / count);
            cones.segments.push_back({c, begin, end, k == 0 ? -inf : begin, k + 1 == count ? inf : end});
            begin = end;
        }
    }
    add_analytic(cones, cones.segments.size());
}

void Accelerator::Impl::record(unsigned id, ShapeKind kind, uint32_t mesh) {
    if (kinds.size() <= id) kinds.resize(id + 1), mesh_of_geometry.resize(id + 1);
    kinds[id] = kind;
    mesh_of_geometry[id] = mesh;
}

}  // namespace whitted
