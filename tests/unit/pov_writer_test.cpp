// SPDX-License-Identifier: MIT
// The POV-Ray converter (docs/pov-model.md §1): numbers are written so that POV-Ray reads back the
// very doubles Whitted uses, nothing from the scene except numbers reaches the SDL, and the
// lecture's material becomes recipe A (one texture, grey ks) or recipe B (four layered textures).

#include "converters/pov_writer.h"
#include "scene/description.h"

#include "test_support.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>

namespace whitted {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

/// The `count` numbers that follow `prefix` in `text` (separators: spaces, newlines, commas, '<', '>'),
/// read with strtod exactly as a C library reads a decimal.
std::vector<double> numbers_after(const std::string& text, const std::string& prefix, size_t count, size_t from = 0) {
    const size_t at = text.find(prefix, from);
    EXPECT_NE(at, std::string::npos) << "'" << prefix << "' not in the SDL";
    if (at == std::string::npos) return std::vector<double>(count, std::nan(""));
    const char* p = text.c_str() + at + prefix.size();
    std::vector<double> out;
    while (out.size() < count) {
        while (*p == ' ' || *p == ',' || *p == '<' || *p == '>' || *p == '\n') ++p;
        char* end = nullptr;
        const double value = std::strtod(p, &end);
        EXPECT_NE(end, p) << "no number at '" << std::string(p, std::min<size_t>(20, std::strlen(p))) << "'";
        if (end == p) break;
        out.push_back(value);
        p = end;
    }
    return out;
}

/// [x, y, z] in YAML, each number with enough digits to read back the same double.
std::string fmt_vec(const Vec3& v) {
    char buffer[96];
    std::snprintf(buffer, sizeof buffer, "[%.17g, %.17g, %.17g]", v.x, v.y, v.z);
    return buffer;
}

size_t count_of(const std::string& text, const std::string& word) {
    size_t n = 0;
    for (size_t at = text.find(word); at != std::string::npos; at = text.find(word, at + 1)) ++n;
    return n;
}

std::string sdl_for(const std::string& objects_and_materials, const std::string& path = "scene.yaml") {
    const SceneDescription d =
        parse_scene_text("camera: {eye: [0, 1, 5], look_at: [0, 0, 0], fov: 50}\nimage: {width: 40, height: 30}\n" +
                             objects_and_materials,
                         path);
    const Scene scene = validate_scene(d);  // the converter's input is always a valid scene
    return pov::scene_to_sdl(d, scene);
}

// Lights and objects sit in one light_group, after the camera: POV-Ray keeps no shadow cache
// for a light-group light (docs/pov-model.md §3). The group lights only what it holds, so every
// object must be inside it, and `global_lights off` keeps nothing outside it lit twice.
TEST(PovWriter, LightsAndObjectsShareOneLightGroup) {
    const std::string sdl = sdl_for(
        "lights: [{type: point, position: [1, 2, 3]}, {type: directional, direction: [0, -1, 0]}]\n"
        "objects:\n  - {type: sphere, center: [0, 0, 0], radius: 1, material: {kd: 0.5}}\n"
        "  - {type: plane, point: [0, -1, 0], normal: [0, 1, 0], material: {kd: 0.5}}\n");
    ASSERT_EQ(count_of(sdl, "light_group {"), 1u);
    const size_t group = sdl.find("light_group {");
    EXPECT_LT(sdl.find("camera {"), group);
    const size_t end = sdl.rfind("global_lights off");
    ASSERT_NE(end, std::string::npos);
    for (const char* word : {"light_source {", "sphere {", "plane {"}) {
        for (size_t at = sdl.find(word); at != std::string::npos; at = sdl.find(word, at + 1)) {
            EXPECT_GT(at, group) << word;
            EXPECT_LT(at, end) << word;
        }
    }
    EXPECT_EQ(sdl.substr(end), "global_lights off\n}\n");  // the group closes the file
    // Without objects there is nothing to light: no group (POV-Ray refuses an empty one).
    EXPECT_EQ(count_of(sdl_for("lights: [{type: point, position: [1, 2, 3]}]\n"), "light_group"), 0u);
}

// A mesh far from the origin (further than its half extent) is written about the centre of its
// bounds plus `translate`, so that POV-Ray's float plane distances stay small; the written
// vertices are exactly the float offsets Whitted stores (mesh_origin). A mesh around the origin
// is written as it is, with no translate.
TEST(PovWriter, FarMeshWrittenAboutItsOwnCentreWithTheFloatOffsetsWhittedStores) {
    const std::vector<Vec3> far{
        {100000.3, 70000.7, -40000.1}, {100001.9, 70000.2, -39999.5}, {99999.1, 70002.6, -40000.9}};
    std::string mesh = "objects:\n  - {type: mesh, material: {kd: 0.5}, triangles: [[0, 1, 2]], vertices: [";
    for (const Vec3& v : far) mesh += fmt_vec(v) + (&v == &far.back() ? "" : ", ");
    mesh += "]}\n";
    const std::string sdl = sdl_for(mesh);
    // About the centre of the mesh's bounds (mesh_origin), written exactly, as Whitted stores it.
    const auto centre = numbers_after(sdl, "translate", 3);
    ASSERT_EQ(centre.size(), 3u);
    for (int axis = 0; axis < 3; ++axis) {
        double lo = far[0][axis], hi = far[0][axis];
        for (const Vec3& v : far) lo = std::min(lo, v[axis]), hi = std::max(hi, v[axis]);
        EXPECT_EQ(centre[size_t(axis)], 0.5 * (lo + hi)) << "axis " << axis;
    }
    const auto written = numbers_after(sdl, "vertex_vectors { 3,", 9);
    for (size_t i = 0; i < 3; ++i) {
        for (int axis = 0; axis < 3; ++axis) {
            const double local = written[3 * i + axis];
            EXPECT_EQ(double(float(local)), local);  // POV-Ray stores it as this float exactly
            EXPECT_EQ(local, double(float(far[i][axis] - centre[size_t(axis)]))) << "vertex " << i << " axis " << axis;
            EXPECT_LT(std::fabs(local), 4.0);
        }
    }
    const std::string near = sdl_for(
        "objects:\n  - {type: mesh, material: {kd: 0.5}, triangles: [[0, 1, 2]], "
        "vertices: [[0.3, 0.7, -0.1], [1.9, -0.2, 0.5], [-0.9, 1.6, -0.9]]}\n");
    EXPECT_THAT(near, Not(HasSubstr("translate")));
    EXPECT_EQ(numbers_after(near, "vertex_vectors { 3,", 3),
              (std::vector<double>{float(0.3), float(0.7), float(-0.1)}));
}

// Vertex normals are written as the floats Whitted holds (the unit normal rounded to float), so
// that POV-Ray, which makes each normal it reads unit length again and stores it as a float,
// ends with the normals Whitted's emulation of it (compat/povray/mesh2.cpp,
// MeshAsPovray::smooth_normal) starts from. The rounding is real: GCC 12's vectoriser once dropped it, and x and y of
// these normals were written unrounded (vec3.h, float_rounded).
TEST(PovWriter, NormalsAreWrittenAsFloats) {
    const std::string sdl = sdl_for(
        "objects:\n  - {type: mesh, material: {kd: 0.5}, triangles: [[0, 1, 2]], "
        "vertices: [[0, 0, 0], [1, 0, 0], [0, 1, 0]], normals: [[0.3, 0.4, 0.5], [0.3, 0.4, 0.5], [0.1, 0.4, 0.5]]}\n");
    const auto written = numbers_after(sdl, "normal_vectors { 3,", 9);
    const Vec3 given[3] = {{0.3, 0.4, 0.5}, {0.3, 0.4, 0.5}, {0.1, 0.4, 0.5}};
    for (int i = 0; i < 3; ++i) {
        const Vec3 unit = given[i] / length(given[i]);
        for (int axis = 0; axis < 3; ++axis) {
            volatile float single = float(unit[axis]);
            EXPECT_EQ(written[3 * i + axis], double(single)) << "normal " << i << " axis " << axis;
        }
    }
}

// Every mesh2 carries an inside_vector: only then does POV-Ray's mesh report all of a ray's
// crossings instead of stopping at the nearest, so a shadow ray that meets the mesh within 1e-3
// of its start still sees the mesh farther on (docs/pov-model.md §3). That holds for a plain
// mesh, an OBJ-free triangle, and a prototype's declared mesh alike.
TEST(PovWriter, EveryMesh2HasAnInsideVector) {
    const std::string sdl = sdl_for(
        "prototypes:\n  tri: {type: mesh, vertices: [[0, 0, 0], [1, 0, 0], [0, 1, 0]], triangles: [[0, 1, 2]]}\n"
        "objects:\n  - {type: mesh, material: {kd: 0.5}, triangles: [[0, 1, 2]], "
        "vertices: [[0.3, 0.7, -0.1], [1.9, 0.2, 0.5], [-0.9, 2.6, -0.9]]}\n"
        "  - {type: triangle, material: {kd: 0.5}, vertices: [[0, 0, 0], [1, 0, 0], [0, 1, 0]]}\n"
        "  - {type: instance, prototype: tri, material: {kd: 0.5}}\n");
    ASSERT_EQ(count_of(sdl, "mesh2 {"), 3u);
    EXPECT_EQ(count_of(sdl, "inside_vector <0, 0, 1>"), 3u);
    for (size_t at = sdl.find("mesh2 {"); at != std::string::npos; at = sdl.find("mesh2 {", at + 1)) {
        const size_t faces = sdl.find("face_indices", at);
        EXPECT_LT(faces, sdl.find("inside_vector", at));  // inside this mesh2, after its faces
        EXPECT_LT(sdl.find("inside_vector", at), sdl.find("}\n}", faces) + 3);
    }
}

// POV-Ray keeps an object's bounding box in single precision, corner and size each rounded to
// the nearest float, and culls rays with it exactly: a bare box lost the rays that cross it only
// along an edge (tests/pov/box_edge_bounds.yaml). So each box sits in a union (not split) with
// two radius-0 spheres whose bounding box, rounded as POV-Ray rounds it, holds every corner of
// the box, turned or not, near the origin and far from it; and no more than a hair larger.
TEST(PovWriter, BoxSitsInAUnionWhoseFloatBoundingBoxHoldsIt) {
    const char* cases[][2] = {
        {"[9.0299, 0.01, -1.0922]", "[9.0699, 0.05, -1.0522]"},
        {"[100000.3, 70000.1, -40000.7]", "[100001.1, 70000.9, -39999.9]"},
        {"[-0.02, -0.02, -0.02]", "[0.02, 0.02, 0.02]"},
    };
    for (const char* transform :
         {"", ", transform: [{rotate: {axis: [0, 1, 0], angle: 37.7}}, {translate: [3, 0.03, -2]}]"}) {
        for (const auto& [min, max] : cases) {
            const std::string sdl = sdl_for(std::string("objects:\n  - {type: box, min: ") + min + ", max: " + max +
                                            transform + ", material: {kd: 0.5}}\n");
            SCOPED_TRACE(sdl);
            ASSERT_EQ(count_of(sdl, "union { box {"), 1u);
            EXPECT_EQ(count_of(sdl, "split_union off }"), 1u);
            const auto lo = numbers_after(sdl, "sphere {", 4),
                       hi = numbers_after(sdl, "sphere {", 4, sdl.find("sphere {") + 1);
            EXPECT_EQ(lo[3], 0.0);  // radius 0: no ray hits it
            EXPECT_EQ(hi[3], 0.0);
            // The world corners of the box, as Whitted places them.
            const SceneDescription d = parse_scene_text(
                std::string("camera: {eye: [0, 1, 5], look_at: [0, 0, 0]}\nimage: {width: 4, height: 3}\nobjects:\n  - "
                            "{type: box, min: ") +
                    min + ", max: " + max + transform + ", material: {kd: 0.5}}\n",
                "scene.yaml");
            const Scene scene = validate_scene(d);
            ASSERT_EQ(scene.boxes.size(), 1u);
            const Box& box = scene.boxes[0];
            Vec3 low_corner(INFINITY), high_corner(-INFINITY);
            for (int corner = 0; corner < 8; ++corner) {
                const Vec3 local{corner & 1 ? box.max.x : box.min.x, corner & 2 ? box.max.y : box.min.y,
                                 corner & 4 ? box.max.z : box.min.z};
                const Vec3 world = box.object_to_world ? box.object_to_world->apply_point(local) : local;
                for (int axis = 0; axis < 3; ++axis) {
                    low_corner[axis] = std::min(low_corner[axis], world[axis]);
                    high_corner[axis] = std::max(high_corner[axis], world[axis]);
                }
            }
            double scale = 0;  // the box's size and distance from the origin
            for (int axis = 0; axis < 3; ++axis)
                scale = std::max({scale, std::fabs(low_corner[axis]), std::fabs(high_corner[axis]),
                                  high_corner[axis] - low_corner[axis]});
            for (int axis = 0; axis < 3; ++axis) {
                // POV-Ray: each sphere's box is its float centre; the union's is lowerLeft =
                // float(min), size = float(max - min) over those, tested against lowerLeft + size
                // summed in float.
                const float lower = float(lo[axis]);
                const float size = float(double(float(hi[axis])) - double(lower));
                const float upper = lower + size;
                EXPECT_LE(double(lower), low_corner[axis]) << "axis " << axis;
                EXPECT_GE(double(upper), high_corner[axis]) << "axis " << axis;
                EXPECT_GE(lo[axis], low_corner[axis] - 1e-5 * scale) << "axis " << axis;  // a hair, not more
                EXPECT_LE(hi[axis], high_corner[axis] + 1e-5 * scale) << "axis " << axis;
            }
        }
    }
}

// Awkward doubles (0.1 + 0.2, tiny, huge, many digits) come back bit for bit.
TEST(PovWriter, NumbersRoundTripExactly) {
    const std::string text =
        "lights:\n  - {type: point, position: [0.30000000000000004, -1.0000000000000002e-7, 123456.78901234567]}\n"
        "objects:\n"
        "  - {type: sphere, center: [0.1, -2.718281828459045, 3.0e+21], radius: 0.7071067811865476,\n"
        "     material: {kd: [0.123456789012345678, 0.1, 1e-300]}}\n";
    const SceneDescription d = parse_scene_text(
        "camera: {eye: [0, 1, 5], look_at: [0, 0, 0], fov: 33.3}\nimage: {width: 7, height: 3}\n" + text, "scene.yaml");
    const std::string sdl = pov::scene_to_sdl(d);

    const auto light = numbers_after(sdl, "light_source {", 3);
    EXPECT_EQ(light, (std::vector<double>{0.30000000000000004, -1.0000000000000002e-7, 123456.78901234567}));
    const auto sphere = numbers_after(sdl, "sphere {", 4);
    EXPECT_EQ(sphere, (std::vector<double>{0.1, -2.718281828459045, 3.0e+21, 0.7071067811865476}));
    EXPECT_EQ(sphere[3], std::get<SphereShape>(d.objects[0].shape).radius.value);
    const auto pigment = numbers_after(sdl, "pigment { rgb", 3);
    EXPECT_EQ(pigment, (std::vector<double>{0.123456789012345678, 0.1, 1e-300}));
    EXPECT_EQ(numbers_after(sdl, "angle", 1)[0], 33.3);
    // A right-handed scene is rendered by POV-Ray with `right −x·W/H`.
    EXPECT_EQ(numbers_after(sdl, "right", 3), (std::vector<double>{-7.0 / 3.0, 0, 0}));
}

// Names and paths are user text: a quote or newline in them must not end a string or start a
// directive in the SDL. Only numbers from the scene are written, so no quote appears at all.
TEST(PovWriter, NamesWithQuotesAndNewlinesNeverReachTheSdl) {
    const std::string evil_path = "dir/we\"ird\n#include \"evil.inc\"\n.yaml";
    const std::string sdl = sdl_for(
        "materials:\n"
        "  \"evil\\\" name\\n#declare Injected = 1;\": {kd: 0.5}\n"
        "objects:\n"
        "  - {type: sphere, center: [0, 0, 0], radius: 1, material: \"evil\\\" name\\n#declare Injected = 1;\"}\n",
        evil_path);
    EXPECT_THAT(sdl, HasSubstr("sphere {"));
    EXPECT_THAT(sdl, Not(HasSubstr("\"")));
    EXPECT_THAT(sdl, Not(HasSubstr("Injected")));
    EXPECT_THAT(sdl, Not(HasSubstr("evil\" name")));
    // The scene path may appear, but only inside the one-line comment that opens the file.
    EXPECT_EQ(sdl.compare(0, 3, "// "), 0);
    EXPECT_THAT(sdl.substr(0, sdl.find('\n')), HasSubstr("we_ird"));
    EXPECT_THAT(sdl, Not(HasSubstr("\n#include")));
    // Every line starting with '#' is one the converter writes itself.
    for (size_t at = sdl.find("\n#"); at != std::string::npos; at = sdl.find("\n#", at + 1))
        EXPECT_EQ(sdl.compare(at + 1, 13, "#version 3.7;"), 0) << sdl.substr(at + 1, 40);
}

// Grey ks (with kd > 0 wherever ka > 0): one texture, pigment kd, ambient ka/kd per channel,
// diffuse 1, `specular ks roughness 1/p`, reflection km.
TEST(PovWriter, RecipeAForGreySpecular) {
    const double ka[3] = {0.08, 0.03, 0.02}, kd[3] = {0.56, 0.21, 0.14}, ks = 0.5, p = 50, km = 0.25;
    const std::string sdl = sdl_for(
        "materials:\n  ball: {ka: [0.08, 0.03, 0.02], kd: [0.56, 0.21, 0.14], ks: 0.5, p: 50, km: 0.25}\n"
        "objects:\n  - {type: sphere, center: [0, 0, 0], radius: 1, material: ball}\n");
    EXPECT_EQ(count_of(sdl, "texture {"), 1u);
    EXPECT_EQ(numbers_after(sdl, "pigment { rgb", 3), (std::vector<double>{kd[0], kd[1], kd[2]}));
    EXPECT_EQ(numbers_after(sdl, "ambient rgb", 3), (std::vector<double>{ka[0] / kd[0], ka[1] / kd[1], ka[2] / kd[2]}));
    EXPECT_EQ(numbers_after(sdl, "diffuse", 1)[0], 1.0);
    EXPECT_EQ(numbers_after(sdl, "specular", 1)[0], ks);
    EXPECT_EQ(numbers_after(sdl, "roughness", 1)[0], 1 / p);
    EXPECT_EQ(numbers_after(sdl, "reflection { rgb", 3), (std::vector<double>{km, km, km}));
    EXPECT_THAT(sdl, HasSubstr("adc_bailout 0"));
}

// Coloured ks: four layers, bottom first (docs/pov-model.md §1b with t1 = t2 = 1/2, s = 1):
// black + specular lobe; filter ks/(t1·t2); diffuse kd/(t1·(1 − t2)) at transmit t2; white at
// transmit t1 with ambient ka/(1 − t1) and the mirror.
TEST(PovWriter, RecipeBLayersForColouredSpecular) {
    const double ka[3] = {0.3, 0.05, 0}, kd[3] = {0, 0.6, 0.8}, ks[3] = {0.9, 0.2, 0.1}, p = 40;
    const double t1 = 0.5, t2 = 0.5;
    const std::string sdl = sdl_for(
        "materials:\n  odd: {ka: [0.3, 0.05, 0], kd: [0, 0.6, 0.8], ks: [0.9, 0.2, 0.1], p: 40, km: [0.2, 0.3, 0.4]}\n"
        "objects:\n  - {type: sphere, center: [0, 0, 0], radius: 1, material: odd}\n");
    std::vector<size_t> layer;  // where each texture starts, in SDL order (bottom layer first)
    for (size_t at = sdl.find("texture {"); at != std::string::npos; at = sdl.find("texture {", at + 1))
        layer.push_back(at);
    ASSERT_EQ(layer.size(), 4u);
    // L4 (bottom): opaque black, the highlight lobe with strength 1 and exponent p.
    EXPECT_EQ(numbers_after(sdl, "pigment { rgb", 1, layer[0])[0], 0.0);
    EXPECT_EQ(numbers_after(sdl, "specular", 1, layer[0])[0], 1.0);
    EXPECT_EQ(numbers_after(sdl, "roughness", 1, layer[0])[0], 1 / p);
    // L3: pure filter.
    EXPECT_EQ(numbers_after(sdl, "rgbf", 4, layer[1]),
              (std::vector<double>{ks[0] / (t1 * t2), ks[1] / (t1 * t2), ks[2] / (t1 * t2), 1}));
    // L2: diffuse.
    EXPECT_EQ(numbers_after(sdl, "rgbt", 4, layer[2]),
              (std::vector<double>{kd[0] / (t1 * (1 - t2)), kd[1] / (t1 * (1 - t2)), kd[2] / (t1 * (1 - t2)), t2}));
    // L1 (top): ambient and mirror.
    EXPECT_EQ(numbers_after(sdl, "rgbt", 4, layer[3]), (std::vector<double>{1, 1, 1, t1}));
    EXPECT_EQ(numbers_after(sdl, "ambient rgb", 3, layer[3]),
              (std::vector<double>{ka[0] / (1 - t1), ka[1] / (1 - t1), ka[2] / (1 - t1)}));
    EXPECT_EQ(numbers_after(sdl, "reflection { rgb", 3, layer[3]), (std::vector<double>{0.2, 0.3, 0.4}));
    EXPECT_THAT(sdl, HasSubstr("adc_bailout 0"));
}

// The colour of ks alone decides: ka = 0.1·kd (recipe A could hold it) with a tinted ks still
// needs the layers, because POV-Ray's `specular` is a single number.
TEST(PovWriter, TintedSpecularAloneSelectsRecipeB) {
    const std::string sdl = sdl_for(
        "materials:\n  tint: {ka: [0.05, 0.05, 0.05], kd: [0.5, 0.5, 0.5], ks: [0.5, 0.5, 0.25], p: 10}\n"
        "objects:\n  - {type: sphere, center: [0, 0, 0], radius: 1, material: tint}\n");
    EXPECT_EQ(count_of(sdl, "texture {"), 4u);
    EXPECT_EQ(numbers_after(sdl, "rgbf", 4), (std::vector<double>{0.5 / 0.25, 0.5 / 0.25, 0.25 / 0.25, 1}));
}

// A mesh file whose object gives its own material is converted as it is rendered
// (validate_scene): its MTL side is not read, so a `usemtl` of nothing, or faces without one,
// neither warn of a default material it does not get nor stop the conversion.
TEST(PovWriter, MeshWithItsOwnMaterialIgnoresTheObjMaterialsAsRenderDoes) {
    const test::ScratchDirectory dir;
    dir.write("tri.obj", "mtllib missing.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl nowhere\nf 1 2 3\nf 3 2 1\n");
    const std::string scene = (dir.path() / "scene.yaml").string();
    const std::string objects = "objects:\n  - {type: mesh, file: tri.obj, material: {kd: [0.25, 0.5, 0.75]}}\n";
    (void)test::scene_from("camera: {eye: [0, 1, 5], look_at: [0, 0, 0]}\nimage: {width: 4, height: 3}\n" + objects,
                           scene);  // render accepts it
    ::testing::internal::CaptureStderr();
    std::string sdl;
    EXPECT_NO_THROW(sdl = sdl_for(objects, scene));
    const std::string printed = ::testing::internal::GetCapturedStderr();
    EXPECT_THAT(printed, Not(HasSubstr("default material")));
    EXPECT_THAT(printed, Not(HasSubstr("warning")));
    EXPECT_EQ(count_of(sdl, "mesh2"), 1u);
    EXPECT_EQ(numbers_after(sdl, "pigment { rgb", 3), (std::vector<double>{0.25, 0.5, 0.75}));
}

// The converter writes the Scene validate_scene built: the mesh files were read once, by that
// walk, and are not read again (here they are gone by the time the SDL is written), and an OBJ
// with two MTL materials becomes one mesh2 per material, in the MTL's order.
TEST(PovWriter, WritesTheBuiltSceneWithoutReadingTheMeshFilesAgain) {
    const test::ScratchDirectory dir;
    dir.write("two.mtl", "newmtl red\nKa 0 0 0\nKd 1 0 0\nKs 0 0 0\nnewmtl green\nKa 0 0 0\nKd 0 1 0\nKs 0 0 0\n");
    dir.write("quad.obj",
              "mtllib two.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nusemtl green\nf 1 2 3\nusemtl red\nf 1 3 4\n");
    const std::string path = (dir.path() / "scene.yaml").string();
    const SceneDescription d = parse_scene_text(
        "camera: {eye: [0, 1, 5], look_at: [0, 0, 0]}\nimage: {width: 4, height: 3}\n"
        "objects:\n  - {type: mesh, file: quad.obj, transform: [{translate: [0, 0, 1]}]}\n",
        path);
    const Scene scene = validate_scene(d);
    const std::string before = pov::scene_to_sdl(d, scene);
    std::filesystem::remove(dir.path() / "quad.obj");
    std::filesystem::remove(dir.path() / "two.mtl");
    EXPECT_EQ(pov::scene_to_sdl(d, scene), before);
    EXPECT_EQ(count_of(before, "mesh2"), 2u);
    const size_t red = before.find("pigment { rgb <1, 0, 0> }"), green = before.find("pigment { rgb <0, 1, 0> }");
    ASSERT_NE(red, std::string::npos);
    ASSERT_NE(green, std::string::npos);
    EXPECT_LT(red, green);  // red is the MTL's first material
    EXPECT_EQ(numbers_after(before, "face_indices { 1,\n    <", 3), (std::vector<double>{0, 2, 3}));
}

// A cone's cap is written as the scene gives it, not as base + height·axis (which rounds).
TEST(PovWriter, ConeCapIsWrittenAsGiven) {
    const std::string sdl = sdl_for(
        "objects:\n  - {type: cone, base: [0.1, 0.2, 0.3], base_radius: 0.7, cap: [0.3, 1.7, -0.9],"
        " cap_radius: 0.1, material: {kd: 0.5}}\n");
    EXPECT_EQ(numbers_after(sdl, "cone {", 8), (std::vector<double>{0.1, 0.2, 0.3, 0.7, 0.3, 1.7, -0.9, 0.1}));
}

// A prototype's OBJ without usemtl: its faces get the default material only through an
// instance without a material of its own, so render and convert warn of it only then (with
// every instance giving one, the warning used to name a material nothing is drawn with).
TEST(PovWriter, TheDefaultMaterialIsWarnedOfOnlyWhereAnInstanceShowsIt) {
    const test::ScratchDirectory dir;
    dir.write("tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    const std::string scene = (dir.path() / "scene.yaml").string();
    const std::string head = "camera: {eye: [0, 1, 5], look_at: [0, 0, 0]}\nimage: {width: 4, height: 3}\n";
    const std::string prototypes = "prototypes:\n  tri: {type: mesh, file: tri.obj}\n";
    const std::string given = "  - {type: instance, prototype: tri, material: {kd: 0.5}}\n";
    const std::string left = "  - {type: instance, prototype: tri, transform: {translate: [1, 0, 0]}}\n";
    for (const std::string& objects : {given, given + given, given + left, left}) {
        const std::string text = prototypes + "objects:\n" + objects;
        const bool shows = objects.find("transform") != std::string::npos;
        const SceneDescription d = parse_scene_text(head + text, scene);
        for (const int reader : {0, 1, 2}) {  // render's one pass, the two passes, convert alone
            ::testing::internal::CaptureStderr();
            if (reader == 0) (void)load_scene_text(head + text, scene);
            if (reader == 1) (void)validate_scene(d);
            if (reader == 2) (void)pov::scene_to_sdl(d);
            const std::string printed = ::testing::internal::GetCapturedStderr();
            EXPECT_EQ(count_of(printed, "they get the default material"), shows ? 1u : 0u)
                << "reader " << reader << ", objects:\n"
                << objects << "printed: " << printed;
        }
    }
    // A plain mesh without a material shows it, and says so.
    ::testing::internal::CaptureStderr();
    (void)test::scene_from(head + "objects:\n  - {type: mesh, file: tri.obj}\n", scene);
    EXPECT_THAT(::testing::internal::GetCapturedStderr(), HasSubstr("they get the default material"));
}

// The .ini renders deterministically and linearly (docs/pov-model.md §0): size, no display, no
// antialiasing, 16-bit linear PNG.
TEST(PovWriter, IniIsLinearAndDeterministic) {
    const SceneDescription d = parse_scene_text(
        "camera: {eye: [0, 1, 5], look_at: [0, 0, 0]}\nimage: {width: 40, height: 30}\n", "scene.yaml");
    const std::string ini = pov::ini_for(d, "scene.pov", "scene.png");
    EXPECT_THAT(ini, HasSubstr("+W40 +H30 -D -A"));
    EXPECT_THAT(ini, HasSubstr("+FN16"));
    EXPECT_THAT(ini, HasSubstr("File_Gamma=1.0"));
    EXPECT_THAT(ini, Not(HasSubstr("+A0")));
    EXPECT_THROW((void)pov::ini_for(d, "evil\".pov", "scene.png"), std::invalid_argument);
}

}  // namespace
}  // namespace whitted
