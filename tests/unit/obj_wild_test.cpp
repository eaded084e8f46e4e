// SPDX-License-Identifier: MIT
// OBJ files as exporters write them (issue 15): polygons that are not convex, a UTF-8 byte-order
// mark, Latin-1 names, numbers too small for a float, `mtllib` with several files, undefined
// materials and faces without any. Areas are closed-form; messages keep FILE:LINE:COL.

#include "render/accelerator.h"
#include "render/renderer.h"
#include "scene/mesh_file.h"
#include "scene/scene.h"

#include "test_support.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <numbers>
#include <random>
#include <string>
#include <vector>

namespace whitted {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

// ---------------------------------------------------------------------------------------------
// The triangulator, on polygons whose area is known in closed form.

struct Point2 {
    double x, y;
};

std::vector<Vec3> in_xy(const std::vector<Point2>& points) {
    std::vector<Vec3> corners;
    for (const Point2& p : points) corners.push_back({p.x, p.y, 0});
    return corners;
}

/// An L: the 2×2 square less its top right 1×1 quarter; area 3.
const std::vector<Point2> l_shape = {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};

/// A star of `points` tips on radius `outer`, the notches between them on radius `inner`:
/// 2·points triangles (centre, tip, notch) of area ½·outer·inner·sin(π/points) each.
std::vector<Point2> star(int points, double outer, double inner) {
    std::vector<Point2> corners;
    for (int k = 0; k < 2 * points; ++k) {
        const double angle = std::numbers::pi * k / points, r = k % 2 == 0 ? outer : inner;
        corners.push_back({r * std::cos(angle), r * std::sin(angle)});
    }
    return corners;
}
double star_area(int points, double outer, double inner) {
    return points * outer * inner * std::sin(std::numbers::pi / points);
}

/// A comb: a back of height 1 and width 2·teeth − 1, with `teeth` teeth of width 1 and length
/// 3 hanging from it, 1 apart; area (2·teeth − 1) + 3·teeth.
std::vector<Point2> comb(int teeth) {
    const double width = 2.0 * teeth - 1;
    std::vector<Point2> corners = {{0, 3}, {0, 0}, {1, 0}, {1, 3}};
    for (int t = 1; t < teeth; ++t) {
        const double left = 2.0 * t;
        corners.insert(corners.end(), {{left, 3}, {left, 0}, {left + 1, 0}, {left + 1, 3}});
    }
    corners.insert(corners.end(), {{width, 4}, {0, 4}});
    return corners;
}

/// Signed area of each triangle, seen from `normal`'s side.
std::vector<double> signed_areas(const std::vector<Vec3>& corners, const std::vector<uint32_t>& triangles,
                                 const Vec3& normal) {
    std::vector<double> areas;
    for (size_t t = 0; t + 2 < triangles.size(); t += 3) {
        const Vec3 a = corners[triangles[t]], b = corners[triangles[t + 1]], c = corners[triangles[t + 2]];
        areas.push_back(dot(cross(b - a, c - a), normal) / 2);
    }
    return areas;
}

/// The triangles cover the planar polygon (in z = 0, anticlockwise) exactly: n − 2 of them,
/// none turned over, their areas add up to `area`, and each of a grid of points inside the
/// polygon (and off every edge) is in exactly one of them, each point outside in none.
void expect_exact_cover(const std::vector<Point2>& polygon, double area) {
    const std::vector<Vec3> corners = in_xy(polygon);
    const std::vector<uint32_t> triangles = triangulate_polygon(corners);
    ASSERT_EQ(triangles.size(), 3 * (corners.size() - 2));
    for (const uint32_t c : triangles) ASSERT_LT(c, corners.size());
    double sum = 0;
    for (const double a : signed_areas(corners, triangles, {0, 0, 1})) {
        EXPECT_GE(a, -1e-12) << "a triangle is turned over";
        sum += a;
    }
    EXPECT_NEAR(sum, area, 1e-9 * area);
    // Crossing-number test for the polygon, barycentric signs for the triangles.
    const auto inside_polygon = [&](double x, double y) {
        bool inside = false;
        for (size_t i = 0, j = polygon.size() - 1; i < polygon.size(); j = i++) {
            const Point2 a = polygon[i], b = polygon[j];
            if ((a.y > y) != (b.y > y) && x < (b.x - a.x) * (y - a.y) / (b.y - a.y) + a.x) inside = !inside;
        }
        return inside;
    };
    const auto in_triangle = [&](size_t t, double x, double y) {
        const Vec3 p{x, y, 0};
        const Vec3 a = corners[triangles[t]], b = corners[triangles[t + 1]], c = corners[triangles[t + 2]];
        const double d1 = cross(b - a, p - a).z, d2 = cross(c - b, p - b).z, d3 = cross(a - c, p - c).z;
        return d1 > 0 && d2 > 0 && d3 > 0;
    };
    double min_x = 1e300, max_x = -1e300, min_y = 1e300, max_y = -1e300;
    for (const Point2& p : polygon)
        min_x = std::min(min_x, p.x), max_x = std::max(max_x, p.x), min_y = std::min(min_y, p.y),
        max_y = std::max(max_y, p.y);
    int inside_points = 0;
    for (int i = 0; i < 97; ++i) {
        for (int j = 0; j < 89; ++j) {
            // Irrational-looking offsets keep the samples off the edges.
            const double x = min_x + (max_x - min_x) * (i + 0.3183) / 97,
                         y = min_y + (max_y - min_y) * (j + 0.5772) / 89;
            int covering = 0;
            for (size_t t = 0; t < triangles.size(); t += 3) covering += in_triangle(t, x, y);
            const bool inside = inside_polygon(x, y);
            inside_points += inside;
            EXPECT_EQ(covering, inside ? 1 : 0) << "at (" << x << ", " << y << ")";
        }
    }
    EXPECT_GT(inside_points, 100);
}

TEST(Triangulate, LShapeFromEveryStartingCorner) {
    // The fan is right only from the reflex corner (1, 1); ear clipping from all of them.
    for (size_t start = 0; start < l_shape.size(); ++start) {
        std::vector<Point2> rotated(l_shape.begin() + long(start), l_shape.end());
        rotated.insert(rotated.end(), l_shape.begin(), l_shape.begin() + long(start));
        SCOPED_TRACE("starting at corner " + std::to_string(start));
        EXPECT_FALSE(is_convex_polygon(in_xy(rotated)));
        expect_exact_cover(rotated, 3.0);
    }
}

TEST(Triangulate, Stars) {
    expect_exact_cover(star(5, 1.0, 0.4), star_area(5, 1.0, 0.4));
    expect_exact_cover(star(33, 2.0, 1.5), star_area(33, 2.0, 1.5));    // 66 corners, as concave_polygon.obj
    expect_exact_cover(star(12, 10.0, 0.5), star_area(12, 10.0, 0.5));  // thin spikes
}

TEST(Triangulate, Combs) {
    for (const int teeth : {2, 3, 10, 40}) {
        SCOPED_TRACE(std::to_string(teeth) + " teeth");
        expect_exact_cover(comb(teeth), (2.0 * teeth - 1) + 3.0 * teeth);
    }
}

TEST(Triangulate, LargeSimplePolygonsStayExact) {
    // Thousands of corners that do not turn left, so the ear search does real work: its bound of
    // n²/2 corner-in-triangle tests must not cut short a polygon that is simple.
    expect_exact_cover(star(1500, 2.0, 1.0), star_area(1500, 2.0, 1.0));  // 3,000 corners
    expect_exact_cover(comb(1000), (2.0 * 1000 - 1) + 3.0 * 1000);        // 4,000 corners
}

TEST(Triangulate, APolygonThatCrossesItselfAtTheCornerLimitGetsItsTriangles) {
    // 20,000 corners at random points of a 100 × 100 grid: a polygon that crosses itself
    // everywhere, whose ear search finds no ear in n steps, n times over (55 s before its work
    // was bounded). It still gets n − 2 triangles of its own corners, each corner cut once.
    constexpr size_t n = 20000;
    std::mt19937 random(4620);
    std::uniform_int_distribution<int> coordinate(0, 99);
    std::vector<Vec3> corners;
    for (size_t i = 0; i < n; ++i) corners.push_back({double(coordinate(random)), double(coordinate(random)), 0});
    const std::vector<uint32_t> triangles = triangulate_polygon(corners);
    ASSERT_EQ(triangles.size(), 3 * (n - 2));
    std::vector<int> tips(n, 0);  // the middle corner of each cut is the one cut off
    for (size_t t = 0; t < triangles.size(); t += 3) {
        for (size_t k = 0; k < 3; ++k) ASSERT_LT(triangles[t + k], n);
        if (t + 3 < triangles.size()) ++tips[triangles[t + 1]];
    }
    EXPECT_EQ(*std::max_element(tips.begin(), tips.end()), 1) << "a corner was cut off twice";
}

/// An OBJ file of `faces` faces of `n` corners each at random points of a 100 × 100 grid (each
/// crosses itself everywhere: the ear clipping's worst case).
std::string crossing_faces_obj(int faces, int n) {
    std::mt19937 random(4620);
    std::uniform_int_distribution<int> coordinate(0, 99);
    std::string text;
    for (int i = 0; i < faces * n; ++i)
        text += "v " + std::to_string(coordinate(random)) + " " + std::to_string(coordinate(random)) + " 0\n";
    for (int f = 0; f < faces; ++f) {
        text += "f";
        for (int c = 0; c < n; ++c) text += " " + std::to_string(f * n + c + 1);
        text += "\n";
    }
    return text;
}

TEST(Triangulate, AFileOfManyLargeFacesIsCutWithinOneBudget) {
    // Each face is bounded (n²/2 corner tests) but a file was not: ten faces of 19,999 corners
    // took 25 s. The file's ear clipping is bounded at 4e8 tests, two such faces: the other eight
    // keep their fan, named in one warning, and every face still has its n − 2 triangles.
    constexpr int n = 19999;
    const test::ScratchDirectory directory;
    const std::string one = directory.write("one.obj", crossing_faces_obj(1, n));
    const std::string ten = directory.write("ten.obj", crossing_faces_obj(10, n));
    const auto seconds_to_load = [](const std::string& path, MeshData& mesh) {
        const auto start = std::chrono::steady_clock::now();
        mesh = load_obj_mesh(path, {}, 0, false);  // no MTL: no warnings of faces without usemtl
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    };
    MeshData mesh_one, mesh_ten;
    const double t_one = seconds_to_load(one, mesh_one), t_ten = seconds_to_load(ten, mesh_ten);
    EXPECT_TRUE(mesh_one.warnings.empty()) << mesh_one.warnings.front();
    ASSERT_EQ(mesh_ten.warnings.size(), 1u);
    EXPECT_THAT(mesh_ten.warnings[0], HasSubstr(ten + ":" + std::to_string(10 * n + 3) +
                                                ":1: 8 faces that are not convex, from this one on, keep the fan"));
    EXPECT_EQ(mesh_ten.indices.size(), size_t(10) * 3 * (n - 2));
    // Ears for the first face, the same as alone (the same corners); the fan for the third.
    for (size_t c = 0; c < mesh_one.indices.size(); ++c) ASSERT_EQ(mesh_ten.indices[c] % n, mesh_one.indices[c]);
    const size_t third = size_t(2) * 3 * (n - 2);
    EXPECT_EQ(mesh_ten.indices[third], uint32_t(2 * n));
    EXPECT_EQ(mesh_ten.indices[third + 1], uint32_t(2 * n + 1));
    EXPECT_EQ(mesh_ten.indices[third + 2], uint32_t(2 * n + 2));
    // Ten faces cost about two faces' ear clipping, not ten (a ratio, measured in one run).
    EXPECT_LT(t_ten, 5 * t_one) << "one face: " << t_one << " s, ten: " << t_ten << " s";
}

TEST(Triangulate, CollinearAndRepeatedCorners) {
    // The L with a corner in the middle of three edges, one corner written twice and one
    // straight run of three corners: still area 3, n − 2 triangles, some of no area.
    const std::vector<Point2> noisy = {{0, 0}, {1, 0}, {2, 0},   {2, 0}, {2, 1}, {1.5, 1},
                                       {1, 1}, {1, 2}, {0.5, 2}, {0, 2}, {0, 1}};
    for (size_t start = 0; start < noisy.size(); ++start) {
        std::vector<Point2> rotated(noisy.begin() + long(start), noisy.end());
        rotated.insert(rotated.end(), noisy.begin(), noisy.begin() + long(start));
        SCOPED_TRACE("starting at corner " + std::to_string(start));
        expect_exact_cover(rotated, 3.0);
    }
}

TEST(Triangulate, ConvexPolygonKeepsTheFanFromTheFirstCorner) {
    const std::vector<Vec3> hexagon = in_xy(star(3, 1.0, 1.0));  // all corners on one circle
    ASSERT_TRUE(is_convex_polygon(hexagon));
    const std::vector<uint32_t> triangles = triangulate_polygon(hexagon);
    EXPECT_EQ(triangles, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 4, 5}));
}

