// SPDX-License-Identifier: MIT
// The lecture's shading model on single hits, against the formula written out by hand:
//   L = ka·Ia + Σ_i [kd·I_i·(n·l_i) + ks·I_i·max(0, n·h_i)^p] + km·L(r)
// with the scene-format v1 rules: the n·l gate removes both terms, a shadowed light adds
// neither, directional lights have l = −direction everywhere.

#include "render/shading.h"
#include "render/accelerator.h"
#include "scene/scene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

namespace whitted {
namespace {

constexpr double tolerance = 1e-12;

void expect_color_near(const Color& actual, const Color& expected, double tol) {
    EXPECT_NEAR(actual.x, expected.x, tol);
    EXPECT_NEAR(actual.y, expected.y, tol);
    EXPECT_NEAR(actual.z, expected.z, tol);
}

// The floor y = 0 seen from (0, 1, 1) through the origin: at the hit n = (0, 1, 0) and
// v = (0, 1, 1)/√2.
const Vec3 eye{0, 1, 1};
const Vec3 up_normal{0, 1, 0};
const Vec3 to_eye = normalize(eye);

Scene floor_scene(const Material& material) {
    Scene scene;
    scene.width = scene.height = 1;
    scene.max_depth = 5;
    scene.ambient = Color(1.0);
    scene.background = Color(0.0);
    scene.materials = {material};
    scene.planes = {{Vec3{0, 0, 0}, up_normal, 0}};
    return scene;
}

Material material(const Color& ka, const Color& kd, const Color& ks, double p, Highlight highlight = Highlight::blinn) {
    return {ka, kd, ks, p, Color(0.0), highlight};
}

Light point_light(const Vec3& position, const Color& intensity) {
    return {LightType::point, position, {}, intensity};
}

Light directional_light(const Vec3& direction, const Color& intensity) {
    return {LightType::directional, {}, -normalize(direction), intensity};
}

Color trace_from(const Scene& scene, const Vec3& origin, const Vec3& target) {
    // The ray leaves the camera: the exact rule's windows (RaySpans) measure from the eye.
    Scene placed = scene;
    placed.camera.eye = origin;
    const Accelerator accelerator(placed);
    const LectureShading shading(placed, accelerator);
    RayCounts counts;
    return shading.trace({origin, normalize(target - origin), 1e-4, 1e7}, 0, counts);
}

TEST(Shading, AmbientAloneIsKaTimesIaPerChannel) {
    Scene scene = floor_scene(material({0.2, 0.3, 0.4}, Color(1.0), Color(1.0), 10));
    scene.ambient = {0.5, 1.0, 2.0};
    expect_color_near(trace_from(scene, eye, {0, 0, 0}), {0.2 * 0.5, 0.3 * 1.0, 0.4 * 2.0}, tolerance);
}

// Light at (1, 2, 0) over the origin: l = (1, 2, 0)/√5, so n·l = 2/√5; the Blinn half vector is
// l + v = (1/√5, 2/√5 + 1/√2, 1/√2) normalised.
TEST(Shading, DiffusePlusBlinnHighlightInClosedForm) {
    const Color ka{0.05, 0.1, 0.15}, kd{0.3, 0.6, 0.9}, intensity{1, 0.5, 0.25};
    const double ks = 0.4, p = 7;
    Scene scene = floor_scene(material(ka, kd, Color(ks), p));
    scene.lights = {point_light({1, 2, 0}, intensity)};
    const double s5 = std::sqrt(5.0), s2 = std::sqrt(2.0);
    const double n_dot_l = 2 / s5;
    const Vec3 half{1 / s5, 2 / s5 + 1 / s2, 1 / s2};
    const double n_dot_h = half.y / length(half);
    const Color expected = ka + kd * intensity * n_dot_l + intensity * (ks * std::pow(n_dot_h, p));
    expect_color_near(trace_from(scene, eye, {0, 0, 0}), expected, tolerance);
}

// highlight: phong uses the mirrored view r_v = (0, 1, −1)/√2, so r_v·l = 2/√10.
TEST(Shading, PhongHighlightUsesMirroredViewRay) {
    const Color kd{0.2, 0.2, 0.2}, intensity{1, 1, 1};
    const double ks = 0.7, p = 3;
    Scene scene = floor_scene(material(Color(0.0), kd, Color(ks), p, Highlight::phong));
    scene.lights = {point_light({1, 2, 0}, intensity)};
    const double expected = 0.2 * (2 / std::sqrt(5.0)) + ks * std::pow(2 / std::sqrt(10.0), p);
    expect_color_near(trace_from(scene, eye, {0, 0, 0}), Color(expected), tolerance);
}

// A light below the floor: n·l < 0, so neither diffuse nor highlight, although the lecture's
// max(0, n·h)^p alone would still be positive here.
TEST(Shading, LightBehindSurfaceRemovesHighlightToo) {
    const Material m = material({0.1, 0.2, 0.3}, Color(1.0), Color(1.0), 1);
    Scene scene = floor_scene(m);
    const Vec3 light{3, -0.5, -1};
    scene.lights = {point_light(light, Color(1.0))};
    const Vec3 to_light = normalize(light);
    ASSERT_LT(dot(up_normal, to_light), 0);
    ASSERT_GT(LectureShading::specular_lobe(m, up_normal, to_eye, to_light), 0.1);  // what the gate must remove
    expect_color_near(trace_from(scene, eye, {0, 0, 0}), {0.1, 0.2, 0.3}, tolerance);
}

// A sphere between the hit and a light straight above: that light adds neither term. A sphere
// beyond the light, or the same light unblocked, shows what the light would have added.
TEST(Shading, ShadowedLightAddsNeitherTerm) {
    const Color ka{0.1, 0.2, 0.3}, kd{0.5, 0.5, 0.5};
    const double ks = 0.5, p = 4;
    Scene scene = floor_scene(material(ka, kd, Color(ks), p));
    scene.lights = {point_light({0, 5, 0}, Color(1.0))};
    scene.spheres = {{nullptr, {0, 2.5, 0}, 0.5, 0}};
    expect_color_near(trace_from(scene, eye, {0, 0, 0}), ka, tolerance);

    // l = (0, 1, 0): n·l = 1, n·h = (1 + 1/√2)/|(0, 1 + 1/√2, 1/√2)|.
    const double s2 = std::sqrt(2.0);
    const double n_dot_h = (1 + 1 / s2) / length(Vec3{0, 1 + 1 / s2, 1 / s2});
    const Color lit = ka + kd + Color(ks * std::pow(n_dot_h, p));
    scene.spheres = {{nullptr, {0, 7, 0}, 0.5, 0}};  // beyond the light: no shadow
    expect_color_near(trace_from(scene, eye, {0, 0, 0}), lit, tolerance);
    scene.spheres.clear();
    expect_color_near(trace_from(scene, eye, {0, 0, 0}), lit, tolerance);
}

// Directional light: l = −direction/|direction| at every point, so two different hits on the
// floor get the same diffuse kd·I·(n·l) with n·l = 2/|(−1, 2, −0.5)|.
TEST(Shading, DirectionalLightIsTheSameEverywhere) {
    const Color kd{0.8, 0.4, 0.2}, intensity{0.5, 1.0, 1.5};
    Scene scene = floor_scene(material(Color(0.0), kd, Color(0.0), 1));
    scene.lights = {directional_light({1, -2, 0.5}, intensity)};
    const Color expected = kd * intensity * (2 / length(Vec3{-1, 2, -0.5}));
    expect_color_near(trace_from(scene, eye, {0, 0, 0}), expected, tolerance);
    expect_color_near(trace_from(scene, {10, 1, -3}, {10, 0, -4}), expected, tolerance);
    expect_color_near(trace_from(scene, {-300, 2, 50}, {-290, 0, 45}), expected, tolerance);
}

// A directional light is shadowed by anything up-beam of the point, however far.
TEST(Shading, DirectionalLightIsShadowed) {
    const Color ka{0.01, 0.02, 0.03};
    Scene scene = floor_scene(material(ka, Color(1.0), Color(1.0), 5));
    const Vec3 direction{1, -2, 0.5};
    scene.lights = {directional_light(direction, Color(1.0))};
    const Vec3 up_beam = -normalize(direction) * 100.0;  // 100 units toward the light from the origin
    scene.spheres = {{nullptr, up_beam, 1.0, 0}};
    expect_color_near(trace_from(scene, eye, {0, 0, 0}), ka, tolerance);
}

// With n = +y, v at angle a on one side and l at angle b on the other, in one plane:
// n·h = cos((a − b)/2) and r_v·l = cos(a − b). So Blinn gives cos((a−b)/2)^p, Phong cos(a−b)^p.
TEST(Shading, BlinnAndPhongLobesInClosedForm) {
    const double a = 60 * std::numbers::pi / 180, b = 20 * std::numbers::pi / 180, p = 10;
    const Vec3 v{std::sin(a), std::cos(a), 0}, l{-std::sin(b), std::cos(b), 0};
    const Material blinn = material({}, {}, Color(1.0), p, Highlight::blinn);
    const Material phong = material({}, {}, Color(1.0), p, Highlight::phong);
    EXPECT_NEAR(LectureShading::specular_lobe(blinn, up_normal, v, l), std::pow(std::cos((a - b) / 2), p), 1e-14);
    EXPECT_NEAR(LectureShading::specular_lobe(phong, up_normal, v, l), std::pow(std::cos(a - b), p), 1e-14);
    // Light exactly along the mirrored view ray: both lobes peak at 1.
    const Vec3 mirrored{-std::sin(a), std::cos(a), 0};
    EXPECT_NEAR(LectureShading::specular_lobe(blinn, up_normal, v, mirrored), 1.0, 1e-14);
    EXPECT_NEAR(LectureShading::specular_lobe(phong, up_normal, v, mirrored), 1.0, 1e-14);
}

// Light and eye together at 80° from n: r_v·l = cos 160° < 0, so Phong gives 0, while h = v
// and Blinn gives cos(80°)^p.
TEST(Shading, PhongLobeClampsAtZeroWhereBlinnDoesNot) {
    const double a = 80 * std::numbers::pi / 180, p = 2;
    const Vec3 v{std::sin(a), std::cos(a), 0};
    const Material blinn = material({}, {}, Color(1.0), p, Highlight::blinn);
    const Material phong = material({}, {}, Color(1.0), p, Highlight::phong);
    EXPECT_EQ(LectureShading::specular_lobe(phong, up_normal, v, v), 0.0);
    EXPECT_NEAR(LectureShading::specular_lobe(blinn, up_normal, v, v), std::pow(std::cos(a), p), 1e-14);
}

// The local terms as one function, against the slide written out: ka·Ia + Σ over the lights
// that arrive of kd·I·max(0, n·l) + ks·I·(n·h)^p. A light that does not arrive adds neither
// term; one arriving with n·l < 0 (the course's convention, which has no gate) adds only its
// highlight.
TEST(Shading, LocalTermsAreTheSlide) {
    const Color ka{0.1, 0.2, 0.3}, kd{0.5, 0.25, 0.125}, ks{0.3, 0.3, 0.6}, ambient{0.5, 1.0, 2.0};
    const double p = 8;
    const Material m = material(ka, kd, ks, p);
    const double b = 30 * std::numbers::pi / 180;
    const Vec3 l{-std::sin(b), std::cos(b), 0}, below{0, -std::sqrt(0.5), std::sqrt(0.5)};
    const Color i1{1, 0.5, 0.25}, i2{2, 2, 2}, i3{0.25, 0.5, 1};
    const ArrivingLight lights[] = {
        {l, dot(up_normal, l), i1, true}, {below, 0.0, i2, false}, {below, dot(up_normal, below), i3, true}};
    const auto lobe = [&](const Vec3& to_light) { return std::pow(dot(up_normal, normalize(to_eye + to_light)), p); };
    const Color expected = ka * ambient + kd * i1 * std::cos(b) + ks * i1 * lobe(l) + ks * i3 * lobe(below);
    expect_color_near(LectureShading::local_terms(m, ambient, up_normal, to_eye, lights, 3), expected, 1e-14);
    // Each light's share is the same function's.
    const LightShare share = LectureShading::light_terms(m, up_normal, to_eye, lights[2]);
    expect_color_near(share.diffuse, Color(0.0), 0.0);
    expect_color_near(share.specular, ks * i3 * lobe(below), 1e-14);
    expect_color_near(LectureShading::ambient_term(m, ambient), ka * ambient, 0.0);
}

// r = 2(n·v)n − v: v at 60° from n on one side leaves at 60° on the other.
TEST(Shading, MirrorDirectionIsVReflectedAboutN) {
    const double a = 60 * std::numbers::pi / 180;
    const Vec3 r = LectureShading::mirror_direction(up_normal, {std::sin(a), std::cos(a), 0});
    expect_color_near(r, {-std::sin(a), std::cos(a), 0}, 1e-15);
}

// Without a glaze the mirror ray has weight km beside the whole local terms; with one, F·L(r)
// beside (1 − F)·local, F = R0 + (1 − R0)(1 − n·v)^5.
TEST(Shading, ReflectanceIsKmOrSchlicksSplit) {
    Material m = material({}, {}, {}, 1);
    m.km = {0.1, 0.2, 0.3};
    const Reflectance plain = LectureShading::reflectance(m, up_normal, to_eye);
    EXPECT_EQ(plain.local, 1.0);
    expect_color_near(plain.mirror, m.km, 0.0);
    m.fresnel_r0 = 0.04;
    const double f = 0.04 + 0.96 * std::pow(1 - 1 / std::sqrt(2.0), 5);
    const Reflectance glazed = LectureShading::reflectance(m, up_normal, to_eye);
    EXPECT_NEAR(glazed.local, 1 - f, 1e-15);
    expect_color_near(glazed.mirror, Color(f), 1e-15);
}

// Surfaces are two-sided: the floor seen from below, lit from below, shades like from above.
TEST(Shading, BackFaceIsLitFromItsOwnSide) {
    const Color kd{0.3, 0.6, 0.9};
    Scene scene = floor_scene(material(Color(0.0), kd, Color(0.0), 1));
    scene.lights = {point_light({1, -2, 0}, Color(1.0))};
    expect_color_near(trace_from(scene, {0, -1, 1}, {0, 0, 0}), kd * (2 / std::sqrt(5.0)), tolerance);
}

// Two lights add; the second one here has n·l = 1/√2 (light at (0, 1, −1)).
TEST(Shading, LightsAdd) {
    const Color kd{0.5, 0.25, 0.125};
    Scene scene = floor_scene(material(Color(0.0), kd, Color(0.0), 1));
    scene.lights = {point_light({1, 2, 0}, {1, 0, 0}), point_light({0, 1, -1}, {0, 1, 1})};
    const Color expected = kd * Color{1, 0, 0} * (2 / std::sqrt(5.0)) + kd * Color{0, 1, 1} * (1 / std::sqrt(2.0));
    expect_color_near(trace_from(scene, eye, {0, 0, 0}), expected, tolerance);
}

// Rays that hit nothing return the background; max_depth 1 allows no mirror bounce at all.
TEST(Shading, MissGivesBackgroundAndMaxDepthOneHasNoMirror) {
    Material mirror = material({0.1, 0.1, 0.1}, Color(0.0), Color(0.0), 1);
    mirror.km = Color(0.5);
    Scene scene = floor_scene(mirror);
    scene.background = {0.2, 0.4, 0.6};
    expect_color_near(trace_from(scene, eye, {0, 2, 0}), scene.background, 0.0);  // looking up: no hit
    // One bounce: ka + km·background.
    expect_color_near(trace_from(scene, eye, {0, 0, 0}), Color{0.1, 0.1, 0.1} + Color{0.1, 0.2, 0.3}, tolerance);
    scene.max_depth = 1;
    expect_color_near(trace_from(scene, eye, {0, 0, 0}), Color(0.1), tolerance);
}

}  // namespace
}  // namespace whitted

