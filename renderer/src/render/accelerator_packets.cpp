// SPDX-License-Identifier: MIT
// Packets: up to Accelerator::packet_size rays through Embree's 4-, 8- or 16-wide calls, one
// template for every width; each ray's answer is then decided as accelerator_exact.cpp decides
// a single ray's.
#include "render/accelerator_impl.h"

#include <cmath>

namespace whitted {

using namespace accel;

namespace {

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

/// Whether at most `most` of the rays are active: they are then cheaper traced one by one
/// (Impl::single_ray_lanes).
bool few_lanes(const bool* active, int count, int most) {
    int in_use = 0;
    for (int i = 0; i < count; ++i) in_use += active[i];
    return in_use <= most;
}

}  // namespace

/// Calls `lanes.operator()<W>(first)` for first = 0, W, 2W, ... < count, with W the native
/// lane_width, so that each packet query is written once for every width. False when
/// Embree has no packets (lane_width 1): the caller then traces the rays one by one.
template <class Lanes>
bool Accelerator::Impl::in_native_groups(int count, Lanes&& lanes) const {
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
void Accelerator::Impl::intersect_lanes(QueryContext& context, const Ray* rays, const bool* query, int first, int count,
                                        HitParts parts, SurfaceHit* hits, bool* found) const {
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
                              context.best_t[i], context.best_normal[i], context.best_tied[i], parts, hits[i], retry);
        if (retry) found[i] = intersect_again(rays[i], hits[i], parts);
    }
}

/// `active`, unless some of those rays starts_afar: each of them is answered by `alone(i)` and
/// the others' flags copied to `kept`, which is returned. Only rays from a plane's far hits take
/// that path; every other ray's packet is the same.
template <class Alone>
const bool* Accelerator::Impl::without_rays_from_afar(const Ray* rays, const bool* active, int count, bool* kept,
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

void Accelerator::Impl::intersect_packet(const Ray* rays, const bool* active, int count, SurfaceHit* hits, bool* found,
                                         HitParts parts) const {
    bool from_here[packet_size];
    active = without_rays_from_afar(rays, active, count, from_here,
                                    [&](int i) { found[i] = intersect_from_afar(rays[i], hits[i], parts); });
    // A few rays (a refracted path, the last steps of a shadow walk) go one by one through
    // Embree's single-ray traversal: a W-wide packet with one lane in use walks the same nodes
    // at W lanes' cost; so do all rays where Embree has no packets (in_native_groups). The
    // answers are the same either way (decided in double).
    bool traced = false;
    if (!without_bvh && !few_lanes(active, count, single_ray_lanes)) {
        QueryContext context(rays, active, count, true);
        traced = in_native_groups(count, [&]<int W>(int first) {
            intersect_lanes<W>(context, rays, active, first, count, parts, hits, found);
        });
    }
    if (!traced)
        for (int i = 0; i < count; ++i)
            if (active[i]) found[i] = intersect(rays[i], hits[i], parts);
    embree_error.throw_if_failed("while tracing rays");
}

/// Shadow rays [first, first + W) through Embree's W-wide call; every lane is written.
template <int W>
void Accelerator::Impl::occluded_lanes(QueryContext& context, const Ray* rays, const bool* query, int first, int count,
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

void Accelerator::Impl::occluded_packet(const Ray* rays, const bool* active, int count, bool* blocked) const {
    bool from_here[packet_size];
    active = without_rays_from_afar(rays, active, count, from_here, [&](int i) { blocked[i] = occluded(rays[i]); });
    bool traced = false;
    if (!without_bvh && !few_lanes(active, count, single_ray_lanes)) {  // a few rays go one by one, as in
                                                                        // intersect_packet
        // Planes first (no BVH): a ray a plane blocks needs no Embree query.
        bool query[packet_size];
        for (int i = 0; i < count; ++i) query[i] = active[i] && !(blocked[i] = occluded_by_plane(rays[i]));
        QueryContext context(rays, query, count, true);
        context.embree.filter = shadow_filter();
        traced = in_native_groups(
            count, [&]<int W>(int first) { occluded_lanes<W>(context, rays, query, first, count, blocked); });
    }
    if (!traced)  // occluded() tests the planes first too
        for (int i = 0; i < count; ++i)
            if (active[i]) blocked[i] = occluded(rays[i]);
    embree_error.throw_if_failed("while tracing shadow rays");
}

}  // namespace whitted