TEST(Triangulate, TiltedClockwisePolygonFarFromTheOrigin) {
    // The L turned clockwise (mirrored), then tilted about two axes and moved 10⁴ away: its plane
    // is found by Newell's method, the triangles keep its winding, the area stays 3.
    std::vector<Vec3> corners;
    const double c1 = std::cos(0.7), s1 = std::sin(0.7), c2 = std::cos(1.1), s2 = std::sin(1.1);
    for (auto it = l_shape.rbegin(); it != l_shape.rend(); ++it) {
        const Vec3 p{it->x, it->y, 0};
        const Vec3 q{p.x, c1 * p.y - s1 * p.z, s1 * p.y + c1 * p.z};   // about x
        const Vec3 r{c2 * q.x + s2 * q.z, q.y, -s2 * q.x + c2 * q.z};  // about y
        corners.push_back(r + Vec3{1e4, -2e4, 3e4});
    }
    EXPECT_FALSE(is_convex_polygon(corners));
    const std::vector<uint32_t> triangles = triangulate_polygon(corners);
    ASSERT_EQ(triangles.size(), 12u);
    Vec3 normal;  // of the mirrored L: −z, turned like the corners
    {
        const Vec3 q{0, -c1 * 0 + s1 * 1, -c1 * 1 - 0};  // (0, 0, −1) about x
        normal = {c2 * q.x + s2 * q.z, q.y, -s2 * q.x + c2 * q.z};
    }
    double sum = 0;
    for (const double a : signed_areas(corners, triangles, normal)) {
        EXPECT_GE(a, -1e-6);
        sum += a;
    }
    EXPECT_NEAR(sum, 3.0, 1e-6);
}

