// SPDX-License-Identifier: MIT
// The exact decision: Embree proposes candidates in float; each is decided again in double
// from the scene's own data and the double ray (triangles by the filter or after the query,
// spheres, boxes and cones in their callbacks), and the planes are tested directly.
#include "render/accelerator_impl.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>

namespace whitted {
namespace accel {

namespace {

/// Embree's float copy of `ray` in its frame, with `id`, its index in the query (packets:
/// accelerator_packets.cpp, set_lane).
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

/// A sphere's, box's or cone's material and object (Scene::objects index + 1).
std::pair<uint32_t, uint32_t> material_and_object(const Scene& scene, ShapeKind kind, unsigned prim) {
    if (kind == ShapeKind::spheres) return {scene.spheres[prim].material, scene.spheres[prim].object};
    if (kind == ShapeKind::cones) return {scene.cones[prim].material, scene.cones[prim].object};
    return {scene.boxes[prim].material, scene.boxes[prim].object};
}

/// The double test of shape `prim` of a geometry of kind `Kind`. The kind is a template
/// argument so that a callback's loop over its lanes chooses the test once, and inlines the
/// sphere's.
template <ShapeKind Kind>
bool intersect_analytic(const AnalyticGeometry& geometry, unsigned prim, const Ray& ray, double t_max, ShapeHit& hit) {
    if constexpr (Kind == ShapeKind::spheres) {
        return intersect_sphere(geometry.scene->spheres[prim], ray, ray.t_min, t_max, hit);
    } else if constexpr (Kind == ShapeKind::cones) {
        return intersect_cone(geometry.scene->cones[prim], ray, ray.t_min, t_max, hit);
    } else {
        const Box& box = geometry.scene->boxes[prim];
        return geometry.scene->intersection == Intersection::povray
                   ? intersect_box_as_povray(box, ray, ray.t_min, t_max, hit)
                   : intersect_box(box, ray, ray.t_min, t_max, hit);
    }
}

/// Calls `body.template operator()<Kind>()` with `kind` as a template argument.
template <class Body>
decltype(auto) with_kind(ShapeKind kind, Body&& body) {
    if (kind == ShapeKind::spheres) return body.template operator()<ShapeKind::spheres>();
    if (kind == ShapeKind::cones) return body.template operator()<ShapeKind::cones>();
    return body.template operator()<ShapeKind::boxes>();
}

/// Whether Scene::objects number `object` (index + 1) is a cylinder or cone.
bool is_cone_object(const Scene& scene, uint32_t object) {
    const ObjectType type = scene.objects[object - 1].type;
    return type == ObjectType::cylinder || type == ObjectType::cone;
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

/// How far past its edges, in barycentric terms, a triangle still counts as hit by the exact
/// test: far below any ray's float error, and far above double's rounding of u and v, so that
/// a ray along an edge two triangles share meets at least one of them.
constexpr double triangle_edge_margin = 1e-10;

/// The decision on a triangle candidate, made in double from the scene's own float vertices
/// and the double ray: the ray passes inside the triangle and meets it within (t_min, t_max),
/// by the exact test (Möller–Trumbore in double), or by POV-Ray's own where `as_povray`
/// (render.intersection: povray, the rules `whitted check` renders with: intersect_mesh2, with
/// `instanced` for a prototype's triangle, the ray then in the prototype's space). Embree's
/// float test only proposes candidates: it is given triangles widened beyond its rounding
/// (Impl::add_mesh), so every triangle the double ray meets is among them, and the widened parts
/// are refused here. hit.normal is (v1 − v0) × (v2 − v0).
bool hit_triangle_in_double(const TriangleMesh& mesh, unsigned prim, const Ray& ray, bool as_povray, bool instanced,
                            ShapeHit& hit) {
    if (as_povray) return intersect_mesh2(mesh, prim, ray, instanced, hit);
    const uint32_t* index = &mesh.indices[3 * size_t(prim)];
    const Vec3 v0 = mesh.vertex(index[0]), v1 = mesh.vertex(index[1]), v2 = mesh.vertex(index[2]);
    return intersect_triangle(v0, v1, v2, ray, ray.t_min, ray.t_max, hit, triangle_edge_margin);
}

/// The smooth shading normal at a hit on a triangle, unit length: the lecture's blend of the
/// vertex normals (blended_normal), or for a mesh decided as POV-Ray decides it, POV-Ray's at
/// `point`, the hit in the mesh's space (MeshAsPovray::smooth_normal). False where the
/// triangle is shaded flat, with its face normal.
bool smooth_normal(const TriangleMesh& mesh, uint32_t prim, const ShapeHit& hit, const MeshAsPovray& povray,
                   const Vec3& point, Convention convention, Vec3& out) {
    return povray.decided ? povray.smooth_normal(mesh, prim, point, convention, out)
                          : blended_normal(mesh, prim, hit.u, hit.v, convention, out);
}

}  // namespace

void analytic_bounds(const RTCBoundsFunctionArguments* args) {
    const auto* geometry = static_cast<const AnalyticGeometry*>(args->geometryUserPtr);
    Vec3 lo, hi;
    if (geometry->kind == ShapeKind::spheres)
        world_bounds(geometry->scene->spheres[args->primID], lo, hi);
    else if (geometry->kind != ShapeKind::cones)
        world_bounds(geometry->scene->boxes[args->primID], lo, hi);
    // Widen by a relative margin so that float rounding of the bounds never clips a hit: for a
    // part of a cone, the whole cone's margin.
    Vec3 pad;
    if (geometry->kind == ShapeKind::cones) {
        const ConeSegment& segment = geometry->segments[args->primID];
        const Cone& cone = geometry->scene->cones[segment.cone];
        world_bounds(cone, lo, hi);
        pad = (hi - lo) * 1e-6 + Vec3(1e-6);
        world_bounds(cone, segment.s_begin, segment.s_end, lo, hi);
    } else {
        pad = (hi - lo) * 1e-6 + Vec3(1e-6);
    }
    lo -= geometry->offset;
    hi -= geometry->offset;
    lo -= pad;
    hi += pad;
    args->bounds_o->lower_x = std::nextafter(float(lo.x), -INFINITY);
    args->bounds_o->lower_y = std::nextafter(float(lo.y), -INFINITY);
    args->bounds_o->lower_z = std::nextafter(float(lo.z), -INFINITY);
    args->bounds_o->upper_x = std::nextafter(float(hi.x), INFINITY);
    args->bounds_o->upper_y = std::nextafter(float(hi.y), INFINITY);
    args->bounds_o->upper_z = std::nextafter(float(hi.z), INFINITY);
}

namespace {

template <ShapeKind Kind>
bool consider(const AnalyticGeometry& geometry, unsigned part, QueryContext& context, unsigned id, float& tfar) {
    // A part of a cone (ConeSegment) reports the cone itself, and only the hit that is its own.
    const ConeSegment* segment = Kind == ShapeKind::cones ? &geometry.segments[part] : nullptr;
    const unsigned prim = segment ? segment->cone : part;
    const Ray& ray = context.rays[id];
    const double limit = std::min(context.best_t[id], double(tfar));
    // Up to and including the limit, to see a hit at exactly the t of the one held.
    ShapeHit hit;
    if (!intersect_analytic<Kind>(geometry, prim, ray, next_up(limit), hit)) return false;
    if (segment && !(hit.u >= segment->owns_from && hit.u < segment->owns_to)) return false;
    const auto [material, object] = material_and_object(*geometry.scene, geometry.kind, prim);
    if (hit.t == limit) {
        // At a triangle's (float) distance, or at the ray's end: the candidate does not win.
        if (limit != context.best_t[id] || !(limit < ray.t_max)) return false;
        // An exact tie with the sphere or box held: overlapping boxes with faces in one
        // plane, or two equal spheres in one place.
        const Vec3& held = context.best_normal[id];
        // The exact rule: the tie goes to the first object in the file, whatever order
        // Embree met them in (which differs from one instruction set to another). So does a
        // tie with a cone, and a tie that looks the same, under POV-Ray's rules too: its
        // order (PovrayTestOrder) knows spheres and boxes.
        const bool by_object = geometry.scene->intersection == Intersection::exact ||
                               geometry.kind == ShapeKind::cones ||
                               is_cone_object(*geometry.scene, context.best_object[id]);
        if (by_object || (material == context.best_material[id] && hit.normal.x == held.x && hit.normal.y == held.y &&
                          hit.normal.z == held.z)) {
            if (object > context.best_object[id]) return false;
        } else if (!povray_tie_replaces(material == context.best_material[id], context.best_edge_tie[id], hit.edge_tie,
                                        context.best_tied[id])) {
            return false;
        }
    } else {
        context.best_tied[id] = false;
    }
    context.best_t[id] = hit.t;
    context.best_normal[id] = hit.normal;
    context.best_edge_tie[id] = hit.edge_tie;
    context.best_material[id] = material;
    context.best_object[id] = object;
    // Round the float distance up so Embree keeps visiting boxes that may hold a closer hit.
    tfar = next_up(float(hit.t));
    return true;
}

template <ShapeKind Kind>
bool blocks(const AnalyticGeometry& geometry, unsigned part, const Ray& ray) {
    if constexpr (Kind == ShapeKind::spheres) {
        return sphere_blocks(geometry.scene->spheres[part], ray, ray.t_min, ray.t_max);
    } else {
        // Any hit on the cone blocks, whichever part's box the ray is in.
        const unsigned prim = Kind == ShapeKind::cones ? geometry.segments[part].cone : part;
        ShapeHit hit;
        return intersect_analytic<Kind>(geometry, prim, ray, ray.t_max, hit);
    }
}

template <ShapeKind Kind>
void intersect_lanes(const RTCIntersectFunctionNArguments* args, const AnalyticGeometry& geometry,
                     QueryContext& context) {
    RTCRayN* rays = RTCRayHitN_RayN(args->rayhit, args->N);
    RTCHitN* hits = RTCRayHitN_HitN(args->rayhit, args->N);
    const unsigned prim = Kind == ShapeKind::cones ? geometry.segments[args->primID].cone : args->primID;
    for (unsigned i = 0; i < args->N; ++i) {
        if (!args->valid[i]) continue;
        const unsigned id = RTCRayN_id(rays, args->N, i);
        if (!context.is_query(id)) continue;
        if (!consider<Kind>(geometry, args->primID, context, id, RTCRayN_tfar(rays, args->N, i))) continue;
        const Vec3& normal = context.best_normal[id];
        RTCHitN_geomID(hits, args->N, i) = args->geomID;
        RTCHitN_primID(hits, args->N, i) = prim;
        RTCHitN_instID(hits, args->N, i, 0) = RTC_INVALID_GEOMETRY_ID;
        RTCHitN_u(hits, args->N, i) = 0;
        RTCHitN_v(hits, args->N, i) = 0;
        RTCHitN_Ng_x(hits, args->N, i) = float(normal.x);
        RTCHitN_Ng_y(hits, args->N, i) = float(normal.y);
        RTCHitN_Ng_z(hits, args->N, i) = float(normal.z);
    }
}

template <ShapeKind Kind>
void occluded_lanes(const RTCOccludedFunctionNArguments* args, const AnalyticGeometry& geometry,
                    const QueryContext& context) {
    for (unsigned i = 0; i < args->N; ++i) {
        if (!args->valid[i]) continue;
        const unsigned id = RTCRayN_id(args->ray, args->N, i);
        if (!context.is_query(id)) continue;
        if (blocks<Kind>(geometry, args->primID, context.rays[id]))
            RTCRayN_tfar(args->ray, args->N, i) = -INFINITY;  // Embree's mark for "occluded"
    }
}

}  // namespace

bool consider_analytic(const AnalyticGeometry& geometry, unsigned part, QueryContext& context, unsigned id,
                       float& tfar) {
    return with_kind(geometry.kind,
                     [&]<ShapeKind Kind>() { return consider<Kind>(geometry, part, context, id, tfar); });
}

bool analytic_blocks(const AnalyticGeometry& geometry, unsigned part, const Ray& ray) {
    return with_kind(geometry.kind, [&]<ShapeKind Kind>() { return blocks<Kind>(geometry, part, ray); });
}

void analytic_intersect(const RTCIntersectFunctionNArguments* args) {
    const auto* geometry = static_cast<const AnalyticGeometry*>(args->geometryUserPtr);
    auto* context = reinterpret_cast<QueryContext*>(args->context);
    if (context->gathering) return;  // nearest_triangle's query asks for triangles only
    with_kind(geometry->kind, [&]<ShapeKind Kind>() { intersect_lanes<Kind>(args, *geometry, *context); });
}

void analytic_occluded(const RTCOccludedFunctionNArguments* args) {
    const auto* geometry = static_cast<const AnalyticGeometry*>(args->geometryUserPtr);
    const auto* context = reinterpret_cast<const QueryContext*>(args->context);
    with_kind(geometry->kind, [&]<ShapeKind Kind>() { occluded_lanes<Kind>(args, *geometry, *context); });
}

/// Filter call `args`'s candidate `i` (a triangle) by the double test, on the ray as its mesh
/// sees it (brought into the prototype for an instance's): true, with `hit`, when it is met.
bool candidate_met_in_double(const RTCFilterFunctionNArguments* args, unsigned i, ShapeHit& hit) {
    const auto* geometry = static_cast<const TriangleGeometry*>(args->geometryUserPtr);
    const auto* context = reinterpret_cast<const QueryContext*>(args->context);
    const unsigned id = RTCRayN_id(args->ray, args->N, i);
    const unsigned inst = RTCHitN_instID(args->hit, args->N, i, 0);
    const bool instanced = inst != RTC_INVALID_GEOMETRY_ID;
    const Ray ray =
        instanced ? to_object_space(*(*geometry->instance_transforms)[inst], context->rays[id]) : context->rays[id];
    return hit_triangle_in_double(*geometry->mesh, RTCHitN_primID(args->hit, args->N, i), ray, geometry->as_povray,
                                  instanced, hit);
}

/// Embree's filter for triangle candidates (hit_triangle_in_double): on the meshes' own
/// geometry where every candidate must be decided as it is met (EmbreeFrame::exact_range);
/// otherwise on the context of shadow rays (whose first accepted candidate ends the search)
/// and of a ray traced again after its nearest candidate was refused.
void triangle_filter(const RTCFilterFunctionNArguments* args) {
    const auto* context = reinterpret_cast<const QueryContext*>(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] != -1) continue;
        if (!context->is_query(RTCRayN_id(args->ray, args->N, i))) continue;
        ShapeHit hit;
        if (!candidate_met_in_double(args, i, hit)) args->valid[i] = 0;
    }
}

void TriangleCandidates::add(const TriangleCandidate& candidate) {
    if (count < capacity) {
        nearest[count++] = candidate;
        return;
    }
    TriangleCandidate* farthest = std::max_element(nearest, nearest + capacity);
    if (candidate < *farthest) *farthest = candidate;
}

/// nearest_triangle's filter: every triangle candidate the double test accepts is gathered, and
/// every one is refused, so that Embree goes on to all of them within the query's range.
void gather_triangles(const RTCFilterFunctionNArguments* args) {
    const auto* geometry = static_cast<const TriangleGeometry*>(args->geometryUserPtr);
    const auto* context = reinterpret_cast<const QueryContext*>(args->context);
    TriangleCandidates& gathered = *context->gathering;
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] != -1) continue;
        args->valid[i] = 0;
        if (!context->is_query(RTCRayN_id(args->ray, args->N, i))) continue;
        ShapeHit hit;
        if (!candidate_met_in_double(args, i, hit)) continue;
        const unsigned inst = RTCHitN_instID(args->hit, args->N, i, 0);
        const uint32_t object = inst != RTC_INVALID_GEOMETRY_ID
                                    ? gathered.scene->instances[(*gathered.mesh_of_geometry)[inst]].object
                                    : geometry->mesh->object;
        gathered.add(
            {hit.t, object, inst, RTCHitN_geomID(args->hit, args->N, i), RTCHitN_primID(args->hit, args->N, i)});
    }
}

}  // namespace accel

