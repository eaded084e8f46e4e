// SPDX-License-Identifier: MIT
// The yardstick for Whitted's render stage: Embree alone, tracing the rays Whitted traces on the
// same scene, with no shading and no double-precision decisions. Only Embree, TBB and the C++
// library; bench/embree_rate.py writes its scene description from a Whitted scene and sets the
// two side by side (docs/performance.md, "Rays per second against Embree's own rate").
//
//   whitted_embree_rate SCENE.rays [--threads N] [--sphere-points]   (WHITTED_EMBREE_ISA as for Whitted)
//
// SCENE.rays, one item a line (numbers in the world's coordinates):
//   camera EX EY EZ LX LY LZ UX UY UZ FOV     image W H     max_depth D     light X Y Z
//   plane PX PY PZ NX NY NZ KM                (a square of side 2e5 about P: two triangles)
//   sphere CX CY CZ R KM
//   mesh FILE.obj KM M00 M01 M02 M03 M10 ... M23   (object to world, 3x4 rows; smooth normals)
#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

struct Vec {
    float x = 0, y = 0, z = 0;
    friend Vec operator+(Vec a, Vec b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
    friend Vec operator-(Vec a, Vec b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
    friend Vec operator*(Vec a, float s) { return {a.x * s, a.y * s, a.z * s}; }
    friend float dot(Vec a, Vec b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
    friend Vec cross(Vec a, Vec b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
    friend Vec normalize(Vec a) { return a * (1.0f / std::sqrt(dot(a, a))); }
};

/// What a hit needs for its secondary rays: the normal and the mirror coefficient km.
struct Shape {
    enum Kind { plane, mesh, spheres } kind = plane;
    float km = 0;                        // a plane's and a mesh's
    Vec plane_normal;                    // a plane's
    std::vector<Vec> normals;            // a mesh's, one per normal index
    std::vector<uint32_t> normal_index;  // a mesh's, three per triangle
    std::vector<Vec> centres;            // the spheres', by primID
    std::vector<float> sphere_km;        // the spheres', by primID
};

struct Scene {
    Vec eye, forward, right, up;  // camera rays: normalize(forward + right·x0 + up·y0)
    int width = 0, height = 0, max_depth = 5;
    std::vector<Vec> lights;
    std::vector<Shape> shapes;  // by geomID
    size_t triangles = 0, spheres = 0;
    // Spheres as user geometry tested here in float (Whitted's are user geometry tested in
    // double): 1.4-1.5x the rate of Embree's RTC_GEOMETRY_TYPE_SPHERE_POINT (--sphere-points).
    bool user_spheres = true;
    std::vector<float> sphere_data;  // x, y, z, r per sphere
};

/// The nearest t in (tnear, tfar) at which ray i of an N-ray packet meets sphere s, or -1.
float sphere_t(const float* s, RTCRayN* ray, unsigned N, unsigned i) {
    const Vec o{RTCRayN_org_x(ray, N, i) - s[0], RTCRayN_org_y(ray, N, i) - s[1], RTCRayN_org_z(ray, N, i) - s[2]};
    const Vec d{RTCRayN_dir_x(ray, N, i), RTCRayN_dir_y(ray, N, i), RTCRayN_dir_z(ray, N, i)};
    const float a = dot(d, d), b = dot(o, d), disc = b * b - a * (dot(o, o) - s[3] * s[3]);
    if (disc < 0) return -1;
    const float q = std::sqrt(disc), tnear = RTCRayN_tnear(ray, N, i);
    float t = (-b - q) / a;
    if (!(t > tnear)) t = (-b + q) / a;
    return t > tnear && t < RTCRayN_tfar(ray, N, i) ? t : -1;
}
void sphere_bounds(const RTCBoundsFunctionArguments* args) {
    const float* s = static_cast<const float*>(args->geometryUserPtr) + 4 * args->primID;
    *args->bounds_o = {s[0] - s[3], s[1] - s[3], s[2] - s[3], 0, s[0] + s[3], s[1] + s[3], s[2] + s[3], 0};
}
void sphere_intersect(const RTCIntersectFunctionNArguments* args) {
    const float* s = static_cast<const float*>(args->geometryUserPtr) + 4 * args->primID;
    RTCRayN* ray = RTCRayHitN_RayN(args->rayhit, args->N);
    RTCHitN* hit = RTCRayHitN_HitN(args->rayhit, args->N);
    for (unsigned i = 0; i < args->N; ++i) {
        if (!args->valid[i]) continue;
        const float t = sphere_t(s, ray, args->N, i);
        if (t < 0) continue;
        RTCRayN_tfar(ray, args->N, i) = t;
        RTCHitN_primID(hit, args->N, i) = args->primID, RTCHitN_geomID(hit, args->N, i) = args->geomID;
        RTCHitN_instID(hit, args->N, i, 0) = args->context->instID[0];
        RTCHitN_u(hit, args->N, i) = RTCHitN_v(hit, args->N, i) = 0;
    }
}
void sphere_occluded(const RTCOccludedFunctionNArguments* args) {
    const float* s = static_cast<const float*>(args->geometryUserPtr) + 4 * args->primID;
    for (unsigned i = 0; i < args->N; ++i)
        if (args->valid[i] && sphere_t(s, args->ray, args->N, i) >= 0) RTCRayN_tfar(args->ray, args->N, i) = -INFINITY;
}

struct Counts {
    std::atomic<uint64_t> camera{0}, shadow{0}, reflected{0};
};

Vec read_vec(std::istream& in) {
    Vec v;
    in >> v.x >> v.y >> v.z;
    return v;
}

/// Attaches a triangle geometry to `rtc` and its shape to `scene` under its geomID.
void add_triangles(RTCDevice device, RTCScene rtc, Scene& scene, const std::vector<Vec>& positions,
                   const std::vector<uint32_t>& corners, Shape shape) {
    RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    std::copy(positions.begin(), positions.end(),
              static_cast<Vec*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                        sizeof(Vec), positions.size())));
    std::copy(corners.begin(), corners.end(),
              static_cast<uint32_t*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                             3 * sizeof(uint32_t), corners.size() / 3)));
    rtcCommitGeometry(geometry);
    scene.shapes.resize(rtcAttachGeometry(rtc, geometry) + 1);
    scene.shapes.back() = std::move(shape);
    rtcReleaseGeometry(geometry);
}