// --- Refraction (Whitted 1980's transmitted ray): kt·L(t), t by Snell's law ---

namespace whitted {
namespace {

/// Records the rays the shading sends on, lane 0 only.
struct RecordedRays final : PathObserver {
    struct Sent {
        int level;
        Ray ray;
        Color weight;
    };
    std::vector<Sent> mirrors, refracted;
    void miss(int, int, const Ray&, const Color&, const Color&) override {}
    void hit(int, int, const Ray&, const SurfaceHit&, const Vec3&) override {}
    void ambient(int, int, const Color&) override {}
    void light(int, int, size_t, const LightTerms&) override {}
    void local(int, int, const Color&, const Color&, const Color&) override {}
    void mirror(int, int level, const Ray& r, const Color& w) override { mirrors.push_back({level, r, w}); }
    void transmitted(int, int level, const Ray& r, const Color& w) override { refracted.push_back({level, r, w}); }
};

Material glass(double ior, const Color& kt, const Color& km = Color(0.0)) {
    Material m{Color(0.0), Color(0.0), Color(0.0), 1, km, Highlight::blinn};
    m.kt = kt;
    m.ior = ior;
    return m;
}

/// A scene of boxes (material 0 each) and nothing else.
Scene box_scene(const std::vector<Box>& boxes, const std::vector<Material>& materials) {
    Scene scene;
    scene.width = scene.height = 1;
    scene.max_depth = 6;
    scene.ambient = Color(1.0);
    scene.materials = materials;
    scene.boxes = boxes;
    for (size_t i = 0; i < boxes.size(); ++i) {
        scene.boxes[i].object = uint32_t(i + 1);
        scene.objects.push_back({ObjectType::box, {}});
    }
    return scene;
}

RecordedRays record(const Scene& scene, const Ray& ray) {
    const Accelerator accelerator(scene);
    const LectureShading shading(scene, accelerator);
    RecordedRays recorded;
    RayCounts counts;
    Color radiance;
    shading.trace_packet(&ray, 1, 0, &radiance, counts, recorded);
    return recorded;
}

}  // namespace

// The objects a refracted ray is inside: every sequence of entering (push_back), leaving the
// innermost (pop_back) and leaving another (erase) gives the list a plain vector gives, through
// the change from the entries held in place to the heap and back, and a copy is the same list.
TEST(Interiors, KeepTheObjectsInOrderAsAPlainListDoes) {
    std::mt19937 random(20261206);
    for (int run = 0; run < 200; ++run) {
        Interiors list;
        std::vector<Interiors::Entry> model;
        for (int step = 0; step < 60; ++step) {
            const auto choice = random() % 3;
            if (model.empty() || choice == 0) {
                const Interiors::Entry entry{uint32_t(random() % 1000), 1.0 + double(random() % 100) / 64.0};
                list.push_back(entry);
                model.push_back(entry);
            } else if (choice == 1) {
                list.pop_back();
                model.pop_back();
            } else {
                const size_t at = random() % model.size();
                list.erase(list.begin() + at);
                model.erase(model.begin() + std::ptrdiff_t(at));
            }
            const Interiors copy = list;
            for (const Interiors* seen : {static_cast<const Interiors*>(&list), &copy}) {
                ASSERT_EQ(size_t(seen->end() - seen->begin()), model.size());
                ASSERT_EQ(seen->empty(), model.empty());
                for (size_t i = 0; i < model.size(); ++i) {
                    ASSERT_EQ(seen->begin()[i].object, model[i].object);
                    ASSERT_EQ(seen->begin()[i].ior, model[i].ior);
                }
                if (!model.empty()) {
                    ASSERT_EQ(seen->back().object, model.back().object);
                }
            }
        }
    }
}

TEST(Refraction, ASlabShiftsARayByTheTextbookAmount) {
    // A slab 0 ≤ y ≤ 1 of index 1.5, met at θ = 50° from its normal: inside the ray runs at θ'
    // with sin θ' = sin θ / 1.5, and leaves parallel to where it came from, shifted sideways by
    // d·sin(θ − θ')/cos θ'.
    const double eta = 1.5, theta = 50 * std::numbers::pi / 180;
    const Scene scene = box_scene({{nullptr, {-50, 0, -50}, {50, 1, 50}, 0, 0}}, {glass(eta, Color(1.0))});
    const Vec3 d{std::sin(theta), -std::cos(theta), 0};
    const Ray ray{Vec3{0, 3, 0} - d * 1.0, d, 1e-4, 1e7};
    const RecordedRays recorded = record(scene, ray);
    ASSERT_EQ(recorded.refracted.size(), 2u);  // in through the top, out through the bottom
    const double theta_inside = std::asin(std::sin(theta) / eta);
    const Ray& inside = recorded.refracted[0].ray;
    EXPECT_NEAR(inside.direction.x, std::sin(theta_inside), 1e-14);
    EXPECT_NEAR(inside.direction.y, -std::cos(theta_inside), 1e-14);
    const Ray& out = recorded.refracted[1].ray;
    EXPECT_NEAR(out.direction.x, d.x, 1e-14);
    EXPECT_NEAR(out.direction.y, d.y, 1e-14);
    // The distance between the line it left on and the line it came on.
    const Vec3 offset = out.origin - ray.origin;
    const double shift = length(offset - d * dot(offset, d));
    EXPECT_NEAR(shift, 1.0 * std::sin(theta - theta_inside) / std::cos(theta_inside), 1e-13);
    EXPECT_EQ(recorded.refracted[0].weight, Color(1.0));
}

TEST(Refraction, AnIndexOfOneLeavesTheImageUnchanged) {
    // A clear ball of index 1 over a lit floor: every pixel as without it (its kt = 1 lets
    // camera and shadow rays through unbent and undimmed).
    Scene with = floor_scene(material(Color(0.1), Color(0.7, 0.5, 0.3), Color(0.0), 1));
    with.lights = {point_light({2, 4, 1}, Color(0.9))};
    Scene without = with;
    with.materials.push_back(glass(1.0, Color(1.0)));
    with.spheres = {{nullptr, {0, 0.6, 0}, 0.5, 1, 2}};
    with.objects = {{ObjectType::plane, {}}, {ObjectType::sphere, {}}};
    without.objects = {{ObjectType::plane, {}}};
    with.planes[0].object = without.planes[0].object = 1;
    for (const Vec3 target : {Vec3{0, 0, 0}, Vec3{0.3, 0, -0.2}, Vec3{-0.4, 0, 0.1}, Vec3{0.2, 0.6, 0.1}})
        expect_color_near(trace_from(with, {0, 3, 3}, target), trace_from(without, {0, 3, 3}, target), 1e-12);
}

TEST(Refraction, BeyondTheCriticalAngleTheLightComesBackAlongTheMirror) {
    // Into the top of a tall glass box (index 1.5) at 80°: inside, the ray meets a side at 49°
    // from its normal, beyond the critical angle asin(1/1.5) = 41.8°: no refracted ray there,
    // and the mirror ray carries the path on with weight 1 in place of km (POV-Ray's rule).
    const double theta = 80 * std::numbers::pi / 180;
    const Color kt(0.6, 0.7, 0.8), km(0.1);
    const Scene scene = box_scene({{nullptr, {-1, -10, -50}, {1, 0, 50}, 0, 0}}, {glass(1.5, kt, km)});
    const Vec3 d{std::sin(theta), -std::cos(theta), 0};
    const RecordedRays recorded = record(scene, {Vec3{-0.5, 0, 0} - d * 2.0, d, 1e-4, 1e7});
    ASSERT_GE(recorded.refracted.size(), 1u);
    EXPECT_EQ(recorded.refracted[0].level, 0);
    EXPECT_EQ(recorded.refracted[0].weight, kt);
    // The first mirror ray is the top's own (weight km); the next, at the side, is the total
    // internal reflection: level 1, weight kt·1, and no refracted ray at level 1.
    ASSERT_GE(recorded.mirrors.size(), 2u);
    EXPECT_EQ(recorded.mirrors[0].weight, km);
    EXPECT_EQ(recorded.mirrors[1].level, 1);
    EXPECT_EQ(recorded.mirrors[1].weight, kt);
    const double sin_inside = std::sin(theta) / 1.5, cos_inside = std::sqrt(1 - sin_inside * sin_inside);
    EXPECT_NEAR(recorded.mirrors[1].ray.direction.x, -sin_inside, 1e-14);  // mirrored off the side x = 1
    EXPECT_NEAR(recorded.mirrors[1].ray.direction.y, -cos_inside, 1e-14);
    for (const auto& sent : recorded.refracted) EXPECT_NE(sent.level, 1);
}

TEST(Refraction, AShadowThroughGlassIsTheLightTimesKtAtEachFace) {
    // A floor under a glass sheet (index 1: no bending), the light straight above: the sheet's
    // two faces each multiply the light by kt.
    const Color kt(0.5, 0.25, 1.0), kd(0.8, 0.6, 0.4);
    Scene scene = floor_scene(material(Color(0.0), kd, Color(0.0), 1));
    scene.materials.push_back(glass(1.0, kt));
    scene.boxes = {{nullptr, {-1, 1, -1}, {1, 1.2, 1}, 1, 2}};
    scene.objects = {{ObjectType::plane, {}}, {ObjectType::box, {}}};
    scene.planes[0].object = 1;
    scene.lights = {point_light({0, 5, 0}, Color(1.0))};
    // Seen from the side, under the sheet: n·l = 1.
    expect_color_near(trace_from(scene, {3, 0.5, 0}, {0, 0, 0}), kd * kt * kt, 1e-15);
}

}  // namespace whitted