using namespace accel;

/// Which triangle the ray meets first, given the one Embree proposed, met at `t` by the double
/// test. Embree chose it by its float distance, whose rounding differs between instruction
/// sets (FMA or not, the packet width): where two triangles lie within that rounding of each
/// other along the ray (coplanar faces of two overlapping gears, a shared edge), the order of
/// their float distances is the instruction set's, not the scene's. So the triangles near `t`
/// are gathered again in double (gather_triangles) and the choice is the exact rule's: the
/// nearest double distance, and of those within tie_window of it the first object in the file
/// (under POV-Ray's rules, of those at exactly that distance), then the nearest, then the
/// lowest instance, mesh and triangle. Returns that triangle in `inst`, `geom`, `prim`.
void Accelerator::Impl::nearest_triangle(const Ray& ray, double t, unsigned& inst, unsigned& geom,
                                         unsigned& prim) const {
    const double stray = triangle_stray(t);
    TriangleCandidates gathered;
    gathered.scene = &scene;
    gathered.mesh_of_geometry = &mesh_of_geometry;
    QueryContext context(&ray, nullptr, 1, false);
    context.embree.filter = gather_triangles;
    context.gathering = &gathered;
    context.start(0, ray);
    RTCRayHit rayhit;
    rayhit.ray = make_embree_ray(ray, 0, frame);
    rayhit.ray.tnear = float(std::max(0.0, t - stray));
    rayhit.ray.tfar = next_up(float(t + stray));
    rayhit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rayhit.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(rtc_scene, &context.embree, &rayhit);
    if (gathered.count == 0) return;  // not expected: the proposed triangle is among them
    const TriangleCandidate *begin = gathered.nearest, *end = begin + gathered.count;
    const TriangleCandidate* chosen = std::min_element(begin, end);
    const double nearest = chosen->t;
    const double window = scene.intersection == Intersection::povray ? 0.0 : tie_window(ray, nearest);
    for (const TriangleCandidate* c = begin; c != end; ++c)
        if (c->t <= nearest + window &&
            std::tie(c->object, c->t, c->inst, c->geom, c->prim) <
                std::tie(chosen->object, chosen->t, chosen->inst, chosen->geom, chosen->prim))
            chosen = c;
    inst = chosen->inst, geom = chosen->geom, prim = chosen->prim;
}