/// The OBJ mesh's triangles (v, vn, f with v//n corners, as bench/generate.py writes them),
/// placed by the 3x4 matrix m; normals by its cofactor matrix (the inverse transpose, scaled).
void add_mesh(RTCDevice device, RTCScene rtc, Scene& scene, const std::string& path, float km, const float* m) {
    std::ifstream file(path);
    std::vector<Vec> positions;
    std::vector<uint32_t> corners;
    Shape shape;
    shape.kind = Shape::mesh;
    shape.km = km;
    const auto place = [m](Vec p) {
        return Vec{m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3], m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7],
                   m[8] * p.x + m[9] * p.y + m[10] * p.z + m[11]};
    };
    const Vec c0{m[0], m[4], m[8]}, c1{m[1], m[5], m[9]}, c2{m[2], m[6], m[10]};
    const Vec n0 = cross(c1, c2), n1 = cross(c2, c0), n2 = cross(c0, c1);  // columns of the cofactor matrix
    std::string line;
    while (std::getline(file, line)) {
        if (line.size() < 2) continue;
        const char* s = line.c_str() + 2;
        char* end;
        if (line[0] == 'v' && line[1] == ' ') {
            const float x = std::strtof(s, &end), y = std::strtof(end, &end), z = std::strtof(end, &end);
            positions.push_back(place({x, y, z}));
        } else if (line[0] == 'v' && line[1] == 'n') {
            const float x = std::strtof(s + 1, &end), y = std::strtof(end, &end), z = std::strtof(end, &end);
            shape.normals.push_back(normalize(n0 * x + n1 * y + n2 * z));
        } else if (line[0] == 'f') {
            for (int k = 0; k < 3; ++k) {
                corners.push_back(uint32_t(std::strtoul(s, &end, 10) - 1));
                shape.normal_index.push_back(uint32_t(std::strtoul(end + 2, &end, 10) - 1));  // skips "//"
                s = end;
            }
        }
    }
    scene.triangles += corners.size() / 3;
    add_triangles(device, rtc, scene, positions, corners, std::move(shape));
}