// ---------------------------------------------------------------------------------------------
// Through the OBJ reader.

double mesh_area(const MeshData& mesh) {
    double area = 0;
    for (size_t t = 0; t < mesh.indices.size(); t += 3) {
        Vec3 p[3];
        for (int k = 0; k < 3; ++k) {
            const float* xyz = &mesh.positions[3 * size_t(mesh.indices[t + size_t(k)])];
            p[k] = {xyz[0], xyz[1], xyz[2]};
        }
        const double signed_area = cross(p[1] - p[0], p[2] - p[0]).z / 2;
        EXPECT_GE(signed_area, -1e-9) << "triangle " << t / 3 << " is turned over";
        // Unsigned: triangles that overlap (a wrong fan) add up to more than the polygon.
        area += std::fabs(signed_area);
    }
    return area;
}

TEST(ObjWild, ConcaveFacesAreCutIntoEarsForEveryNumberOfRuns) {
    const test::ScratchDirectory directory;
    // Two faces, the second with normals, so that the rewrite also moves normal indices; the
    // fast path takes faces of up to 16 corners, the slow one the rest.
    std::string text = "vn 0 0 1\n";
    const std::vector<Point2> teeth = comb(3);  // 14 corners
    for (const Point2& p : teeth) text += "v " + std::to_string(p.x) + " " + std::to_string(p.y) + " 0\n";
    text += "f";
    for (size_t i = 1; i <= teeth.size(); ++i) text += " " + std::to_string(i) + "//1";
    text += "\n";
    const std::vector<Point2> big = star(20, 1.0, 0.5);  // 40 corners
    for (const Point2& p : big) text += "v " + std::to_string(p.x + 10) + " " + std::to_string(p.y) + " 0\nvn 0 0 1\n";
    text += "f";
    for (size_t i = 0; i < big.size(); ++i) text += " " + std::to_string(15 + i) + "/1/" + std::to_string(2 + i);
    text += "\n";
    const std::string path = directory.write("concave.obj", text);
    const MeshData whole = load_obj_mesh(path, {}, 1, false);
    EXPECT_EQ(whole.indices.size(), 3u * (12 + 38));
    EXPECT_NEAR(mesh_area(whole), 5.0 + 9.0 + star_area(20, 1.0, 0.5), 1e-5);
    for (int parts = 2; parts <= 5; ++parts) {
        const MeshData in_runs = load_obj_mesh(path, {}, parts, false);
        EXPECT_EQ(in_runs.indices, whole.indices) << parts;
        EXPECT_EQ(in_runs.positions, whole.positions) << parts;
    }
}

