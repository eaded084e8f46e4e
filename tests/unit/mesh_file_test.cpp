// SPDX-License-Identifier: MIT
// Wavefront OBJ + MTL loading: the MTL's Ka/Kd/Ks/Ns become ka/kd/ks/p, `illum 3` (reflection)
// makes km = Ks, polygons are split into triangles, and bad files are refused naming the file.

#include "scene/mesh_file.h"
#include "scene/scene.h"

#include "test_support.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <set>
#include <utility>
#include <vector>

namespace whitted {
namespace {

using ::testing::HasSubstr;

const char* const two_materials_mtl =
    "newmtl glass\n"
    "Ka 0.1 0.2 0.3\n"
    "Kd 0.4 0.5 0.6\n"
    "Ks 0.7 0.8 0.9\n"
    "Ns 25\n"
    "illum 3\n"
    "\n"
    "newmtl tin\n"
    "Ka 0 0 0\n"
    "Kd 0.5 0.5 0.5\n"
    "Ks 0.25 0.25 0.25\n"
    "Ns 10\n"
    "illum 2\n";

// A unit square in z = 0 (one quad) and a triangle standing on its edge.
const char* const quad_and_triangle_obj =
    "mtllib materials.mtl\n"
    "v 0 0 0\n"
    "v 1 0 0\n"
    "v 1 1 0\n"
    "v 0 1 0\n"
    "v 0 0 1\n"
    "usemtl glass\n"
    "f 1 2 3 4\n"
    "usemtl tin\n"
    "f 1 2 5\n";

Vec3 position(const MeshData& mesh, uint32_t index) {
    return {mesh.positions[3 * index], mesh.positions[3 * index + 1], mesh.positions[3 * index + 2]};
}

const MaterialDescription* find(const MeshData& mesh, const std::string& name) {
    for (const auto& m : mesh.materials)
        if (m.name == name) return &m;
    return nullptr;
}

void expect_color_float(const Color& actual, float r, float g, float b) {
    // The MTL reader keeps floats: compare with the float nearest each written decimal.
    EXPECT_EQ(actual.x, double(r));
    EXPECT_EQ(actual.y, double(g));
    EXPECT_EQ(actual.z, double(b));
}

TEST(ObjMesh, MtlCoefficientsMapToTheLectureMaterial) {
    const test::ScratchDirectory directory;
    directory.write("materials.mtl", two_materials_mtl);
    const MeshData mesh = load_obj_mesh(directory.write("model.obj", quad_and_triangle_obj), {});
    ASSERT_EQ(mesh.materials.size(), 2u);
    const MaterialDescription* glass = find(mesh, "glass");
    const MaterialDescription* tin = find(mesh, "tin");
    ASSERT_TRUE(glass && tin);
    expect_color_float(glass->ka.value, 0.1f, 0.2f, 0.3f);
    expect_color_float(glass->kd.value, 0.4f, 0.5f, 0.6f);
    expect_color_float(glass->ks.value, 0.7f, 0.8f, 0.9f);
    EXPECT_EQ(glass->p.value, 25.0);
    expect_color_float(glass->km.value, 0.7f, 0.8f, 0.9f);  // illum 3: a mirror as strong as Ks
    expect_color_float(tin->ks.value, 0.25f, 0.25f, 0.25f);
    EXPECT_EQ(tin->p.value, 10.0);
    EXPECT_EQ(tin->km.value, Color(0.0));  // illum 2: highlights, no mirror
}

// The quad becomes two triangles that tile the unit square (total area 1, both facing +z);
// the triangle after it keeps its own material.
TEST(ObjMesh, QuadIsSplitIntoTwoTriangles) {
    const test::ScratchDirectory directory;
    directory.write("materials.mtl", two_materials_mtl);
    const MeshData mesh = load_obj_mesh(directory.write("model.obj", quad_and_triangle_obj), {});
    ASSERT_EQ(mesh.indices.size(), 9u);
    ASSERT_EQ(mesh.positions.size(), 15u);  // 5 vertices, no normals: used as written
    EXPECT_TRUE(mesh.normals.empty());
    double area = 0;
    std::set<uint32_t> corners;
    for (int t = 0; t < 2; ++t) {
        const Vec3 a = position(mesh, mesh.indices[3 * t]), b = position(mesh, mesh.indices[3 * t + 1]),
                   c = position(mesh, mesh.indices[3 * t + 2]);
        const Vec3 n = cross(b - a, c - a);
        EXPECT_GT(n.z, 0) << "triangle " << t << " keeps the quad's winding";
        area += length(n) / 2;
        for (int k = 0; k < 3; ++k) corners.insert(mesh.indices[3 * t + k]);
    }
    EXPECT_NEAR(area, 1.0, 1e-7);
    EXPECT_EQ(corners, (std::set<uint32_t>{0, 1, 2, 3}));
    EXPECT_EQ((std::vector<uint32_t>{mesh.indices[6], mesh.indices[7], mesh.indices[8]}),
              (std::vector<uint32_t>{0, 1, 4}));
    ASSERT_EQ(mesh.triangle_material.size(), 3u);
    EXPECT_EQ(mesh.materials[size_t(mesh.triangle_material[0])].name, "glass");
    EXPECT_EQ(mesh.materials[size_t(mesh.triangle_material[1])].name, "glass");
    EXPECT_EQ(mesh.materials[size_t(mesh.triangle_material[2])].name, "tin");
}

// Normals indexed apart from positions: every (position, normal) pair becomes one vertex so that
// normals index like positions.
TEST(ObjMesh, VertexNormalsFollowTheirCorners) {
    const test::ScratchDirectory directory;
    const MeshData mesh = load_obj_mesh(directory.write("n.obj",
                                                        "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
                                                        "vn 0 0 1\nvn 0 1 0\n"
                                                        "f 1//2 2//1 3//1\n"),
                                        {});
    ASSERT_EQ(mesh.indices.size(), 3u);
    ASSERT_EQ(mesh.normals.size(), mesh.positions.size());
    const auto normal = [&](uint32_t i) {
        return Vec3{mesh.normals[3 * i], mesh.normals[3 * i + 1], mesh.normals[3 * i + 2]};
    };
    EXPECT_EQ(position(mesh, mesh.indices[0]), (Vec3{0, 0, 0}));
    EXPECT_EQ(normal(mesh.indices[0]), (Vec3{0, 1, 0}));
    EXPECT_EQ(position(mesh, mesh.indices[1]), (Vec3{1, 0, 0}));
    EXPECT_EQ(normal(mesh.indices[1]), (Vec3{0, 0, 1}));
    EXPECT_EQ(position(mesh, mesh.indices[2]), (Vec3{0, 1, 0}));
    EXPECT_EQ(normal(mesh.indices[2]), (Vec3{0, 0, 1}));
}

TEST(ObjMesh, OutOfRangeFaceIndexNamesTheFile) {
    const test::ScratchDirectory directory;
    const std::string path = directory.write("broken.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
    const auto error = test::input_error_from([&] { (void)load_obj_mesh(path, {"scene.yaml", 4, 11}); });
    ASSERT_TRUE(error);
    EXPECT_THAT(std::string(error->what()), HasSubstr(path));
}

// Large files are read by several threads, a run of lines each. Whatever the number of runs,
// the mesh must be the same, value for value: every statement form the reader takes appears in
// this file, and with 1..7 runs its lines are cut at many different places.
std::string every_form_obj() {
    std::string text = "# every statement form the reader takes\r\n\n   \t\n";
    text += "o torus\ng group\ns 1\nvt 0.5 0.5\n";
    for (int i = 0; i < 40; ++i) {
        const double x = 0.1 * i, y = -0.25 * i + 1e-3, z = 1.0 / (i + 3);
        char line[160];
        switch (i % 4) {
            case 0:
                std::snprintf(line, sizeof line, "v %.6f %.6f %.6f\n", x, y, z);
                break;
            case 1:
                std::snprintf(line, sizeof line, "v %.17g\t%.17g %.17g 1.0\r\n", x, y, z);
                break;
            case 2:
                std::snprintf(line, sizeof line, "  v %.3e %+.4e %.9E  \n", x, y, z);
                break;
            default:
                std::snprintf(line, sizeof line, "v %g %g %g\n", x, y, z);
                break;
        }
        text += line;
        std::snprintf(line, sizeof line, "vn %.6f %.6f %.6f\n", z, x, 1.0);
        text += line;
    }
    for (int i = 0; i + 3 < 40; ++i) {
        const int a = i + 1, b = i + 2, c = i + 3;
        char line[200];
        switch (i % 6) {
            case 0:
                std::snprintf(line, sizeof line, "f %d %d %d\n", a, b, c);
                break;
            case 1:
                std::snprintf(line, sizeof line, "f %d//%d %d//%d %d//%d\n", a, a, b, b, c, c);
                break;
            case 2:
                std::snprintf(line, sizeof line, "f %d/1/%d %d/1/%d %d/1/%d %d/1/%d\r\n", a, a, b, b, c, c, c + 1,
                              c + 1);
                break;
            case 3:
                std::snprintf(line, sizeof line, "f -1 -2 -3\n");
                break;
            case 4:
                std::snprintf(line, sizeof line, "\tf %d/1 %d/ %d//\n", a, b, c);
                break;
            default:
                std::snprintf(line, sizeof line, "f %d//%d %d//%d %d//%d\n", a, b, b, c, c, a);
                break;
        }
        text += line;
    }
    text += "f";  // a 20-gon, longer than the fast path takes
    for (int i = 1; i <= 20; ++i) text += " " + std::to_string(i);
    text += "\nl 1 2\n# no newline at the end\nv 1 2 3";
    return text;
}

void expect_same_mesh(const MeshData& a, const MeshData& b, int parts) {
    EXPECT_EQ(a.positions, b.positions) << parts << " runs";
    EXPECT_EQ(a.normals, b.normals) << parts << " runs";
    EXPECT_EQ(a.indices, b.indices) << parts << " runs";
    EXPECT_EQ(a.triangle_material, b.triangle_material) << parts << " runs";
}

TEST(ObjMesh, ReadingInRunsGivesTheSameMesh) {
    const test::ScratchDirectory directory;
    const std::string path = directory.write("forms.obj", every_form_obj());
    const MeshData whole = load_obj_mesh(path, {}, 1);
    ASSERT_EQ(whole.positions.size(), 41u * 3);
    // Corners name other normals than their positions' (the last f form), so vertices are split.
    EXPECT_EQ(whole.normals.size(), 0u) << "the v/t and v// corners have no normal: flat";
    EXPECT_GT(whole.indices.size(), 3u * 37);
    for (int parts = 2; parts <= 7; ++parts) expect_same_mesh(load_obj_mesh(path, {}, parts), whole, parts);
}

TEST(ObjMesh, ReadingInRunsKeepsSmoothAndSplitVertices) {
    // Every corner has a normal, some name another normal than their position's: one vertex per
    // distinct pair, numbered in order of first use, the same for every number of runs.
    std::string text;
    for (int i = 0; i < 30; ++i) text += "v " + std::to_string(i) + " " + std::to_string(i % 7) + " 0.5\n";
    for (int i = 0; i < 30; ++i) text += "vn 0 " + std::to_string(i % 3) + " 1\n";
    for (int i = 1; i + 2 <= 30; ++i) {
        const int n = i % 5 == 0 ? 30 - i : i;  // every fifth face names other normals
        text += "f " + std::to_string(i) + "//" + std::to_string(n) + " " + std::to_string(i + 1) + "//" +
                std::to_string(i + 1) + " " + std::to_string(i + 2) + "//" + std::to_string(i + 2) + "\n";
    }
    const test::ScratchDirectory directory;
    const std::string path = directory.write("split.obj", text);
    const MeshData whole = load_obj_mesh(path, {}, 1);
    ASSERT_EQ(whole.normals.size(), whole.positions.size());
    EXPECT_GT(whole.positions.size(), 30u * 3) << "some positions carry two normals";
    for (int parts = 2; parts <= 6; ++parts) expect_same_mesh(load_obj_mesh(path, {}, parts), whole, parts);
}

// A mistake anywhere is reported for the same line and column, in the same words, however many
// runs read the file (an error in a later run must not hide an earlier one).
TEST(ObjMesh, ReadingInRunsReportsTheFirstMistake) {
    const std::string good = every_form_obj();
    const std::vector<std::pair<std::string, std::string>> mistakes = {
        {"vn 0.", "vn x0."}, {"vn 0.", "vn 1e999 "}, {"f -1 -2 -3\n", "f -1 -2 -90\n"},
        {"f ", "f 1 2\nf "}, {"//", "///"},          {"o torus\n", "o torus\nv 1 2\n"},
    };
    const test::ScratchDirectory directory;
    for (const auto& [from, to] : mistakes) {
        for (const bool late : {false, true}) {
            std::string text = good;
            const size_t at = late ? text.rfind(from) : text.find(from);
            ASSERT_NE(at, std::string::npos) << from;
            text.replace(at, from.size(), to);
            if (!late) text.replace(text.rfind("f -1 -2 -3\n"), 11, "f 1 2 999\n");  // a second, later mistake
            const std::string path = directory.write("bad.obj", text);
            const auto whole = test::input_error_from([&] { (void)load_obj_mesh(path, {}, 1); });
            ASSERT_TRUE(whole) << to;
            for (int parts = 2; parts <= 7; ++parts) {
                const auto in_runs = test::input_error_from([&] { (void)load_obj_mesh(path, {}, parts); });
                ASSERT_TRUE(in_runs) << to << ", " << parts << " runs";
                EXPECT_EQ(std::string(in_runs->what()), std::string(whole->what())) << parts << " runs";
            }
        }
    }
}

// In a scene: the path is relative to the scene file; without `material:` the MTL's materials
// are used per face, with it every face takes the override.
TEST(ObjMesh, SceneUsesMtlMaterialsUnlessOverridden) {
    const test::ScratchDirectory directory;
    std::filesystem::create_directories(directory.path() / "models");
    directory.write("models/materials.mtl", two_materials_mtl);
    directory.write("models/model.obj", quad_and_triangle_obj);
    const std::string scene_path = (directory.path() / "scene.yaml").string();
    const std::string head =
        "camera: {eye: [0, 0, 5], look_at: [0, 0, 0]}\nimage: {width: 2, height: 2}\n"
        "materials:\n  red: {kd: [1, 0, 0]}\nobjects:\n";

    const Scene from_mtl = test::scene_from(head + "  - {type: mesh, file: models/model.obj}\n", scene_path);
    ASSERT_EQ(from_mtl.meshes.size(), 1u);
    ASSERT_EQ(from_mtl.meshes[0].triangle_materials.size(), 3u);
    const Material& first = from_mtl.materials[from_mtl.meshes[0].triangle_materials[0]];
    const Material& last = from_mtl.materials[from_mtl.meshes[0].triangle_materials[2]];
    EXPECT_EQ(first.km, Color(double(0.7f), double(0.8f), double(0.9f)));
    EXPECT_EQ(first.p, 25.0);
    EXPECT_EQ(last.km, Color(0.0));
    EXPECT_EQ(last.p, 10.0);

    const Scene overridden =
        test::scene_from(head + "  - {type: mesh, file: models/model.obj, material: red}\n", scene_path);
    ASSERT_EQ(overridden.meshes.size(), 1u);
    EXPECT_TRUE(overridden.meshes[0].triangle_materials.empty());
    EXPECT_EQ(overridden.materials[overridden.meshes[0].material].kd, (Color{1, 0, 0}));
}

}  // namespace
}  // namespace whitted