/// Reads SCENE.rays into `scene` and Embree's geometry into `rtc`.
void read_scene(const char* path, RTCDevice device, RTCScene rtc, Scene& scene) {
    std::ifstream file(path);
    if (!file) throw std::runtime_error(std::string("cannot read ") + path);
    Vec eye, look_at, up;
    float fov = 60;
    std::vector<float>& sphere_data = scene.sphere_data;
    Shape spheres;
    spheres.kind = Shape::spheres;
    std::string line, item;
    size_t line_number = 0;
    const auto refuse = [&](const std::string& why) {
        throw std::runtime_error(std::string(path) + ":" + std::to_string(line_number) + ": " + why +
                                 " (bench/embree_rate.py writes these files from a scene)");
    };
    while (std::getline(file, line)) {
        ++line_number;
        std::istringstream in(line);
        if (!(in >> item)) continue;
        if (item == "camera") {
            eye = read_vec(in), look_at = read_vec(in), up = read_vec(in);
            in >> fov;
        } else if (item == "image") {
            in >> scene.width >> scene.height;
        } else if (item == "max_depth") {
            in >> scene.max_depth;
        } else if (item == "light") {
            scene.lights.push_back(read_vec(in));
        } else if (item == "plane") {
            const Vec p = read_vec(in), n = normalize(read_vec(in));
            Shape shape;
            in >> shape.km;
            shape.plane_normal = n;
            const Vec a = normalize(cross(n, std::fabs(n.x) < 0.9f ? Vec{1, 0, 0} : Vec{0, 1, 0})) * 1e5f;
            const Vec b = cross(n, a);
            add_triangles(device, rtc, scene, {p - a - b, p + a - b, p + a + b, p - a + b}, {0, 1, 2, 0, 2, 3}, shape);
        } else if (item == "sphere") {
            const Vec c = read_vec(in);
            float r, km;
            in >> r >> km;
            sphere_data.insert(sphere_data.end(), {c.x, c.y, c.z, r});
            spheres.centres.push_back(c);
            spheres.sphere_km.push_back(km);
        } else if (item == "mesh") {
            std::string obj;
            float km, m[12];
            in >> obj >> km;
            for (float& x : m) in >> x;
            if (!in) refuse("a mesh line needs a file, km and 12 numbers");
            add_mesh(device, rtc, scene, obj, km, m);
        } else {
            refuse("'" + item + "' is not an item of a .rays file");
        }
        if (in.fail()) refuse("a number is missing or not a number");
    }
    if (scene.width <= 0 || scene.height <= 0) refuse("no 'image WIDTH HEIGHT' line");
    if (!sphere_data.empty()) {
        // All the spheres in one geometry: Embree's own sphere primitive, or user geometry.
        RTCGeometry geometry;
        if (scene.user_spheres) {
            geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER);
            rtcSetGeometryUserPrimitiveCount(geometry, unsigned(sphere_data.size() / 4));
            rtcSetGeometryUserData(geometry, sphere_data.data());
            rtcSetGeometryBoundsFunction(geometry, sphere_bounds, nullptr);
            rtcSetGeometryIntersectFunction(geometry, sphere_intersect);
            rtcSetGeometryOccludedFunction(geometry, sphere_occluded);
        } else {
            geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
            auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(
                geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), sphere_data.size() / 4));
            std::copy(sphere_data.begin(), sphere_data.end(), v);
        }
        rtcCommitGeometry(geometry);
        scene.spheres = spheres.centres.size();
        scene.shapes.resize(rtcAttachGeometry(rtc, geometry) + 1);
        scene.shapes.back() = std::move(spheres);
        rtcReleaseGeometry(geometry);
    }
    // Whitted's camera (docs/scene-format.md §5.1): fov across the width.
    const Vec f = normalize(look_at - eye);
    const float aspect = float(scene.width) / float(scene.height);
    scene.eye = eye;
    scene.forward = f * (1.0f / (2.0f * std::tan(fov * float(M_PI) / 360.0f)));
    scene.right = normalize(cross(f, up)) * aspect;
    scene.up = cross(f, normalize(cross(up, f)));
    scene.forward = scene.forward * aspect;
}