// The render of a comb-shaped face, seen straight on by an orthographic camera, ambient light
// only: the pixels it covers are its area over a pixel's, give or take one pixel along its
// outline. (The fan from its first corner would also fill the two gaps between the teeth,
// 6 of its 20 square units: 9600 pixels more, far beyond that.)
TEST(ObjWild, RenderOfAConcaveFaceCoversItsArea) {
    const test::ScratchDirectory directory;
    const std::vector<Point2> teeth = comb(3);  // 5 wide, 4 high, area 14
    std::string obj;
    for (const Point2& p : teeth) obj += "v " + std::to_string(p.x) + " " + std::to_string(p.y) + " 0\n";
    obj += "f";
    for (size_t i = 1; i <= teeth.size(); ++i) obj += " " + std::to_string(i);
    directory.write("comb.obj", obj + "\n");
    const int pixels = 240;
    const double view_width = 6.0, pixel = view_width / pixels;
    const Scene scene = test::scene_from(
        test::join_lines({"camera: {type: orthographic, eye: [2.5, 2, 10], look_at: [2.5, 2, 0], view_width: 6}",
                          "image: {width: 240, height: 240}", "ambient: 1",
                          "objects: [{type: mesh, file: comb.obj, material: {ka: 1}}]"}),
        (directory.path() / "scene.yaml").string());
    const Accelerator accelerator(scene, 1);
    RenderJob options;
    options.threads = 2;
    const RenderedTiles result = render(scene, accelerator, options);
    int covered = 0;
    for (int j = 0; j < pixels; ++j)
        for (int i = 0; i < pixels; ++i) covered += result.image.pixel(i, j)[0] > 0;
    double perimeter = 0;
    for (size_t k = 0; k < teeth.size(); ++k) {
        const Point2 a = teeth[k], b = teeth[(k + 1) % teeth.size()];
        perimeter += std::hypot(b.x - a.x, b.y - a.y);
    }
    EXPECT_NEAR(covered, 14.0 / (pixel * pixel), perimeter / pixel);
}