/// How far along `ray` (in its t) nearest_triangle looks on either side of a hit at `t`.
/// Embree's float distance strays from the double one by a few ulps of the coordinates and
/// distances involved (world_triangle_margin's 2^-24 (reach + span) each), more where the ray
/// grazes the plane; the window takes 2^10 of them and a millionth of t, far beyond both.
double Accelerator::Impl::triangle_stray(double t) const {
    return std::ldexp(frame.reach + frame.span, -14) + 1e-6 * t;
}

/// Whether a ray that met top-level geometry `top` (a mesh of the world, or an instance) at
/// `t` may have met another object's triangle within nearest_triangle's window of it: the hit
/// lies within that window of the world box of a mesh or instance near `top`
/// (find_tie_neighbours). Elsewhere no other object's triangle is near enough to tie, and the
/// ray pays nothing for the settling. A window wider than the neighbours were found with is
/// settled always.
bool Accelerator::Impl::may_meet_another_object(const Ray& ray, unsigned top, double t) const {
    const uint32_t begin = tie_neighbours_start[top], end = tie_neighbours_start[top + 1];
    if (begin == end) return false;
    const double window = triangle_stray(t) * length(ray.direction);
    if (!(window <= tie_neighbour_margin)) return true;
    const Vec3 x = ray.at(t);
    // The hit point is rounded in double: the same relative pad as the boxes'.
    const double grow = window + 1e-9 * std::max({std::fabs(x.x), std::fabs(x.y), std::fabs(x.z)});
    for (uint32_t i = begin; i != end; ++i) {
        const WorldBox& b = tie_neighbours[i];
        if (x.x >= b.lo.x - grow && x.x <= b.hi.x + grow && x.y >= b.lo.y - grow && x.y <= b.hi.y + grow &&
            x.z >= b.lo.z - grow && x.z <= b.hi.z + grow)
            return true;
    }
    return false;
}