/// Embree's calls of W lanes (RTCRayHitNt<W> is laid out as RTCRayHit4/8/16).
template <int W>
void intersect(const int* valid, RTCScene rtc, RTCIntersectContext* context, RTCRayHitNt<W>& rays) {
    if constexpr (W == 16) rtcIntersect16(valid, rtc, context, reinterpret_cast<RTCRayHit16*>(&rays));
    if constexpr (W == 8) rtcIntersect8(valid, rtc, context, reinterpret_cast<RTCRayHit8*>(&rays));
    if constexpr (W == 4) rtcIntersect4(valid, rtc, context, reinterpret_cast<RTCRayHit4*>(&rays));
}
template <int W>
void occluded(const int* valid, RTCScene rtc, RTCIntersectContext* context, RTCRayNt<W>& rays) {
    if constexpr (W == 16) rtcOccluded16(valid, rtc, context, reinterpret_cast<RTCRay16*>(&rays));
    if constexpr (W == 8) rtcOccluded8(valid, rtc, context, reinterpret_cast<RTCRay8*>(&rays));
    if constexpr (W == 4) rtcOccluded4(valid, rtc, context, reinterpret_cast<RTCRay4*>(&rays));
}

/// One ray of a 16-ray packet, as Whitted holds it before handing Embree its lanes.
struct Ray {
    Vec origin, direction;
    float t_min = 0, t_max = 0;
};

template <class Packet>
void set_lane(Packet& p, int lane, const Ray& ray, bool active) {
    p.org_x[lane] = ray.origin.x, p.org_y[lane] = ray.origin.y, p.org_z[lane] = ray.origin.z;
    p.dir_x[lane] = ray.direction.x, p.dir_y[lane] = ray.direction.y, p.dir_z[lane] = ray.direction.z;
    p.tnear[lane] = active ? ray.t_min : 0;
    p.tfar[lane] = active ? ray.t_max : -INFINITY;  // an unused lane, as Embree writes one
    p.time[lane] = 0, p.mask[lane] = active ? ~0u : 0, p.id[lane] = unsigned(lane), p.flags[lane] = 0;
}

/// The 16 rays of a packet, with `active` ones, through Embree's W-wide calls (Whitted's
/// in_native_groups): a group with no active ray is not called. Occlusion answers in `hit`
/// (true: blocked); intersection gives t, geomID, primID, u, v.
template <int W>
void trace(RTCScene rtc, RTCIntersectContext* context, const Ray* rays, const bool* active, bool shadow, float* t,
           unsigned* geom, unsigned* prim, float* u, float* v, bool* hit) {
    for (int first = 0; first < 16; first += W) {
        alignas(64) int valid[W];
        alignas(64) RTCRayHitNt<W> packet;
        bool any = false;
        for (int lane = 0; lane < W; ++lane) {
            valid[lane] = active[first + lane] ? -1 : 0;
            any |= active[first + lane];
            set_lane(packet.ray, lane, rays[first + lane], active[first + lane]);
            packet.hit.geomID[lane] = RTC_INVALID_GEOMETRY_ID;
        }
        if (!any) continue;
        if (shadow) {
            occluded<W>(valid, rtc, context, packet.ray);
            for (int lane = 0; lane < W; ++lane) hit[first + lane] = packet.ray.tfar[lane] == -INFINITY;
            continue;
        }
        intersect<W>(valid, rtc, context, packet);
        for (int lane = 0; lane < W; ++lane) {
            const int i = first + lane;
            hit[i] = active[i] && packet.hit.geomID[lane] != RTC_INVALID_GEOMETRY_ID;
            t[i] = packet.ray.tfar[lane], geom[i] = packet.hit.geomID[lane], prim[i] = packet.hit.primID[lane];
            u[i] = packet.hit.u[lane], v[i] = packet.hit.v[lane];
        }
    }
}

