// SPDX-License-Identifier: MIT
// Scene-format v1 input errors: each mistake must be refused with a message that says what is
// wrong, at the line and column where it was written (1-based). Single values are checked by
// parse_scene_text, ranges and cross-references by validate_scene; both are exercised through
// test::scene_error, which runs the two in sequence.

#include "scene/description.h"
#include "scene/scene.h"

#include "test_support.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <ctime>

namespace whitted {
namespace {

using test::column_of;
using test::join_lines;
using test::scene_error;
using ::testing::HasSubstr;

// A valid scene; each test changes one line (line k is index k − 1).
std::vector<std::string> base_lines() {
    return {
        "camera: {eye: [0, 0, 5], look_at: [0, 0, 0]}",  // 1
        "image: {width: 8, height: 6}",                  // 2
        "materials:",                                    // 3
        "  red: {kd: [1, 0, 0]}",                        // 4
        "objects:",                                      // 5
        "  - type: sphere",                              // 6
        "    center: [0, 0, 0]",                         // 7
        "    radius: 1",                                 // 8
        "    material: red",                             // 9
    };
}

/// Expects `lines` to be refused with `fragment` in the message, at `line` and the column
/// where `token` starts on that line.
void expect_error_at(const std::vector<std::string>& lines, const std::string& fragment, int line,
                     const std::string& token) {
    const auto error = scene_error(join_lines(lines));
    ASSERT_TRUE(error);
    EXPECT_THAT(error->message(), HasSubstr(fragment));
    EXPECT_EQ(error->where().file, "scene.yaml");
    EXPECT_EQ(error->where().line, line) << error->what();
    EXPECT_EQ(error->where().column, column_of(lines[size_t(line) - 1], token)) << error->what();
}

TEST(Parse, BaseSceneIsValidAndDefaultsFollowTheContract) {
    const SceneDescription d = parse_scene_text(join_lines(base_lines()), "scene.yaml");
    EXPECT_EQ(d.version.value, 1);
    EXPECT_EQ(d.camera.type.value, CameraType::perspective);
    EXPECT_EQ(d.camera.up.value, (Vec3{0, 1, 0}));
    EXPECT_EQ(d.camera.fov.value, 45.0);
    EXPECT_EQ(d.image.samples.value, 1);
    EXPECT_EQ(d.image.background.value, Color(0.0));
    EXPECT_EQ(d.max_depth.value, 5);
    EXPECT_EQ(d.ambient.value, Color(1.0));
    ASSERT_EQ(d.materials.size(), 1u);
    EXPECT_EQ(d.materials[0].ka.value, Color(0.0));
    EXPECT_EQ(d.materials[0].ks.value, Color(0.0));
    EXPECT_EQ(d.materials[0].km.value, Color(0.0));
    EXPECT_EQ(d.materials[0].p.value, 1.0);
    EXPECT_EQ(d.materials[0].highlight.value, Highlight::blinn);
    const Scene scene = validate_scene(d);
    EXPECT_EQ(scene.spheres.size(), 1u);
}

// JSON is YAML; a single number stands for a grey colour.
TEST(Parse, JsonSceneAndGreyShorthand) {
    const SceneDescription d =
        parse_scene_text(R"({"camera": {"eye": [0, 0, 5], "look_at": [0, 0, 0]}, "image": {"width": 4, "height": 4},)"
                         R"( "ambient": 0.25, "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 2,)"
                         R"( "material": {"kd": 0.5, "km": [0.1, 0.2, 0.3]}}]})",
                         "scene.json");
    EXPECT_EQ(d.ambient.value, Color(0.25));
    ASSERT_EQ(d.objects.size(), 1u);
    ASSERT_TRUE(d.objects[0].material && d.objects[0].material->inline_);
    EXPECT_EQ(d.objects[0].material->inline_->kd.value, Color(0.5));
    EXPECT_EQ(d.objects[0].material->inline_->km.value, (Color{0.1, 0.2, 0.3}));
    EXPECT_EQ(std::get<SphereShape>(d.objects[0].shape).radius.value, 2.0);
}

TEST(ParseErrors, YamlSyntaxErrorAtTheStrayBracket) {
    auto lines = base_lines();
    lines[1] = "image: {width: 8, height: 6]";
    expect_error_at(lines, "syntax error", 2, "]");
}

TEST(ParseErrors, MessageReadsFileLineColumn) {
    auto lines = base_lines();
    lines[7] = "    radius: big";
    const auto error = scene_error(join_lines(lines));
    ASSERT_TRUE(error);
    EXPECT_THAT(std::string(error->what()), ::testing::StartsWith("scene.yaml:8:13: "));
}

TEST(ParseErrors, UnknownKeySuggestsTheClosestOne) {
    auto lines = base_lines();
    lines[7] = "    raduis: 1";
    expect_error_at(lines, "did you mean 'radius'", 8, "raduis");
}

TEST(ParseErrors, WrongTypeForANumber) {
    auto lines = base_lines();
    lines[7] = "    radius: [1]";
    expect_error_at(lines, "expected a number", 8, "[1]");
    lines[7] = "    radius: \"1\"";  // a quoted string is text, not a number
    expect_error_at(lines, "expected a number", 8, "\"1\"");
}

TEST(ParseErrors, NanAndInfinityAreRefused) {
    for (const std::string value : {".nan", ".inf", "-.inf", ".NaN"}) {
        auto lines = base_lines();
        lines[7] = "    radius: " + value;
        expect_error_at(lines, "finite", 8, value);
    }
    auto lines = base_lines();
    lines[6] = "    center: [0, 1e999, 0]";  // overflows a double
    expect_error_at(lines, "out of range", 7, "1e999");
}

TEST(ParseErrors, VectorOfWrongLength) {
    auto lines = base_lines();
    lines[6] = "    center: [0, 0]";
    expect_error_at(lines, "expected 3 numbers", 7, "[0, 0]");
    lines[6] = "    center: [0, 0, 0, 0]";
    expect_error_at(lines, "expected 3 numbers", 7, "[0, 0, 0, 0]");
}

TEST(ParseErrors, RadiusMustBePositive) {
    for (const std::string value : {"0", "-1"}) {
        auto lines = base_lines();
        lines[7] = "    radius: " + value;
        expect_error_at(lines, "radius must be > 0", 8, value);
    }
}

TEST(ParseErrors, FovMustBeStrictlyBetween0And180) {
    for (const std::string value : {"0", "180", "-10", "200"}) {
        auto lines = base_lines();
        lines[0] = "camera: {eye: [0, 0, 5], look_at: [0, 0, 0], fov: " + value + "}";
        expect_error_at(lines, "fov must be between 0 and 180", 1, value + "}");
    }
    auto lines = base_lines();
    lines[0] = "camera: {eye: [0, 0, 5], look_at: [0, 0, 0], fov: 179.9}";
    EXPECT_NO_THROW(test::scene_from(join_lines(lines)));
}

TEST(ParseErrors, PlaneNormalMustNotBeZero) {
    auto lines = base_lines();
    lines[5] = "  - {type: plane, point: [0, 0, 0], normal: [0, 0, 0], material: red}";
    lines.resize(6);
    expect_error_at(lines, "normal must not be the zero vector", 6, "[0, 0, 0], m");
}

TEST(ParseErrors, BoxMinMustBeBelowMaxOnEveryAxis) {
    auto lines = base_lines();
    lines[5] = "  - {type: box, min: [0, 0, 0], max: [1, 0, 1], material: red}";  // equal on y
    lines.resize(6);
    expect_error_at(lines, "min must be less than max", 6, "[1, 0, 1]");
    lines[5] = "  - {type: box, min: [0, 0, 0], max: [1, 1, -1], material: red}";  // reversed on z
    expect_error_at(lines, "min must be less than max", 6, "[1, 1, -1]");
}

TEST(ParseErrors, SpecularExponentMustBePositive) {
    for (const std::string value : {"0", "-2"}) {
        auto lines = base_lines();
        lines[3] = "  red: {kd: [1, 0, 0], p: " + value + "}";
        expect_error_at(lines, "exponent must be > 0", 4, value + "}");
    }
}

TEST(ParseErrors, MeshIndexOutOfRange) {
    auto lines = base_lines();
    lines.resize(5);
    lines.push_back("  - type: mesh");
    lines.push_back("    vertices: [[0, 0, 0], [1, 0, 0], [0, 1, 0]]");
    lines.push_back("    triangles: [[0, 1, 2], [0, 2, 3]]");
    lines.push_back("    material: red");
    expect_error_at(lines, "vertex index 3 is out of range (0..2)", 8, "[0, 2, 3]");
    lines[7] = "    triangles: [[0, -1, 2]]";
    expect_error_at(lines, "vertex index -1 is out of range", 8, "[0, -1, 2]");
    lines[7] = "    triangles: [[0, 1]]";
    expect_error_at(lines, "expected 3 vertex indices", 8, "[0, 1]]");
}

TEST(ParseErrors, EyeMustDifferFromLookAt) {
    auto lines = base_lines();
    lines[0] = "camera: {eye: [1, 2, 3], look_at: [1, 2, 3]}";
    expect_error_at(lines, "look_at must differ from eye", 1, "[1, 2, 3]}");
}

TEST(ParseErrors, UpParallelToViewDirection) {
    auto lines = base_lines();
    lines[0] = "camera: {eye: [0, 5, 0], look_at: [0, 0, 0], up: [0, 2, 0]}";
    expect_error_at(lines, "parallel to the view direction", 1, "[0, 2, 0]");
}

TEST(ParseErrors, UnknownMaterialNameSuggestsDefinedOne) {
    auto lines = base_lines();
    lines[8] = "    material: rde";
    expect_error_at(lines, "unknown material 'rde'", 9, "rde");
    const auto error = scene_error(join_lines(lines));
    ASSERT_TRUE(error);
    EXPECT_THAT(error->message(), HasSubstr("did you mean 'red'"));
}

TEST(ParseErrors, MissingMeshFileIsNamed) {
    const test::ScratchDirectory directory;
    auto lines = base_lines();
    lines.resize(5);
    lines.push_back("  - {type: mesh, file: models/missing.obj, material: red}");
    const std::string scene_path = (directory.path() / "scene.yaml").string();
    const auto error = scene_error(join_lines(lines), scene_path);
    ASSERT_TRUE(error);
    EXPECT_THAT(error->message(), HasSubstr("not found"));
    EXPECT_THAT(error->message(), HasSubstr((directory.path() / "models" / "missing.obj").string()));
    EXPECT_EQ(error->where().file, scene_path);
    EXPECT_EQ(error->where().line, 6);
    EXPECT_EQ(error->where().column, column_of(lines[5], "models/missing.obj"));
}

TEST(ParseErrors, OtherFormatVersionIsRefused) {
    auto lines = base_lines();
    lines.insert(lines.begin(), "version: 2");
    expect_error_at(lines, "unsupported scene format version 2", 1, "2");
    lines[0] = "version: 1";
    EXPECT_NO_THROW(test::scene_from(join_lines(lines)));
}

// Groups may nest 64 deep (limits::max_nesting); the 65th group is refused where it starts.
TEST(ParseErrors, GroupNestingLimit) {
    const auto nested = [](int groups) {
        std::string line = "objects: ";
        for (int i = 0; i < groups; ++i) line += "[{type: group, objects: ";
        line += "[{type: sphere, center: [0, 0, 0], radius: 1, material: {kd: 1}}]";
        for (int i = 0; i < groups; ++i) line += "}]";
        return line;
    };
    const std::string camera = "camera: {eye: [0, 0, 5], look_at: [0, 0, 0]}";
    const std::string image = "image: {width: 2, height: 2}";
    EXPECT_NO_THROW(test::scene_from(join_lines({camera, image, nested(limits::max_nesting)})));

    const std::string too_deep = nested(limits::max_nesting + 1);
    const auto error = scene_error(join_lines({camera, image, too_deep}));
    ASSERT_TRUE(error);
    EXPECT_THAT(error->message(), HasSubstr("nested deeper than 64"));
    EXPECT_EQ(error->where().line, 3);
    size_t last_group = 0;
    for (int i = 0; i <= limits::max_nesting; ++i) last_group = too_deep.find("{type: group", last_group + 1);
    EXPECT_EQ(error->where().column, int(last_group) + 1);
}

// Deeply nested YAML values are refused with an InputError (not a stack overflow), at any depth.
TEST(ParseErrors, DeeplyNestedValuesAreRefused) {
    for (const int depth : {600, 100000}) {
        const std::string text =
            "camera: {eye: [0, 0, 5], look_at: [0, 0, 0]}\nimage: {width: 2, height: 2}\n"
            "ambient: " +
            std::string(size_t(depth), '[') + "1" + std::string(size_t(depth), ']') + "\n";
        const auto error = scene_error(text);
        ASSERT_TRUE(error) << depth;
        EXPECT_THAT(error->message(), HasSubstr("nested")) << depth;
        EXPECT_EQ(error->where().line, 3) << depth;
    }
}

// "Billion laughs": nine levels of ten aliases each expand to 10^9 values. The parser shares
// aliased nodes, so the scene must be refused by counting, quickly and without the memory.
TEST(ParseErrors, AliasBombIsRefusedQuickly) {
    std::vector<std::string> lines = {"a: &a [lol, lol, lol, lol, lol, lol, lol, lol, lol, lol]"};
    for (char level = 'b'; level <= 'i'; ++level) {
        const std::string previous(1, char(level - 1));
        std::string line = std::string(1, level) + ": &" + level + " [";
        for (int k = 0; k < 10; ++k) line += (k ? ", *" : "*") + previous;
        lines.push_back(line + "]");
    }
    const auto start = std::chrono::steady_clock::now();
    const auto error = scene_error(join_lines(lines));
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ASSERT_TRUE(error);
    EXPECT_THAT(error->message(), HasSubstr("aliases"));
    EXPECT_LT(seconds, 10.0);
    RecordProperty("seconds", std::to_string(seconds));
}

TEST(ParseErrors, ManyAndHugeNamesGetABoundedMessage) {
    // 100,000 materials (defined-twice checks by one look each, not a walk of the list), and an
    // unknown name of 100,000 bytes with control characters: the message lists 20 names,
    // printable, suggests nothing, and says how many there are.
    std::string text = "camera: {eye: [0, 0, 5], look_at: [0, 0, 0]}\nimage: {width: 2, height: 2}\nmaterials:\n";
    for (int i = 0; i < 100000; ++i) text += "  m" + std::to_string(i) + ": {kd: 1}\n";
    const std::string huge = "\\e[2J" + std::string(100000, 'x');
    text += "objects:\n  - {type: sphere, center: [0, 0, 0], radius: 1, material: \"" + huge + "\"}\n";
    const auto error = test::input_error_from([&] { (void)load_scene_text(text, "many.yaml"); });
    ASSERT_TRUE(error);
    const std::string message = error->message();
    EXPECT_LT(message.size(), 2000u) << message.substr(0, 300);
    EXPECT_THAT(message, ::testing::HasSubstr("(100000 in all)"));
    EXPECT_THAT(message, ::testing::Not(::testing::HasSubstr("did you mean")));
    EXPECT_EQ(message.find('\x1b'), std::string::npos);
    // A name defined twice among them is still found, at its place.
    const std::string twice =
        "camera: {eye: [0, 0, 5], look_at: [0, 0, 0]}\nimage: {width: 2, height: 2}\n"
        "materials:\n  a: {kd: 1}\n  b: {kd: 1}\n  a: {kd: 0.5}\n";
    const auto duplicate = test::input_error_from([&] { (void)parse_scene_text(twice, "twice.yaml"); });
    ASSERT_TRUE(duplicate);
    EXPECT_EQ(duplicate->where().line, 6);
}

/// This thread's CPU time in seconds: unlike the wall clock, it does not grow when other
/// processes share the cores (ctest -j, a loaded machine), only with the work done here.
double thread_seconds() {
    timespec now{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
    return double(now.tv_sec) + 1e-9 * double(now.tv_nsec);
}

/// The shortest of three loads of `text`, in seconds of this thread's CPU time.
double seconds_to_load(const std::string& text) {
    double best = 1e30;
    for (int run = 0; run < 3; ++run) {
        const double start = thread_seconds();
        (void)load_scene_text(text, "many.yaml");
        best = std::min(best, thread_seconds() - start);
    }
    return best;
}

/// `n` prototypes of one triangle each, each placed by one instance without a material.
std::string prototypes_scene(int n) {
    std::string text = "camera: {eye: [0, 0, 5], look_at: [0, 0, 0]}\nimage: {width: 2, height: 2}\nprototypes:\n";
    for (int i = 0; i < n; ++i)
        text += "  p" + std::to_string(i) + ": {type: triangle, vertices: [[0, 0, 0], [1, 0, 0], [0, 1, 0]]}\n";
    text += "objects:\n";
    for (int i = 0; i < n; ++i)
        text += "  - {type: instance, prototype: p" + std::to_string(i) +
                ", material: {kd: 1}, transform: [{translate: [" + std::to_string(i % 100) + ", 0, 0]}]}\n";
    return text;
}

// Reading grows with the number of definitions, not with its square: four times the prototypes
// (each with an instance) take less than eight times as long. A pass over every instance per
// prototype made it sixteen (80,000 took 29 s). A ratio measured in one run, so it holds on a slow
// machine as on a fast one.
TEST(ParseScale, PrototypesAndInstancesReadInLinearTime) {
    const double small = seconds_to_load(prototypes_scene(10000));
    const double large = seconds_to_load(prototypes_scene(40000));
    EXPECT_LT(large, 8 * small) << "10,000 prototypes: " << small << " s; 40,000: " << large << " s";
}

}  // namespace
}  // namespace whitted