const PovrayTestOrder& Accelerator::Impl::tie_order() const {
    // The threads that wait help build it (its sorts split work).
    tbb::collaborative_call_once(tie_order_built, [&] { tie_order_data = std::make_unique<PovrayTestOrder>(scene); });
    return *tie_order_data;
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
bool Accelerator::Impl::finish_hit(const Ray& ray, unsigned inst, unsigned geom, unsigned prim, double best_t,
                                   const Vec3& best_normal, bool tied, HitParts parts, SurfaceHit& out,
                                   bool& retry) const {
    const bool normals = parts == HitParts::all;
    retry = false;
    bool found = false;
    double t_max = ray.t_max;
    ShapeHit hit;
    bool tested = false;  // `hit` holds the double test of triangle `prim`
    if (geom != RTC_INVALID_GEOMETRY_ID && (inst != RTC_INVALID_GEOMETRY_ID || kinds[geom] == ShapeKind::triangles)) {
        // A triangle: decided in double, then settled against its near neighbours along the ray.
        const bool instanced = inst != RTC_INVALID_GEOMETRY_ID;
        const TriangleMesh& mesh =
            instanced ? scene.prototypes[scene.instances[mesh_of_geometry[inst]].prototype].meshes[geom]
                      : scene.meshes[mesh_of_geometry[geom]];
        const bool as_povray = instanced
                                   ? prototype_povray[scene.instances[mesh_of_geometry[inst]].prototype][geom].decided
                                   : world_povray[mesh_of_geometry[geom]].decided;
        const Ray local =
            instanced ? to_object_space(scene.instances[mesh_of_geometry[inst]].object_to_world, ray) : ray;
        if (!hit_triangle_in_double(mesh, prim, local, as_povray, instanced, hit)) return retry = true, false;
        tested = true;
        if (may_meet_another_object(ray, instanced ? inst : geom, hit.t)) {
            const unsigned proposed[3] = {inst, geom, prim};
            nearest_triangle(ray, hit.t, inst, geom, prim);
            tested = inst == proposed[0] && geom == proposed[1] && prim == proposed[2];
        }
    }
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
            if (!tested &&
                !hit_triangle_in_double(mesh, prim, to_object_space(to_world, ray), povray.decided, true, hit))
                return retry = true, false;
            if (normals) {
                const double handedness = to_world.determinant() < 0 ? -1.0 : 1.0;
                out.geometric_normal = normalize(to_world.apply_normal(hit.normal)) * handedness;
                Vec3 smooth;
                // POV-Ray takes the world point back into the mesh's space for its normal.
                out.normal = smooth_normal(mesh, prim, hit, povray, to_world.inverse_point(ray.at(hit.t)),
                                           scene.convention, smooth)
                                 ? normalize(to_world.apply_normal(smooth))
                                 : out.geometric_normal;
            }
            out.material = triangle_material(instance, mesh, prim);
            out.object = instance.object;
        } else if (kinds[geom] == ShapeKind::triangles) {
            const TriangleMesh& mesh = scene.meshes[mesh_of_geometry[geom]];
            const MeshAsPovray& povray = world_povray[mesh_of_geometry[geom]];
            if (!tested && !hit_triangle_in_double(mesh, prim, ray, povray.decided, false, hit))
                return retry = true, false;
            if (normals) {
                out.geometric_normal = normalize(hit.normal);
                Vec3 smooth;
                out.normal = smooth_normal(mesh, prim, hit, povray, ray.at(hit.t), scene.convention, smooth)
                                 ? smooth
                                 : out.geometric_normal;
            }
            out.material = triangle_material(mesh, prim);
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
            if (normals) out.normal = out.geometric_normal = normalize(normal);
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
        if (normals) out.normal = out.geometric_normal = plane.normal;
        out.material = plane.material;
        out.object = plane.object;
        found = plane_found = true;
    }
    if (found) out.point = ray.at(out.t);
    return found;
}

