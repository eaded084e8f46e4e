// SPDX-License-Identifier: MIT
// The NFF reader (docs/nff.md): each entity of Haines' NFF document against what it becomes in
// the plain description, with its place; the mapping of `f`; the camera of SPD's own POV-Ray
// output written out here; every malformed entity refused with its FILE:LINE:COL.

#include "scene/nff_file.h"
#include "render/camera.h"
#include "scene/scene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

namespace whitted {
namespace {

const char* const small_scene =
    "b 0.1 0.2 0.3\n"
    "v\n"
    "from 1 2 3\n"
    "at 0 0 0\n"
    "up 0 0 1\n"
    "angle 40\n"
    "hither 0.01\n"
    "resolution 64 64\n"
    "l 4 3 2\n"
    "l 1 -4 4 0.5 0.25 1\n"
    "# a comment line\n"
    "f 1 0.5 0.25 0.8 0.3 7 0 0   # mirror-ish\n"
    "s 0 0 0.5 -0.5\n"
    "p 4\n"
    "1 1 0\n"
    "-1 1 0\n"
    "-1 -1 0\n"
    "1 -1 0\n"
    "f 0.2 0.4 0.6 0.5 0 1 0.9 1.5\n"
    "c\n"
    "0 0 0 0.2\n"
    "0 0 1 0.2\n"
    "c 1 0 0 0.3 1 0 1 0.1\n"
    "pp 3\n"
    "0 0 2 0 0 1\n"
    "1 0 2 0 0.1 1\n"
    "0 1 2 0.1 0 1\n";

TEST(Nff, EntitiesBecomeWhittedObjectsWithTheirPlaces) {
    const SceneDescription d = parse_nff_text(small_scene, "s.nff");
    EXPECT_EQ(d.image.background.value, Color(0.1, 0.2, 0.3));
    EXPECT_EQ(d.camera.eye.value, Vec3(1, 2, 3));
    EXPECT_EQ(d.camera.eye.where.line, 3);
    EXPECT_EQ(d.camera.eye.where.column, 6);
    EXPECT_EQ(d.camera.look_at.value, Vec3(0, 0, 0));
    EXPECT_EQ(d.camera.up.value, Vec3(0, 0, 1));
    EXPECT_EQ(d.camera.fov.value, 40);  // square image: the angle is the horizontal fov
    EXPECT_FALSE(d.camera.view_height.given);
    EXPECT_EQ(d.image.width.value, 64);
    EXPECT_EQ(d.image.height.value, 64);
    EXPECT_EQ(d.ambient.value, Color(0.0));

    ASSERT_EQ(d.lights.size(), 2u);
    EXPECT_EQ(d.lights[0].position.value, Vec3(4, 3, 2));
    EXPECT_EQ(d.lights[0].intensity.value, Color(1.0 / std::sqrt(2.0)));  // no colour: 1/√N
    EXPECT_EQ(d.lights[1].intensity.value, Color(0.5, 0.25, 1));          // its own colour
    EXPECT_EQ(d.lights[1].intensity.where.line, 10);

    ASSERT_EQ(d.materials.size(), 2u);
    const MaterialDescription& f1 = d.materials[0];
    EXPECT_EQ(f1.name, "f1");
    EXPECT_EQ(f1.kd.value, Color(0.8, 0.4, 0.2));  // Kd·(r, g, b)
    EXPECT_EQ(f1.ks.value, Color(0.3));
    EXPECT_EQ(f1.km.value, Color(0.3));  // Ks is the mirror weight too
    EXPECT_EQ(f1.highlight.value, Highlight::phong);
    EXPECT_EQ(f1.p.value, 7);
    EXPECT_EQ(f1.ka.value, Color(0.0));
    EXPECT_EQ(f1.kt.value, Color(0.0));
    EXPECT_FALSE(f1.ior.given);  // SPD writes 0 where nothing is transmitted
    const MaterialDescription& f2 = d.materials[1];
    EXPECT_EQ(f2.kt.value, Color(0.9));
    EXPECT_EQ(f2.ior.value, 1.5);
    EXPECT_EQ(f2.ior.where.line, 19);
    EXPECT_EQ(f2.ior.where.column, 27);

    ASSERT_EQ(d.objects.size(), 5u);
    ASSERT_EQ(d.objects[0].type(), ObjectType::sphere);
    const auto& sphere = std::get<SphereShape>(d.objects[0].shape);
    EXPECT_EQ(sphere.radius.value, 0.5);  // a negative radius: its inside, and Whitted has two sides
    EXPECT_EQ(d.objects[0].material->name, "f1");
    EXPECT_EQ(d.objects[0].where.line, 13);

    ASSERT_EQ(d.objects[1].type(), ObjectType::mesh);
    const auto& square = std::get<MeshShape>(d.objects[1].shape);
    EXPECT_EQ(square.vertices.size(), 4u);
    EXPECT_EQ(square.triangles.size(), 2u);
    EXPECT_TRUE(square.normals.empty());
    EXPECT_EQ(d.objects[1].material->name, "f1");

    ASSERT_EQ(d.objects[2].type(), ObjectType::cylinder);
    const auto& cylinder = std::get<CylinderShape>(d.objects[2].shape);
    EXPECT_EQ(cylinder.base.value, Vec3(0, 0, 0));
    EXPECT_EQ(cylinder.cap.value, Vec3(0, 0, 1));
    EXPECT_EQ(cylinder.radius.value, 0.2);
    EXPECT_TRUE(cylinder.open.value);  // NFF's cones have no end caps
    EXPECT_EQ(d.objects[2].material->name, "f2");

    ASSERT_EQ(d.objects[3].type(), ObjectType::cone);
    const auto& cone = std::get<ConeShape>(d.objects[3].shape);
    EXPECT_EQ(cone.base_radius.value, 0.3);
    EXPECT_EQ(cone.cap_radius.value, 0.1);
    EXPECT_EQ(cone.cap.value, Vec3(1, 0, 1));
    EXPECT_TRUE(cone.open.value);

    ASSERT_EQ(d.objects[4].type(), ObjectType::mesh);
    const auto& patch = std::get<MeshShape>(d.objects[4].shape);
    ASSERT_EQ(patch.normals.size(), 3u);
    EXPECT_EQ(patch.normals[1], Vec3(0, 0.1, 1));
    EXPECT_EQ(d.objects[4].material->name, "f2");
}

TEST(Nff, PolygonsOfOneFillShareAMeshAndANewFillStartsAnother) {
    const std::string view = "v from 0 0 5 at 0 0 0 up 0 1 0 angle 30 resolution 8 8\n";
    const std::string triangle = "p 3 0 0 0 1 0 0 0 1 0\n";
    const SceneDescription d =
        parse_nff_text(view + "f 1 1 1 1 0 1 0 0\n" + triangle + triangle + "f 1 0 0 1 0 1 0 0\n" + triangle, "m.nff");
    ASSERT_EQ(d.objects.size(), 2u);
    const auto& first = std::get<MeshShape>(d.objects[0].shape);
    EXPECT_EQ(first.triangles.size(), 2u);
    EXPECT_EQ(first.vertices.size(), 6u);
    EXPECT_EQ(first.triangles[1], (std::array<int64_t, 3>{3, 4, 5}));
    EXPECT_EQ(std::get<MeshShape>(d.objects[1].shape).triangles.size(), 1u);
    EXPECT_EQ(d.objects[1].material->name, "f2");
}

/// A fill is a material by its eight numbers: a line repeating an earlier fill's (SPD's lattice
/// alternates five fills over 8,281 objects) names that material again; any number different,
/// even in the last bit, is a material of its own; an object before any fill gets "f0".
TEST(Nff, ARepeatedFillIsTheSameMaterial) {
    const std::string view = "v from 0 0 5 at 0 0 0 up 0 1 0 angle 30 resolution 8 8\n";
    const std::string sphere = "s 0 0 0 1\n", triangle = "p 3 0 0 0 1 0 0 0 1 0\n";
    const std::string red = "f 1 0 0 0.5 0.5 3 0 0\n", blue = "f 0 0 1 0.5 0.5 3 0 0\n";
    const std::string red_but_last_bit = "f 1 0 0 0.5 0.5 3.0000000000000004 0 0\n";
    const SceneDescription d =
        parse_nff_text(view + sphere + red + sphere + triangle + blue + sphere + red + sphere + triangle +
                           red_but_last_bit + sphere + "f 1 0 0 .5 .50 3.0 0 0\n" + sphere,
                       "fills.nff");
    ASSERT_EQ(d.materials.size(), 4u);
    EXPECT_EQ(d.materials[0].name, "f0");
    EXPECT_EQ(d.materials[1].name, "f2");
    EXPECT_EQ(d.materials[1].where.line, 3);  // where it was first written
    EXPECT_EQ(d.materials[2].name, "f3");
    EXPECT_EQ(d.materials[2].kd.value, Color(0, 0, 0.5));
    EXPECT_EQ(d.materials[3].name, "f4");
    EXPECT_EQ(d.materials[3].p.value, 3.0000000000000004);
    std::vector<std::string> names;
    for (const ObjectDescription& object : d.objects) names.push_back(object.material->name);
    // The mesh of a fill is handed on when the next fill starts, after that fill's spheres.
    EXPECT_EQ(names, (std::vector<std::string>{"f0", "f2", "f2", "f3", "f2", "f2", "f4", "f2"}));
    ASSERT_EQ(d.objects[2].type(), ObjectType::mesh);
    ASSERT_EQ(d.objects[5].type(), ObjectType::mesh);  // a new mesh, though its fill is f2 again
    EXPECT_EQ(std::get<MeshShape>(d.objects[5].shape).triangles.size(), 1u);
}

/// The area of the triangles a polygon was cut into, against the polygon's own (shoelace).
TEST(Nff, AConcavePolygonIsCutIntoTrianglesThatCoverIt) {
    // An L shape, counter-clockwise, whose fan from the first corner would cover outside it.
    const std::string l_shape = "p 6\n0 0 0\n2 0 0\n2 1 0\n1 1 0\n1 2 0\n0 2 0\n";
    const SceneDescription d =
        parse_nff_text("v from 0 0 5 at 0 0 0 up 0 1 0 angle 30\nf 1 1 1 1 0 1 0 0\n" + l_shape, "l.nff");
    const auto& mesh = std::get<MeshShape>(d.objects.at(0).shape);
    ASSERT_EQ(mesh.triangles.size(), 4u);
    double area = 0;
    for (const auto& t : mesh.triangles) {
        const Vec3 a = mesh.vertices[size_t(t[0])], b = mesh.vertices[size_t(t[1])], c = mesh.vertices[size_t(t[2])];
        const double signed_area = cross(b - a, c - a).z / 2;
        EXPECT_GT(signed_area, 0);  // wound as the polygon: counter-clockwise seen from +z
        area += signed_area;
    }
    EXPECT_DOUBLE_EQ(area, 3.0);
}

TEST(Nff, ANonSquareImageKeepsTheAngleOnBothSides) {
    const SceneDescription d = parse_nff_text(
        "v from 0 0 5 at 0 0 0 up 0 1 0 angle 45 resolution 200 100\nf 1 1 1 1 0 1 0 0\ns 0 0 0 1\n", "w.nff");
    const double side = 2 * std::tan(45.0 * std::numbers::pi / 360);
    EXPECT_TRUE(d.camera.view_height.given);
    EXPECT_DOUBLE_EQ(d.camera.view_width.value, side);
    EXPECT_DOUBLE_EQ(d.camera.view_height.value, side);
    EXPECT_EQ(d.camera.projection_distance.value, 1.0);
    // SPD's POV-Ray camera: direction the unit view vector, up and right each 2·tan(angle/2) long.
    const Camera camera = make_camera(d.camera, 200, 100);
    EXPECT_NEAR(length(camera.forward), 1.0, 1e-15);
    EXPECT_NEAR(length(camera.up), side, 1e-15);
    EXPECT_NEAR(length(camera.right), side, 1e-15);
    EXPECT_NEAR(dot(normalize(camera.right), Vec3(1, 0, 0)), 1.0, 1e-15);  // right-handed: +x seen from +z
}

TEST(Nff, ASquareImageHasTheSameCameraAsSpdsPovRayOutput) {
    const SceneDescription d = parse_nff_text(
        "v from 2.1 1.3 1.7 at 0 0 0 up 0 0 1 angle 45 resolution 512 512\nf 1 1 1 1 0 1 0 0\ns 0 0 0 1\n", "b.nff");
    const Camera camera = make_camera(d.camera, 512, 512);
    // SPD (libpr1.c, POV-Ray 3 output): the frustum's side 2·tan(angle/2) at distance 1 along
    // the view; Whitted's rays go through forward + x·right + y·up for x, y in [−½, ½].
    const double side = 2 * std::tan(45.0 * std::numbers::pi / 360);
    const double scale = 1.0 / length(camera.forward);
    EXPECT_NEAR(length(camera.right) * scale, side, 1e-14);
    EXPECT_NEAR(length(camera.up) * scale, side, 1e-14);
    const Vec3 view = normalize(Vec3(-2.1, -1.3, -1.7));
    EXPECT_NEAR(dot(normalize(camera.forward), view), 1.0, 1e-15);
    // Right = view × up (right-handed), up in the plane of view and the given up.
    EXPECT_NEAR(dot(normalize(camera.right), normalize(cross(view, Vec3(0, 0, 1)))), 1.0, 1e-14);
    EXPECT_GT(camera.up.z, 0);
}

struct BadCase {
    const char* text;
    int line;
    int column;
    const char* says;
};

TEST(Nff, EveryMalformedEntityIsRefusedWithItsPlace) {
    const std::string v = "v from 0 0 5 at 0 0 0 up 0 1 0 angle 30\n";  // line 1
    const BadCase cases[] = {
        {"x 1 2 3\n", 1, 1, "unknown NFF entity 'x'"},
        {"s 0 0 0 1\n", 1, 1, "no view entity 'v'"},
        {"v from 0 0 5 at 0 0 0 up 0 1 0\ns 0 0 0 1\n", 1, 1, "'angle'"},
        {"v at 0 0 0 up 0 1 0 angle 30\n", 1, 1, "'from'"},
        {"v from 0 0 5 from 1 1 1 at 0 0 0 up 0 1 0 angle 30\n", 1, 14, "given twice"},
        {"v from 0 0 5 at 0 0 0 up 0 1 0 angle 180\n", 1, 38, "between 0 and 180"},
        {"v from 0 0 5 at 0 0 0 up 0 1 0 angle 30 resolution 0 8\n", 1, 52, "resolution' width"},
        {"v from 0 0 5 at 0 0 0 up 0 1 0 angle 30 resolution 8.5 8\n", 1, 52, "whole number"},
        {"__V__s 0 0 zero 1\n", 2, 7, "expected a number for sphere centre, got 'zero'"},
        {"__V__s 0 0 0\n", 2, 8, "the file ends where sphere radius"},
        {"__V__s 0 0 1e999 1\n", 2, 7, "got '1e999'"},
        {"__V__s 0 0 nan 1\n", 2, 7, "got 'nan'"},
        {"__V__f 1 1 1 1 0 1 0\n", 2, 16, "index of refraction"},
        {"__V__p 2 0 0 0 1 0 0\n", 2, 3, "from 3 to 20000"},
        {"__V__p 20001\n", 2, 3, "from 3 to 20000"},
        {"__V__p 1000 0 0 0\n", 2, 3, "ends before the polygon's 1000 corners"},
        {"__V__pp 3 0 0 0 0 0 1 1 0 0 0 0 0 0 1 0 0 0 1\n", 2, 24, "zero vector"},
        {"__V__c 0 0 0 1 0 0 1\n", 2, 16, "cone apex radius"},
        {"__V__l 1 2\n", 2, 6, "light position"},
        {"__V__b 1 1 x\n", 2, 7, "background colour"},
        {"v\r\nfrom 0 0 5\rat 0 0 0\nup 0 1 0 angle 30\r\ns 0 0 0 q\n", 5, 9, "sphere radius"},
    };
    for (const BadCase& c : cases) {
        std::string text = c.text;
        if (text.rfind("__V__", 0) == 0) text = v + text.substr(5);
        try {
            parse_nff_text(text, "bad.nff");
            ADD_FAILURE() << "accepted: " << text;
        } catch (const InputError& e) {
            EXPECT_EQ(e.where().file, "bad.nff") << text;
            EXPECT_EQ(e.where().line, c.line) << text << " -> " << e.what();
            EXPECT_EQ(e.where().column, c.column) << text << " -> " << e.what();
            EXPECT_NE(e.message().find(c.says), std::string::npos) << text << " -> " << e.what();
        }
    }
}

TEST(Nff, TheExtensionIsReadInAnyCase) {
    EXPECT_TRUE(is_nff_path("balls.nff"));
    EXPECT_TRUE(is_nff_path("dir/BALLS.NFF"));
    EXPECT_TRUE(is_nff_path("x.Nff"));
    EXPECT_FALSE(is_nff_path("x.nff.yaml"));
    EXPECT_FALSE(is_nff_path("nff"));
}

}  // namespace
}  // namespace whitted
