// SPDX-License-Identifier: MIT
// The course's XML reader (docs/course-format.md): what each element becomes in the plain
// description, with its place; the window camera against the course's formula written out here;
// Schlick's factor against its closed form.

#include "scene/course_xml.h"
#include "render/camera.h"
#include "render/shading.h"
#include "scene/scene.h"
#include "scene/text_checks.h"

#include <gtest/gtest.h>

#include <cctype>
#include <cmath>

namespace whitted {
namespace {

const char* const sphere_scene = R"(<?xml version="1.0"?>
<scene>
  <camera>
    <viewPoint>5 4 3</viewPoint>
    <viewDir>-5 -4 -3</viewDir>
    <viewUp>0 1 0</viewUp>
    <projDistance>5</projDistance>
    <viewWidth>2.5</viewWidth>
    <viewHeight>2</viewHeight>
  </camera>
  <image>30 20</image>
  <shader name="blue" type="Phong"><diffuseColor>.2 .3 .8</diffuseColor><exponent>50</exponent></shader>
  <surface type="Sphere"><shader ref="blue" /><radius>2</radius></surface>
  <light><position>3 4 5</position></light>
</scene>
)";

TEST(CourseXml, ElementsBecomeWhittedKeysWithTheirPlaces) {
    const SceneDescription d = parse_course_xml_text(sphere_scene, "s.xml");
    EXPECT_EQ(d.camera.eye.value, Vec3(5, 4, 3));
    EXPECT_EQ(d.camera.look_at.value, Vec3(0, 0, 0));
    EXPECT_EQ(d.camera.eye.where.line, 4);
    EXPECT_EQ(d.camera.eye.where.column, 16);        // the first number, not the element
    EXPECT_TRUE(d.camera.image_plane_normal.given);  // the 2010 camera: (0, 0, 1) by default
    EXPECT_EQ(d.camera.image_plane_normal.value, Vec3(0, 0, 1));
    EXPECT_EQ(d.camera.projection_distance.value, 5);
    EXPECT_EQ(d.image.width.value, 30);
    EXPECT_EQ(d.image.height.value, 20);
    ASSERT_EQ(d.materials.size(), 1u);
    EXPECT_EQ(d.materials[0].kd.value, Color(.2, .3, .8));
    EXPECT_EQ(d.materials[0].ks.value, Color(1.0));  // the course's default specularColor
    EXPECT_EQ(d.materials[0].ka.value, Color(0.0));
    EXPECT_EQ(d.materials[0].p.value, 50);
    ASSERT_EQ(d.objects.size(), 1u);
    const auto& sphere = std::get<SphereShape>(d.objects[0].shape);
    EXPECT_EQ(sphere.center.value, Vec3(0, 0, 0));  // default centre
    EXPECT_EQ(sphere.radius.value, 2);
    EXPECT_EQ(d.lights[0].intensity.value, Color(1.0));
    EXPECT_EQ(d.convention.value, Convention::course);
    EXPECT_EQ(d.ambient.value, Color(0.0));
    EXPECT_EQ(d.max_depth.value, 11);
    EXPECT_EQ(d.min_weight.value, 0.01);
}

TEST(CourseXml, ObliqueWindowCameraFollowsTheCourseFormula) {
    const SceneDescription d = parse_course_xml_text(sphere_scene, "s.xml");
    const Camera camera = make_camera(d.camera, 30, 20);
    // The course: w = normalize(projNormal) = (0, 0, 1); V = up projected into the plane = (0, 1, 0);
    // U = V × w = (1, 0, 0); centre = eye + 5·normalize(viewDir); pixel (x, y from the bottom).
    const Vec3 eye(5, 4, 3), dir = normalize(Vec3(-5, -4, -3));
    for (const auto& [x, y] : {std::pair{0, 0}, std::pair{29, 19}, std::pair{7, 13}}) {
        const double u = (x + 0.5) / 30 - 0.5, v = (y + 0.5) / 20 - 0.5;
        const Vec3 point = eye + dir * 5.0 + Vec3(1, 0, 0) * (u * 2.5) + Vec3(0, 1, 0) * (v * 2.0);
        const Vec3 expected = normalize(point - eye);
        // Whitted's row j counts from the top.
        const int j = 19 - y;
        const Ray ray = camera_ray(camera, (x + 0.5) / 30 - 0.5, 0.5 - (j + 0.5) / 20);
        EXPECT_NEAR(ray.direction.x, expected.x, 1e-12);
        EXPECT_NEAR(ray.direction.y, expected.y, 1e-12);
        EXPECT_NEAR(ray.direction.z, expected.z, 1e-12);
        EXPECT_EQ(ray.origin, eye);
    }
}

TEST(CourseXml, GroupTransformsAreReversedAndRotationIsXThenYThenZ) {
    const SceneDescription d = parse_course_xml_text(R"(<scene><camera/><image>1 1</image>
<shader name="s" type="Lambertian"/>
<surface type="Group"><translate>1 2 3</translate><rotate>10 20 30</rotate><scale>2 2 2</scale>
<surface type="Sphere"><shader ref="s"/></surface></surface></scene>)",
                                                     "g.xml");
    ASSERT_EQ(d.objects.size(), 1u);
    const auto& steps = d.objects[0].transform;
    ASSERT_EQ(steps.size(), 5u);
    EXPECT_EQ(steps[0].kind, TransformStep::Kind::scale);  // last in the file, first on the points
    EXPECT_EQ(steps[1].kind, TransformStep::Kind::rotate);
    EXPECT_EQ(steps[1].vector, Vec3(1, 0, 0));
    EXPECT_EQ(steps[1].angle, 10);
    EXPECT_EQ(steps[2].vector, Vec3(0, 1, 0));
    EXPECT_EQ(steps[2].angle, 20);
    EXPECT_EQ(steps[3].vector, Vec3(0, 0, 1));
    EXPECT_EQ(steps[3].angle, 30);
    EXPECT_EQ(steps[4].kind, TransformStep::Kind::translate);
    // The children inherit nothing but the shader they name.
    EXPECT_EQ(std::get<GroupShape>(d.objects[0].shape).objects[0].material->name, "s");
}