/// The nearest hit on `ray`: Embree's nearest candidate, when the double test accepts it.
bool Accelerator::Impl::intersect(const Ray& ray, SurfaceHit& out, HitParts parts) const {
    return starts_afar(ray) ? intersect_from_afar(ray, out, parts) : intersect_from_here(ray, out, parts);
}

/// intersect for a ray that does not start afar (or has been brought near).
bool Accelerator::Impl::intersect_from_here(const Ray& ray, SurfaceHit& out, HitParts parts) const {
    bool retry = false;
    const bool found = trace(ray, nullptr, parts, out, retry);
    return retry ? intersect_again(ray, out, parts) : found;
}

/// intersect for a ray that starts_afar: a plane it meets before it reaches the finite shapes'
/// cube, else what it meets from there on (toward_finite_shapes).
bool Accelerator::Impl::intersect_from_afar(const Ray& ray, SurfaceHit& out, HitParts parts) const {
    Ray near;
    double skipped = 0;
    bool retry = false;
    if (!toward_finite_shapes(ray, near, skipped))
        return finish_hit(ray, RTC_INVALID_GEOMETRY_ID, RTC_INVALID_GEOMETRY_ID, 0, 0, {}, false, parts, out, retry);
    Ray before = ray;
    before.t_max = std::min(ray.t_max, skipped);
    if (before.t_max > before.t_min &&
        finish_hit(before, RTC_INVALID_GEOMETRY_ID, RTC_INVALID_GEOMETRY_ID, 0, 0, {}, false, parts, out, retry))
        return true;
    if (!intersect_from_here(near, out, parts)) return false;
    out.t += skipped;
    return true;
}

