// SPDX-License-Identifier: MIT
// ShadingCache (render/reshade.h): an image shaded again from a render's recorded paths, with
// other ka, kd, ks, p, km and light intensities, must be render()'s image of the edited scene
// bit for bit; where the edit would trace a mirror ray the render did not, or moves a light,
// the cache must refuse (the caller renders). The lecture's scenes, shrunk, with random edits;
// and a scene with mirrors, two lights, Phong and Blinn highlights and a min_weight cut-off,
// in both conventions.

#include "render/reshade.h"
#include "render/accelerator.h"
#include "render/renderer.h"
#include "scene/description.h"
#include "scene/scene.h"

#include "test_support.h"

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <sstream>

namespace whitted {
namespace {

bool same_pixels(const Image& a, const Image& b) {
    return a.width == b.width && a.height == b.height && a.rgb.size() == b.rgb.size() &&
           std::memcmp(a.rgb.data(), b.rgb.data(), a.rgb.size() * sizeof(float)) == 0;
}

Image full_render(const Scene& scene) {
    const Accelerator accelerator(scene, 2);
    RenderJob job;
    job.threads = 2;
    return render(scene, accelerator, job).image;
}

template <class T>
void set(Located<T>& field, T value) {
    field.value = value;
    field.given = true;
}

/// Random values for every material's ka, kd, ks, p and km and every light's intensity; a km
/// that was zero stays zero (else the render did not trace its mirror rays), one that was not
/// stays above zero.
void random_edit(SceneDescription& d, std::mt19937& random) {
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const auto colour = [&] { return Color{unit(random), unit(random), unit(random)}; };
    for (MaterialDescription& m : d.materials) {
        set(m.ka, colour() * 0.2);
        set(m.kd, colour());
        set(m.ks, colour());
        // Whole exponents go by repeated squaring, others by std::pow: both.
        set(m.p, unit(random) < 0.5 ? std::floor(1 + 300 * unit(random)) : 0.5 + 100 * unit(random));
        if (!is_zero(m.km.value)) set(m.km, Color{0.05, 0.05, 0.05} + colour() * 0.9);
    }
    for (LightDescription& l : d.lights) set(l.intensity, colour() * 2.0);
}

/// Records `description` rendered, asserts the recording's image is render()'s, then re-shades
/// `edits` random edits and compares each with render() of the edited scene.
void check_random_edits(SceneDescription description, int edits, unsigned seed) {
    const Scene scene = validate_scene(description);
    const Accelerator accelerator(scene, 2);
    Image recorded;
    const ShadingCache cache = ShadingCache::record(scene, accelerator, 2, recorded);
    ASSERT_FALSE(cache.empty());
    const Image rendered = full_render(scene);
    ASSERT_TRUE(same_pixels(recorded, rendered)) << "the recording render differs from render()";
    // A constant image would make the comparisons meaningless.
    ASSERT_GT(std::set<float>(rendered.rgb.begin(), rendered.rgb.end()).size(), 20u);
    Image same;
    ASSERT_TRUE(cache.reshade(scene, 2, same));
    EXPECT_TRUE(same_pixels(same, rendered)) << "re-shading the recorded values";

    std::mt19937 random(seed);
    for (int e = 0; e < edits; ++e) {
        random_edit(description, random);
        const Scene edited = validate_scene(description);
        Image reshaded;
        ASSERT_TRUE(cache.reshade(edited, 2, reshaded)) << "edit " << e;
        const Image expected = full_render(edited);
        EXPECT_TRUE(same_pixels(reshaded, expected)) << "edit " << e << " differs from render()";
        EXPECT_FALSE(same_pixels(reshaded, rendered)) << "edit " << e << " changed nothing";
    }
}

SceneDescription shrunk(const std::string& file, int samples) {
    std::ifstream in(file);
    std::ostringstream text;
    text << in.rdbuf();
    SceneDescription d = parse_any_scene_text(text.str(), file);
    set<int64_t>(d.image.width, d.image.width.value / 10);
    set<int64_t>(d.image.height, d.image.height.value / 10);
    set<int64_t>(d.image.samples, samples);
    return d;
}

TEST(ShadingCache, LectureScenesReshadeToTheRenderOfRandomEdits) {
    const std::filesystem::path dir = std::filesystem::path(WHITTED_SOURCE_DIR) / "examples" / "lecture";
    int scenes = 0;
    unsigned seed = 1;
    for (const auto& entry : std::filesystem::directory_iterator(dir)) {
        if (entry.path().extension() != ".yaml") continue;
        ++scenes;
        for (const int samples : {1, 2}) {
            SCOPED_TRACE(entry.path().filename().string() + ", " + std::to_string(samples) + " sample(s)");
            check_random_edits(shrunk(entry.path().string(), samples), 3, seed++);
        }
    }
    EXPECT_GE(scenes, 9);
}

// Mirrors (km on two materials, to depth 4), a point and a directional light, Phong and Blinn,
// a box, a triangle and a plane; render.min_weight low enough that no path is cut before depth.
std::string mirror_scene(const std::string& convention, double min_weight) {
    return test::join_lines({
        "camera: {eye: [0.3, 1.5, 6], look_at: [0, 0.2, 0], fov: 55}",
        "image: {width: 41, height: 23, background: [0.1, 0.2, 0.3], samples: 2}",
        "render: {max_depth: 4, convention: " + convention + ", min_weight: " + std::to_string(min_weight) + "}",
        "ambient: [0.9, 1, 1.1]",
        "lights:",
        "  - {type: point, position: [-4, 5, 3], intensity: [1, 0.9, 0.8]}",
        "  - {type: directional, direction: [1, -1, -0.5], intensity: 0.4}",
        "materials:",
        "  shiny: {ka: 0.05, kd: [0.6, 0.3, 0.2], ks: 0.5, p: 40, km: 0.3}",
        "  matte: {ka: [0.02, 0.04, 0.06], kd: [0.2, 0.4, 0.6], ks: [0.3, 0.1, 0.0], p: 8, highlight: phong}",
        "  floor: {ka: 0.05, kd: 0.5, km: 0.5}",
        "objects:",
        "  - {type: sphere, center: [-1, 0.2, 0], radius: 1, material: shiny}",
        "  - {type: box, min: [0.5, -1, -1], max: [2, 0.5, 0.5], material: matte,",
        "     transform: [{rotate: {axis: [0, 1, 0], angle: 25}}]}",
        "  - {type: triangle, vertices: [[-2, -1, -2], [2, -1, -2], [0, 2, -2.5]], material: matte}",
        "  - {type: plane, point: [0, -1, 0], normal: [0, 1, 0], material: floor}",
    });
}

TEST(ShadingCache, MirrorsInBothConventionsReshadeToTheRenderOfRandomEdits) {
    for (const char* convention : {"pov", "course"}) {
        SCOPED_TRACE(convention);
        check_random_edits(parse_any_scene_text(mirror_scene(convention, 0.0), "mirrors.yaml"), 4, 7);
    }
}

MaterialDescription& material(SceneDescription& d, const std::string& name) {
    for (MaterialDescription& m : d.materials)
        if (m.name == name) return m;
    throw std::runtime_error("no material " + name);
}

// A path cut short (km to 0) re-shades; one that would now go on (km from 0, or back above
// min_weight's cut-off) is refused, as is a light moved or a transmitting material.
TEST(ShadingCache, RefusesWhatItDidNotRecord) {
    SceneDescription d = parse_any_scene_text(mirror_scene("pov", 0.1), "mirrors.yaml");
    const Scene scene = validate_scene(d);
    const Accelerator accelerator(scene, 2);
    Image image;
    const ShadingCache cache = ShadingCache::record(scene, accelerator, 2, image);
    EXPECT_GT(cache.bytes(), size_t(41 * 23 * 4 * 4));

    SceneDescription cut = d;
    set(material(cut, "floor").km, Color(0.0));
    Image reshaded;
    ASSERT_TRUE(cache.reshade(validate_scene(cut), 2, reshaded)) << "km to 0 only cuts paths short";
    EXPECT_TRUE(same_pixels(reshaded, full_render(validate_scene(cut))));

    SceneDescription more = d;
    set(material(more, "matte").km, Color(0.2));
    EXPECT_FALSE(cache.reshade(validate_scene(more), 2, reshaded)) << "matte's mirror rays were not traced";

    // 0.3 · 0.5 = 0.15 ≥ 0.1 went on, 0.3 · 0.3 = 0.09 did not: now 0.5 · 0.5 = 0.25 would.
    SceneDescription above = d;
    set(material(above, "shiny").km, Color(0.5));
    EXPECT_FALSE(cache.reshade(validate_scene(above), 2, reshaded)) << "a path above the cut-off now";

    SceneDescription moved = d;
    set(moved.lights[0].position, Vec3{-4, 5, 3.5});
    EXPECT_FALSE(cache.reshade(validate_scene(moved), 2, reshaded)) << "a light moved";

    SceneDescription glass = d;
    set(material(glass, "matte").kt, Color(0.5));
    EXPECT_FALSE(cache.reshade(validate_scene(glass), 2, reshaded)) << "transmission";

    SceneDescription bigger = d;
    set<int64_t>(bigger.image.width, 42);
    EXPECT_FALSE(cache.reshade(validate_scene(bigger), 2, reshaded)) << "another image size";
}

}  // namespace
}  // namespace whitted