// An arrowhead quad (area 1.5, the reflex corner (1, 0.5)) from each of its corners: the fan
// is right only from the reflex corner or the one opposite it; quads take a shortcut of their own.
TEST(ObjWild, ArrowheadQuadFromEveryCorner) {
    const std::vector<Point2> arrow = {{0, 0}, {1, 0.5}, {2, 0}, {1, 2}};
    const test::ScratchDirectory directory;
    for (size_t start = 0; start < 4; ++start) {
        std::string text;
        for (size_t k = 0; k < 4; ++k) {
            const Point2 p = arrow[(start + k) % 4];
            text += "v " + std::to_string(p.x) + " " + std::to_string(p.y) + " 0\n";
        }
        const MeshData mesh = load_obj_mesh(directory.write("arrow.obj", text + "f 1 2 3 4\n"), {}, 1, false);
        ASSERT_EQ(mesh.indices.size(), 6u);
        EXPECT_NEAR(mesh_area(mesh), 1.5, 1e-6) << "starting at corner " << start;
    }
}

TEST(ObjWild, Utf8ByteOrderMarkIsSkipped) {
    const test::ScratchDirectory directory;
    const std::string path = directory.write("bom.obj", "\xEF\xBB\xBFv 1 2 3\nv 4 5 6\nv 7 8 10\nf 1 2 3\n");
    const MeshData mesh = load_obj_mesh(path, {}, 1, false);
    ASSERT_EQ(mesh.positions.size(), 9u) << "the first v line is read";
    EXPECT_EQ(mesh.positions[0], 1.0f);
    EXPECT_EQ(mesh.indices, (std::vector<uint32_t>{0, 1, 2}));
}

TEST(ObjWild, Utf16IsRefusedSayingSo) {
    const test::ScratchDirectory directory;
    const std::string path = directory.write("utf16.obj", std::string("\xFE\xFF\0v\0 \0001", 8));
    const auto error = test::input_error_from([&] { (void)load_obj_mesh(path, {}); });
    ASSERT_TRUE(error);
    EXPECT_THAT(std::string(error->what()), HasSubstr(path + ":1:1: the file is UTF-16 text"));
}

TEST(ObjWild, ControlBytesAreRefusedAtTheirPlace) {
    const test::ScratchDirectory directory;
    const std::string path = directory.write("binary.obj", "v 0 0 0\n# caf\xE9\nv 1\x01 0 0\n");
    const auto error = test::input_error_from([&] { (void)load_obj_mesh(path, {}); });
    ASSERT_TRUE(error);
    EXPECT_THAT(std::string(error->what()), HasSubstr(path + ":3:4: the file contains the control byte 0x01"));
}

TEST(ObjWild, Latin1NamesAreJustNames) {
    // regr01.obj's "Terraind\xE4k": g, usemtl and newmtl names of any bytes; comments too.
    const test::ScratchDirectory directory;
    directory.write("latin1.mtl", "# f\xFCr \xC4pfel\nnewmtl Terraind\xE4k\nKd 0.25 0.5 0.75\n");
    const std::string path = directory.write("latin1.obj",
                                             "mtllib latin1.mtl\n# Stra\xDF"
                                             "e\ng Fl\xE4"
                                             "che\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl Terraind\xE4k\nf 1 2 3\n");
    const MeshData mesh = load_obj_mesh(path, {});
    ASSERT_EQ(mesh.materials.size(), 1u);
    EXPECT_EQ(mesh.materials[0].name, "Terraind\xE4k");
    EXPECT_EQ(mesh.materials[0].kd.value, (Color{0.25, 0.5, 0.75}));
    EXPECT_EQ(mesh.triangle_material, (std::vector<int32_t>{0}));
    EXPECT_TRUE(mesh.warnings.empty());
}

TEST(ObjWild, MessagesEscapeBytesThatAreNotText) {
    const test::ScratchDirectory directory;
    directory.write("m.mtl", "newmtl Gr\xC3\xBCn\n");  // UTF-8 "Grün": printed as it is
    const std::string path =
        directory.write("m.obj", "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl Gr\xFCn\nf 1 2 3\n");
    const MeshData mesh = load_obj_mesh(path, {});
    ASSERT_EQ(mesh.warnings.size(), 1u);
    EXPECT_THAT(mesh.warnings[0],
                HasSubstr(path + ":5:8: material 'Gr\\xFCn' is not defined in 'm.mtl' (did you mean 'Gr\xC3\xBCn'?)"));
}