TEST(CourseXml, GlazedTakesTheSubstrateAndTheIndex) {
    const SceneDescription d = parse_course_xml_text(R"(<scene><camera/><image>1 1</image>
<shader name="g" type="Glazed"><refractiveIndex>1.5</refractiveIndex>
<substrate type="Lambertian"><diffuseColor>.4 .5 .8</diffuseColor></substrate></shader></scene>)",
                                                     "g.xml");
    ASSERT_EQ(d.materials.size(), 1u);
    EXPECT_EQ(d.materials[0].kd.value, Color(.4, .5, .8));
    EXPECT_EQ(d.materials[0].fresnel_ior.value, 1.5);
    EXPECT_FALSE(d.materials[0].km.given);
}

TEST(CourseXml, MistakesNameLineAndColumn) {
    const auto error_of = [](const std::string& text) {
        try {
            parse_course_xml_text(text, "bad.xml");
        } catch (const InputError& e) {
            return e.where().str() + " " + e.message();
        }
        return std::string("no error");
    };
    EXPECT_EQ(error_of("<scene>\n  <camera><viewPoint>1 2 x</viewPoint></camera></scene>").rfind("bad.xml:2:26 ", 0),
              0u)
        << error_of("<scene>\n  <camera><viewPoint>1 2 x</viewPoint></camera></scene>");
    EXPECT_NE(error_of("<scene>\n <bogus/></scene>").find("bad.xml:2:2 <scene>: unknown element <bogus>"),
              std::string::npos);
    EXPECT_NE(
        error_of(
            "<scene><camera/><image>1 1</image>\n<surface type=\"Sphere\"><shader ref=\"nope\"/></surface></scene>")
            .find("bad.xml:2:24 unknown shader 'nope'"),
        std::string::npos);
    EXPECT_NE(error_of("<scene><camera>\n</scene>").find("XML syntax error"), std::string::npos);
    EXPECT_NE(error_of("<scene><image>1 1</image><samples>8</samples><camera/></scene>").find("square number"),
              std::string::npos);
}