/// Whitted's paths for one 4x4 packet of camera rays: at each hit an occlusion ray per light
/// that faces it (n·l > 1e-10, the normal turned toward the ray) and a mirror ray where km > 0,
/// up to max_depth hits; the same spans as Whitted's `exact` rays (RaySpans: fractions of the
/// hit's distance from the eye).
template <int W>
void trace_packet(const Scene& scene, RTCScene rtc, Ray* rays, bool* active, Counts& counts) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;  // as Whitted's packets
    uint64_t shadow_count = 0, reflected_count = 0;
    for (int level = 0; level < scene.max_depth; ++level) {
        float t[16], u[16], v[16];
        unsigned geom[16], prim[16];
        bool found[16] = {};
        trace<W>(rtc, &context, rays, active, false, t, geom, prim, u, v, found);
        Vec point[16], normal[16];
        float km[16], distance[16];
        bool any = false;
        for (int i = 0; i < 16; ++i) {
            active[i] = found[i];
            if (!found[i]) continue;
            any = true;
            const Shape& shape = scene.shapes[geom[i]];
            point[i] = rays[i].origin + rays[i].direction * t[i];
            km[i] = shape.kind == Shape::spheres ? shape.sphere_km[prim[i]] : shape.km;
            if (shape.kind == Shape::plane) {
                normal[i] = shape.plane_normal;
            } else if (shape.kind == Shape::spheres) {
                normal[i] = normalize(point[i] - shape.centres[prim[i]]);
            } else {
                const uint32_t* n = &shape.normal_index[3 * prim[i]];
                normal[i] = normalize(shape.normals[n[0]] * (1 - u[i] - v[i]) + shape.normals[n[1]] * u[i] +
                                      shape.normals[n[2]] * v[i]);
            }
            if (dot(normal[i], rays[i].direction) > 0) normal[i] = normal[i] * -1.0f;
            const Vec from_eye = point[i] - scene.eye;
            distance[i] = std::sqrt(dot(from_eye, from_eye));
        }
        if (!any) break;
        for (const Vec& light : scene.lights) {
            Ray shadow[16];
            bool tested[16] = {}, blocked[16];
            for (int i = 0; i < 16; ++i) {
                if (!active[i]) continue;
                const Vec to_light = light - point[i];
                const float light_distance = std::sqrt(dot(to_light, to_light));
                const Vec l = to_light * (1.0f / light_distance);
                const float window = 2e-4f * distance[i];
                shadow[i] = {point[i], l, window, light_distance - window};
                tested[i] = dot(normal[i], l) > 1e-10f && shadow[i].t_max > shadow[i].t_min;
                shadow_count += tested[i];
            }
            trace<W>(rtc, &context, shadow, tested, true, t, geom, prim, u, v, blocked);
        }
        for (int i = 0; i < 16; ++i) {
            if (!active[i]) continue;
            active[i] = km[i] > 0 && level + 1 < scene.max_depth;
            if (!active[i]) continue;
            const Vec d = rays[i].direction;
            rays[i] = {point[i], d - normal[i] * (2 * dot(d, normal[i])), 2e-5f * distance[i], 1e16f};
            ++reflected_count;
        }
    }
    counts.shadow += shadow_count;
    counts.reflected += reflected_count;
}