TEST(ObjWild, NumbersTooSmallForAFloatAreItsNearestValue) {
    const test::ScratchDirectory directory;
    const std::string path =
        directory.write("tiny.obj", "v 1e-50 -1e-50 1e-400\nv 1e-40 -1e-400 2.5e-45\nv 0 1 0\nf 1 2 3\n");
    const MeshData mesh = load_obj_mesh(path, {}, 1, false);
    ASSERT_EQ(mesh.positions.size(), 9u);
    EXPECT_EQ(mesh.positions[0], 0.0f);
    EXPECT_TRUE(std::signbit(mesh.positions[1]));
    EXPECT_EQ(mesh.positions[2], 0.0f);
    EXPECT_EQ(mesh.positions[3], std::strtof("1e-40", nullptr));  // a subnormal
    EXPECT_GT(mesh.positions[3], 0.0f);
    EXPECT_TRUE(std::signbit(mesh.positions[4]));
    EXPECT_EQ(mesh.positions[5], std::strtof("2.5e-45", nullptr));  // 2 × the smallest subnormal
}

TEST(ObjWild, NumbersBeyondFloatRangeAreStillRefused) {
    const test::ScratchDirectory directory;
    for (const char* huge : {"1e39", "-1e400", "inf", "nan"}) {
        const std::string path = directory.write("huge.obj", std::string("v 0 0 0\nv 0 ") + huge + " 0\n");
        const auto error = test::input_error_from([&] { (void)load_obj_mesh(path, {}); });
        ASSERT_TRUE(error) << huge;
        EXPECT_THAT(std::string(error->what()), HasSubstr(path + ":2:5: a vertex coordinate must be a finite number"))
            << huge;
    }
}

const char* const triangle_obj_body = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n";

TEST(ObjWild, MtllibIsAListOfFiles) {
    const test::ScratchDirectory directory;
    directory.write("a.mtl", "newmtl red\nKd 1 0 0\n");
    directory.write("b.mtl", "newmtl blue\nKd 0 0 1\n");
    const std::string path = directory.write("list.obj", std::string("mtllib a.mtl  b.mtl\n") + triangle_obj_body +
                                                             "usemtl blue\nf 1 2 3\nusemtl red\nf 2 4 3\n");
    const MeshData mesh = load_obj_mesh(path, {});
    ASSERT_EQ(mesh.materials.size(), 2u);
    ASSERT_EQ(mesh.triangle_material.size(), 2u);
    EXPECT_EQ(mesh.materials[size_t(mesh.triangle_material[0])].kd.value, (Color{0, 0, 1}));
    EXPECT_EQ(mesh.materials[size_t(mesh.triangle_material[1])].kd.value, (Color{1, 0, 0}));
}

// An MTL file named on many mtllib lines (or twice on one) is read once: each reading added its
// materials again (50 lines naming one MTL file of 100,000 materials took 29 s and 2.8 GB).
TEST(ObjWild, AnMtlFileNamedAgainIsReadOnce) {
    const test::ScratchDirectory directory;
    directory.write("a.mtl", "newmtl red\nKd 1 0 0\nnewmtl green\nKd 0 1 0\n");
    directory.write("b.mtl", "newmtl blue\nKd 0 0 1\n");
    std::string text;
    for (int i = 0; i < 1000; ++i) text += i % 2 ? "mtllib a.mtl b.mtl a.mtl\n" : "mtllib a.mtl\n";
    const std::string path =
        directory.write("many.obj", text + triangle_obj_body + "usemtl blue\nf 1 2 3\nusemtl green\nf 2 4 3\n");
    const MeshData mesh = load_obj_mesh(path, {});
    ASSERT_EQ(mesh.materials.size(), 3u);  // red, green, blue: each once
    EXPECT_EQ(mesh.materials[size_t(mesh.triangle_material[0])].kd.value, (Color{0, 0, 1}));
    EXPECT_EQ(mesh.materials[size_t(mesh.triangle_material[1])].kd.value, (Color{0, 1, 0}));
    EXPECT_TRUE(mesh.warnings.empty());
}