// Elements nested past 512 levels are refused where the 513th opens, however deep the file goes:
// 300,000 levels once overflowed the stack while the tree was freed during the error's unwinding.
TEST(CourseXml, DeepNestingIsRefusedWhereItPassesTheLimit) {
    for (const size_t levels : {size_t(513), size_t(300000)}) {
        std::string text = "<scene>";
        for (size_t i = 1; i < levels; ++i) text += "<surface>";
        for (size_t i = 1; i < levels; ++i) text += "</surface>";
        text += "</scene>";
        try {
            parse_course_xml_text(text, "deep.xml");
            ADD_FAILURE() << levels << " levels: no error";
        } catch (const InputError& e) {
            EXPECT_EQ(e.message(), "elements nested more than 512 levels deep") << levels;
            // The 513th element begins after "<scene>" and 511 "<surface>"s.
            EXPECT_EQ(e.where().str(), "deep.xml:1:" + std::to_string(7 + 511 * 9 + 1)) << levels;
        }
    }
}

// Shaders are found by a hash look-up, and the unknown-shader message lists at most 20 names,
// each escaped and cut short (a file of 100,000 shaders or megabyte names gave 20 MB messages).
TEST(CourseXml, UnknownShaderMessageIsBounded) {
    std::string text = "<scene><camera/><image>1 1</image>\n";
    for (int i = 0; i < 30; ++i)
        text += "<shader name=\"" + std::string(100, 'a') + std::to_string(i) +
                "\" type=\"Lambertian\"><diffuseColor>1 1 1</diffuseColor></shader>\n";
    text += "<surface type=\"Sphere\"><shader ref=\"nope\"/></surface></scene>";
    try {
        parse_course_xml_text(text, "many.xml");
        ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
        const std::string message = e.what();
        EXPECT_LT(message.size(), 2000u) << message.size();
        EXPECT_NE(message.find("unknown shader 'nope'"), std::string::npos) << message;
        EXPECT_NE(message.find("... (30 in all)"), std::string::npos) << message;
    }
}

TEST(Printable, ControlsC1AndBytesThatAreNotUtf8AreEscaped) {
    EXPECT_EQ(printable("a\x1b[2Jb\x07"), "a\\x1b[2Jb\\x07");
    EXPECT_EQ(printable("\xc2\x9b"
                        "2J"),
              "\\x9b2J");                                                          // U+009B, a terminal's CSI
    EXPECT_EQ(printable("Gr\xfcn"), "Gr\\xfcn");                                   // Latin-1, not UTF-8
    EXPECT_EQ(printable("Gr\xc3\xbcn \xe2\x80\xa8"), "Gr\xc3\xbcn \xe2\x80\xa8");  // UTF-8 stays
    EXPECT_EQ(printable(std::string(100, 'x'), 10), "xxxxxxxxxx... (100 bytes)");
}

TEST(Shading, SchlickFresnelClosedForm) {
    const double r0 = 0.04;
    EXPECT_DOUBLE_EQ(LectureShading::schlick_fresnel(r0, 1.0), 0.04);
    EXPECT_DOUBLE_EQ(LectureShading::schlick_fresnel(r0, 0.0), 1.0);
    EXPECT_DOUBLE_EQ(LectureShading::schlick_fresnel(r0, 0.5), 0.04 + 0.96 * 0.03125);
    EXPECT_EQ(LectureShading::schlick_fresnel(r0, -0.1), 0.0);  // seen from behind
}