/// The nearest hit on a ray whose nearest candidate the double test refused (finish_hit):
/// traced again with that test as Embree's filter, so that Embree goes on past every
/// refused candidate to the nearest accepted one. Only such rays pay for the filter's call
/// per candidate (a few percent of the rays that meet a mesh, those near an edge).
bool Accelerator::Impl::intersect_again(const Ray& ray, SurfaceHit& out, HitParts parts) const {
    bool retry = false;
    const bool found = trace(ray, triangle_filter, parts, out, retry);
    if (!retry) return found;
    // Not expected (the filter refuses what finish_hit would); if it came, the planes answer.
    return finish_hit(ray, RTC_INVALID_GEOMETRY_ID, RTC_INVALID_GEOMETRY_ID, 0, 0, {}, false, parts, out, retry);
}

/// One Embree query for `ray` with `filter` on its context (null: none), and finish_hit.
bool Accelerator::Impl::trace(const Ray& ray, RTCFilterFunctionN filter, HitParts parts, SurfaceHit& out,
                              bool& retry) const {
    QueryContext context(&ray, nullptr, 1, false);
    context.embree.filter = filter;
    context.start(0, ray);
    if (without_bvh) {
        float tfar = frame.t_max(ray);
        unsigned geom = RTC_INVALID_GEOMETRY_ID, prim = 0;
        for (const DirectShapes& shapes : direct)
            for (unsigned part = 0; part < shapes.parts; ++part)
                if (consider_analytic(*shapes.geometry, part, context, 0, tfar)) {
                    geom = shapes.id;
                    prim = shapes.geometry->kind == ShapeKind::cones ? shapes.geometry->segments[part].cone : part;
                }
        return finish_hit(ray, RTC_INVALID_GEOMETRY_ID, geom, prim, context.best_t[0], context.best_normal[0],
                          context.best_tied[0], parts, out, retry);
    }
    RTCRayHit rayhit;
    rayhit.ray = make_embree_ray(ray, 0, frame);
    rayhit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rayhit.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(rtc_scene, &context.embree, &rayhit);
    return finish_hit(ray, rayhit.hit.instID[0], rayhit.hit.geomID, rayhit.hit.primID, context.best_t[0],
                      context.best_normal[0], context.best_tied[0], parts, out, retry);
}

/// Calls `lanes.operator()<W>(first)` for first = 0, W, 2W, ... < count, with W the native

bool Accelerator::Impl::occluded(const Ray& ray) const {
    if (occluded_by_plane(ray)) return true;
    if (starts_afar(ray)) {
        Ray near;
        double skipped = 0;
        return toward_finite_shapes(ray, near, skipped) && near.t_max > near.t_min && occluded_in_bvh(near);
    }
    return occluded_in_bvh(ray);
}

/// Embree's answer for a shadow ray, the planes aside.
bool Accelerator::Impl::occluded_in_bvh(const Ray& ray) const {
    if (without_bvh) {
        for (const DirectShapes& shapes : direct)
            for (unsigned part = 0; part < shapes.parts; ++part)
                if (analytic_blocks(*shapes.geometry, part, ray)) return true;
        return false;
    }
    QueryContext context(&ray, nullptr, 1, false);
    context.embree.filter = shadow_filter();
    RTCRay r = make_embree_ray(ray, 0, frame);
    rtcOccluded1(rtc_scene, &context.embree, &r);
    return r.tfar < 0;
}

}  // namespace whitted