// The same file under other spellings (`./a.mtl`, `././a.mtl`, a link to it) is read once too: 50
// spellings of one MTL file of 100,000 materials took 49.8 s and 3.46 GB.
TEST(ObjWild, AnMtlFileSpelledManyWaysIsReadOnce) {
    const test::ScratchDirectory directory;
    directory.write("a.mtl", "newmtl red\nKd 1 0 0\nnewmtl green\nKd 0 1 0\n");
    std::filesystem::create_directory(directory.path() / "sub");
    std::filesystem::create_symlink("a.mtl", directory.path() / "link.mtl");
    std::string text = "mtllib link.mtl\nmtllib sub/../a.mtl\n";
    for (std::string spelling = "a.mtl"; spelling.size() < 200; spelling = "./" + spelling)
        text += "mtllib " + spelling + "\n";
    const std::string path = directory.write("many.obj", text + triangle_obj_body + "usemtl green\nf 1 2 3\n");
    const MeshData mesh = load_obj_mesh(path, {});
    ASSERT_EQ(mesh.materials.size(), 2u);  // red, green: once, not once per spelling
    EXPECT_EQ(mesh.materials[size_t(mesh.triangle_material[0])].kd.value, (Color{0, 1, 0}));
    EXPECT_TRUE(mesh.warnings.empty());
}

TEST(ObjWild, MtllibOfOneNameWithSpaces) {
    // box_mat_with_spaces.obj's rule: the whole rest of the line, if a file has that name.
    const test::ScratchDirectory directory;
    directory.write("my materials.mtl", "newmtl Material name with many, many spaces \nKd 0.5 0.5 0.5\n");
    const std::string path =
        directory.write("spaces.obj", std::string("mtllib my materials.mtl\n") + triangle_obj_body +
                                          "usemtl Material name with many, many spaces   \nf 1 2 3\n");
    const MeshData mesh = load_obj_mesh(path, {});
    ASSERT_EQ(mesh.materials.size(), 1u);
    EXPECT_EQ(mesh.materials[0].name, "Material name with many, many spaces");
    EXPECT_EQ(mesh.triangle_material, (std::vector<int32_t>{0}));
}

// A usemtl that no MTL file defines is drawn, as assimp and Blender draw it, in the default
// material, with a warning that says where and why.
TEST(ObjWild, UndefinedMaterialIsDrawnInTheDefaultWithAWarningSayingWhereAndWhy) {
    const test::ScratchDirectory directory;
    directory.write("known.mtl", "newmtl red\nKd 1 0 0\n");
    const std::string undefined = directory.write(
        "u.obj", std::string("mtllib known.mtl\n") + triangle_obj_body + "usemtl blue\nf 1 2 3\nusemtl red\nf 2 4 3\n");
    MeshData mesh = load_obj_mesh(undefined, {});
    ASSERT_EQ(mesh.warnings.size(), 1u);
    EXPECT_THAT(mesh.warnings[0], HasSubstr(undefined + ":6:8: material 'blue' is not defined in 'known.mtl'"));
    EXPECT_THAT(mesh.warnings[0], HasSubstr("(1 triangle); they get the default material (kd 0.6 grey"));
    ASSERT_EQ(mesh.materials.size(), 2u);  // red, then the default
    EXPECT_EQ(mesh.triangle_material, (std::vector<int32_t>{1, 0}));
    EXPECT_EQ(mesh.materials[1].kd.value, Color(0.6));

    const std::string missing = directory.write(
        "m.obj", std::string("mtllib known.mtl gone.mtl\n") + triangle_obj_body + "usemtl blue\nf 1 2 3\n");
    mesh = load_obj_mesh(missing, {});
    ASSERT_EQ(mesh.warnings.size(), 1u);
    EXPECT_THAT(mesh.warnings[0], HasSubstr(missing +
                                            ":6:8: material 'blue' is not defined in 'known.mtl': the MTL file "
                                            "'gone.mtl' (mtllib at " +
                                            missing + ":1:18) was not found"));

    // The object's own material makes the MTL files unneeded: nothing to say.
    EXPECT_TRUE(load_obj_mesh(missing, {}, 0, false).warnings.empty());
}

// A statement before any newmtl belongs to no material: left out with a warning. What cannot be
// read at all (a colour that is not a number) is still refused, with its place.
TEST(ObjWild, MtlStatementBeforeAnyNewmtlIsLeftOutWithAWarning) {
    const test::ScratchDirectory directory;
    directory.write("early.mtl", "Kd 1 0 0\nnewmtl x\nKd 0 0 1\n");
    const std::string path =
        directory.write("e.obj", std::string("mtllib early.mtl\n") + triangle_obj_body + "usemtl x\nf 1 2 3\n");
    const MeshData mesh = load_obj_mesh(path, {});
    ASSERT_EQ(mesh.warnings.size(), 1u);
    EXPECT_THAT(mesh.warnings[0], HasSubstr("early.mtl:1:1: Kd before any newmtl belongs to no material"));
    ASSERT_EQ(mesh.materials.size(), 1u);
    EXPECT_EQ(mesh.materials[0].kd.value, (Color{0, 0, 1}));

    directory.write("broken.mtl", "newmtl x\nKd red\n");
    const std::string broken =
        directory.write("b.obj", std::string("mtllib broken.mtl\n") + triangle_obj_body + "usemtl x\nf 1 2 3\n");
    const auto error = test::input_error_from([&] { (void)load_obj_mesh(broken, {}); });
    ASSERT_TRUE(error);
    EXPECT_THAT(std::string(error->what()), HasSubstr("broken.mtl:2:4: expected a colour"));
    // The scene's own material makes the MTL file unneeded: it is not read.
    const MeshData own = load_obj_mesh(broken, {}, 0, false);
    EXPECT_TRUE(own.materials.empty());
    EXPECT_EQ(own.triangle_material, (std::vector<int32_t>{-1}));
}