/// Every 4x4 packet of a 32x32 tile (Whitted's render_tile_size), the tiles shared by TBB.
template <int W>
double render(const Scene& scene, RTCScene rtc, Counts& counts) {
    constexpr int tile = 32;
    const int tiles_x = (scene.width + tile - 1) / tile, tiles_y = (scene.height + tile - 1) / tile;
    const auto start = std::chrono::steady_clock::now();
    tbb::parallel_for(tbb::blocked_range<int>(0, tiles_x * tiles_y, 1), [&](const tbb::blocked_range<int>& range) {
        for (int t = range.begin(); t != range.end(); ++t) {
            const int x0 = (t % tiles_x) * tile, y0 = (t / tiles_x) * tile;
            const int x1 = std::min(x0 + tile, scene.width), y1 = std::min(y0 + tile, scene.height);
            uint64_t camera = 0;
            for (int by = y0; by < y1; by += 4) {
                for (int bx = x0; bx < x1; bx += 4) {
                    Ray rays[16];
                    bool active[16] = {};
                    for (int k = 0; k < 16; ++k) {
                        const int x = bx + k % 4, y = by + k / 4;
                        if (x >= x1 || y >= y1) continue;
                        const float sx = (x + 0.5f) / float(scene.width) - 0.5f;
                        const float sy = 0.5f - (y + 0.5f) / float(scene.height);
                        rays[k] = {scene.eye, normalize(scene.forward + scene.right * sx + scene.up * sy), 0, 1e16f};
                        active[k] = true;
                        ++camera;
                    }
                    trace_packet<W>(scene, rtc, rays, active, counts);
                }
            }
            counts.camera += camera;
        }
    });
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

int run(int argc, char** argv) {
    if (argc < 2 || std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h") {
        std::fprintf(argc < 2 ? stderr : stdout, "usage: %s SCENE.rays [--threads N] [--sphere-points]\n", argv[0]);
        return argc < 2 ? 2 : 0;
    }
    int threads = 2;
    Scene scene;
    for (int a = 2; a < argc; ++a) {
        if (std::string(argv[a]) == "--threads" && a + 1 < argc) threads = std::atoi(argv[a + 1]);
        if (std::string(argv[a]) == "--sphere-points") scene.user_spheres = false;
    }
    // The same device settings as Whitted's (accelerator_device.cpp): its thread count, and
    // WHITTED_EMBREE_ISA as Embree's isa= when set.
    std::string config = "verbose=0,threads=" + std::to_string(threads);
    const char* isa = std::getenv("WHITTED_EMBREE_ISA");
    if (isa && *isa) {
        const std::string names[] = {"sse2", "sse4.2", "avx", "avx2", "avx512"};  // Whitted's list
        if (std::find(std::begin(names), std::end(names), isa) == std::end(names)) {
            std::fprintf(stderr, "WHITTED_EMBREE_ISA=%s: not one of sse2, sse4.2, avx, avx2, avx512\n", isa);
            return 2;
        }
        config += std::string(",isa=") + isa;
    }
    tbb::global_control parallelism(tbb::global_control::max_allowed_parallelism, size_t(threads));
    RTCDevice device = rtcNewDevice(config.c_str());
    if (!device) {
        std::fprintf(stderr, "cannot create the Embree device (%s)\n", config.c_str());
        return 1;
    }
    RTCScene rtc = rtcNewScene(device);
    rtcSetSceneFlags(rtc, RTC_SCENE_FLAG_ROBUST);  // Whitted's watertight test
    read_scene(argv[1], device, rtc, scene);
    // Whitted's build quality (accelerator_build.cpp, build_quality): low once the primitives,
    // spheres counting half, outnumber a quarter of the camera rays. A triangle geometry's own
    // quality is medium by default, so low is set on each as well.
    const bool low = double(scene.triangles) + 0.5 * double(scene.spheres) > double(scene.width) * scene.height / 4;
    const RTCBuildQuality quality = low ? RTC_BUILD_QUALITY_LOW : RTC_BUILD_QUALITY_MEDIUM;
    rtcSetSceneBuildQuality(rtc, quality);
    for (unsigned id = 0; id < scene.shapes.size(); ++id) {
        RTCGeometry geometry = rtcGetGeometry(rtc, id);
        rtcSetGeometryBuildQuality(geometry, quality);
        rtcCommitGeometry(geometry);
    }
    const auto build_start = std::chrono::steady_clock::now();
    rtcCommitScene(rtc);
    const double build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - build_start).count();
    const int width = rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED)  ? 16
                      : rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED) ? 8
                                                                                                : 4;
    Counts counts;
    const double seconds = width == 16  ? render<16>(scene, rtc, counts)
                           : width == 8 ? render<8>(scene, rtc, counts)
                                        : render<4>(scene, rtc, counts);
    const uint64_t total = counts.camera + counts.shadow + counts.reflected;
    const char* spheres = !scene.spheres ? "" : scene.user_spheres ? " (user geometry)" : " (sphere points)";
    std::printf("embree: %zu triangles, %zu spheres%s, quality %s, %d-wide calls, %d thread(s)\n", scene.triangles,
                scene.spheres, spheres, low ? "low" : "medium", width, threads);
    std::printf("rays: camera %llu shadow %llu reflected %llu total %llu\n", (unsigned long long)counts.camera.load(),
                (unsigned long long)counts.shadow.load(), (unsigned long long)counts.reflected.load(),
                (unsigned long long)total);
    std::printf("build %.4f s (rtcCommitScene)\n", build_seconds);
    std::printf("trace %.4f s, %.2f M rays/s\n", seconds, double(total) / seconds / 1e6);
    rtcReleaseScene(rtc);
    rtcReleaseDevice(device);
    return 0;
}

int main(int argc, char** argv) {
    // A file that cannot be read or is not a .rays file is a message and exit 1, not an abort.
    try {
        return run(argc, argv);
    } catch (const std::exception& error) {
        std::fprintf(stderr, "%s: %s\n", argv[0], error.what());
        return 1;
    }
}