// The course's parser matches element names to its setters ignoring case: every element of a
// scene written in lower, upper or mixed case reads as the scene in the course's own spelling.
TEST(CourseXml, ElementNamesIgnoreCaseAsTheCoursesParserDoes) {
    const char* const box_scene = R"(<?xml version="1.0"?>
<scene>
  <camera>
    <viewPoint>5 4 3</viewPoint><viewDir>-5 -4 -3</viewDir><viewUp>0 1 0</viewUp>
    <projNormal>5 4 3</projNormal><projDistance>5</projDistance><viewWidth>2.5</viewWidth><viewHeight>2</viewHeight>
  </camera>
  <image>30 20</image>
  <samples>4</samples>
  <shader name="red" type="Phong"><diffuseColor>.8 .2 .1</diffuseColor><specularColor>.5 .5 .5</specularColor><exponent>20</exponent></shader>
  <shader name="glaze" type="Glazed"><refractiveIndex>1.5</refractiveIndex><substrate type="Lambertian"><diffuseColor>.2 .3 .8</diffuseColor></substrate></shader>
  <surface type="Box"><shader ref="red" /><minPt>-1 -1 -1</minPt><maxPt>1 1 1</maxPt></surface>
  <surface type="Group"><translate>1 0 0</translate><rotate>0 30 0</rotate><scale>1 2 1</scale>
    <surface type="Sphere"><shader ref="glaze" /><center>0 1 0</center><radius>0.5</radius></surface>
  </surface>
  <light><position>3 4 5</position><intensity>1 1 1</intensity></light>
</scene>
)";
    const SceneDescription canonical = parse_course_xml_text(box_scene, "c.xml");
    const auto respelled = [&](auto change) {
        std::string text = box_scene;
        std::string out;
        for (size_t i = 0; i < text.size(); ++i) {
            out += text[i];
            if (text[i] != '<' || i + 1 >= text.size() || text[i + 1] == '?') continue;
            size_t j = i + 1;
            if (text[j] == '/') out += text[j++];
            const size_t end = text.find_first_of(" />", j);
            out += change(text.substr(j, end - j));
            i = end - 1;
        }
        return out;
    };
    const auto lower = [](std::string w) {
        for (char& c : w) c = char(std::tolower(static_cast<unsigned char>(c)));
        return w;
    };
    const auto upper = [](std::string w) {
        for (char& c : w) c = char(std::toupper(static_cast<unsigned char>(c)));
        return w;
    };
    const auto mixed = [](std::string w) {
        for (size_t k = 0; k < w.size(); k += 2) w[k] = char(std::toupper(static_cast<unsigned char>(w[k])));
        return w;
    };
    for (const std::string& text : {respelled(lower), respelled(upper), respelled(mixed)}) {
        ASSERT_NE(text, box_scene);
        const SceneDescription d = parse_course_xml_text(text, "c.xml");
        EXPECT_EQ(d.camera.eye.value, canonical.camera.eye.value);
        EXPECT_EQ(d.camera.image_plane_normal.value, canonical.camera.image_plane_normal.value);
        EXPECT_EQ(d.camera.view_height.value, canonical.camera.view_height.value);
        EXPECT_EQ(d.image.samples.value, canonical.image.samples.value);
        ASSERT_EQ(d.materials.size(), canonical.materials.size());
        EXPECT_EQ(d.materials[0].ks.value, canonical.materials[0].ks.value);
        EXPECT_EQ(d.materials[1].fresnel_ior.value, canonical.materials[1].fresnel_ior.value);
        ASSERT_EQ(d.objects.size(), canonical.objects.size());
        EXPECT_EQ(std::get<BoxShape>(d.objects[0].shape).max.value,
                  std::get<BoxShape>(canonical.objects[0].shape).max.value);
        const auto& group = std::get<GroupShape>(d.objects[1].shape);
        const auto& canonical_group = std::get<GroupShape>(canonical.objects[1].shape);
        ASSERT_EQ(group.objects.size(), 1u);
        EXPECT_EQ(d.objects[1].transform.size(), canonical.objects[1].transform.size());
        EXPECT_EQ(std::get<SphereShape>(group.objects[0].shape).radius.value,
                  std::get<SphereShape>(canonical_group.objects[0].shape).radius.value);
        EXPECT_EQ(d.lights[0].position.value, canonical.lights[0].position.value);
    }
    // A name that is no element in any case is still refused, with its place and a suggestion.
    try {
        parse_course_xml_text(respelled([](std::string w) { return w == "radius" ? std::string("radios") : w; }),
                              "c.xml");
        ADD_FAILURE() << "<radios> accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("unknown element <radios>"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace whitted