TEST(ObjWild, FacesWithoutMaterialGetTheDefaultOneAndAWarning) {
    const test::ScratchDirectory directory;
    directory.write("known.mtl", "newmtl red\nKd 1 0 0\n");
    const std::string path = directory.write(
        "d.obj", std::string("mtllib known.mtl\n") + triangle_obj_body + "f 1 2 3\nusemtl red\nf 2 4 3\n");
    const MeshData mesh = load_obj_mesh(path, {});
    ASSERT_EQ(mesh.materials.size(), 2u);
    const MaterialDescription& fallback = mesh.materials[size_t(mesh.triangle_material[0])];
    EXPECT_EQ(fallback.name, default_obj_material_name);
    EXPECT_EQ(fallback.kd.value, Color(0.6));
    EXPECT_EQ(fallback.ka.value, Color(0.0));
    EXPECT_EQ(fallback.ks.value, Color(0.0));
    EXPECT_EQ(fallback.km.value, Color(0.0));
    EXPECT_EQ(mesh.materials[size_t(mesh.triangle_material[1])].name, "red");
    ASSERT_EQ(mesh.warnings.size(), 1u);
    EXPECT_THAT(
        mesh.warnings[0],
        HasSubstr(path + ":6:1: faces without usemtl, from this one on (1 triangle); they get the default material"));

    // usemtl without any mtllib (box.obj): the names are labels, the faces get the default.
    const std::string labels = directory.write("l.obj", std::string(triangle_obj_body) + "usemtl Default\nf 1 2 3 4\n");
    const MeshData labelled = load_obj_mesh(labels, {});
    ASSERT_EQ(labelled.materials.size(), 1u);
    EXPECT_EQ(labelled.triangle_material, (std::vector<int32_t>{0, 0}));
    ASSERT_EQ(labelled.warnings.size(), 1u);
    EXPECT_THAT(labelled.warnings[0],
                HasSubstr(labels + ":5:8: usemtl 'Default', but the file names no MTL file (mtllib) (2 triangles)"));
}

TEST(ObjWild, CountsInMessagesAreGrammatical) {
    const test::ScratchDirectory directory;
    const std::string one = directory.write("one.obj", "v 0 0 0\nf 1 2 3\n");
    auto error = test::input_error_from([&] { (void)load_obj_mesh(one, {}); });
    ASSERT_TRUE(error);
    EXPECT_THAT(std::string(error->what()), HasSubstr(one + ":2:5: face refers to vertex 2, but 1 vertex is defined"));
    const std::string eight = directory.write(
        "eight.obj", std::string(triangle_obj_body) + triangle_obj_body + "vn 0 0 1\nf 1//1 2//1 3//2\n");
    error = test::input_error_from([&] { (void)load_obj_mesh(eight, {}); });
    ASSERT_TRUE(error);
    EXPECT_THAT(std::string(error->what()), HasSubstr(":10:13: face refers to normal 2, but 1 normal is defined"));
    const std::string vertices =
        directory.write("v.obj", std::string(triangle_obj_body) + triangle_obj_body + "f 1 2 9\n");
    error = test::input_error_from([&] { (void)load_obj_mesh(vertices, {}); });
    ASSERT_TRUE(error);
    EXPECT_THAT(std::string(error->what()), HasSubstr(":9:7: face refers to vertex 9, but 8 vertices are defined"));
}

TEST(ObjWild, LinesAndPointsOnlyAreNamedAsTheCause) {
    const test::ScratchDirectory directory;
    const std::string path = directory.write("lines.obj", std::string(triangle_obj_body) + "l 1 2 3\np 4\n");
    const auto error = test::input_error_from([&] { (void)load_obj_mesh(path, {"scene.yaml", 3, 5}); });
    ASSERT_TRUE(error);
    EXPECT_THAT(std::string(error->what()), HasSubstr("scene.yaml:3:5: mesh file '" + path +
                                                      "' has no faces: its 2 line (l) or point (p) "
                                                      "statements are not drawn"));
}

}  // namespace
}  // namespace whitted
