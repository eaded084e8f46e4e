// SPDX-License-Identifier: MIT
// load_scene_file/_text, the one-pass reader `whitted render` uses, against the two-pass
// validate_scene(parse_scene_*) that `convert`, `check` and `explain` use: the same Scene for
// every scene in the repository, the same mistake reported for bad ones, wherever in the file
// the named materials are.

#include "test_support.h"

#include <gmock/gmock.h>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace whitted {
namespace {

using test::join_lines;

void expect_same_transform(const SharedTransform& a, const SharedTransform& b, const std::string& what) {
    EXPECT_EQ(bool(a), bool(b)) << what;
    if (a && b) {
        EXPECT_EQ(a->rows(), b->rows()) << what;
    }
}

void expect_same_color(const Color& a, const Color& b, const std::string& what) {
    EXPECT_EQ(a.x, b.x) << what;
    EXPECT_EQ(a.y, b.y) << what;
    EXPECT_EQ(a.z, b.z) << what;
}

/// Field by field: what the renderer reads must be identical, bit for bit (and the objects'
/// places in the file too, for scenes read from the same text).
void expect_same_scene(const Scene& a, const Scene& b, bool same_text = true) {
    EXPECT_EQ(a.width, b.width);
    EXPECT_EQ(a.height, b.height);
    EXPECT_EQ(a.samples, b.samples);
    EXPECT_EQ(a.max_depth, b.max_depth);
    EXPECT_EQ(a.lights.size(), b.lights.size());
    ASSERT_EQ(a.materials.size(), b.materials.size());
    EXPECT_EQ(a.material_names, b.material_names);
    for (size_t i = 0; i < a.materials.size(); ++i) {
        const std::string what = "material " + std::to_string(i);
        expect_same_color(a.materials[i].ka, b.materials[i].ka, what);
        expect_same_color(a.materials[i].kd, b.materials[i].kd, what);
        expect_same_color(a.materials[i].ks, b.materials[i].ks, what);
        expect_same_color(a.materials[i].km, b.materials[i].km, what);
        EXPECT_EQ(a.materials[i].p, b.materials[i].p) << what;
        EXPECT_EQ(a.materials[i].fresnel_r0, b.materials[i].fresnel_r0) << what;
    }
    ASSERT_EQ(a.objects.size(), b.objects.size());
    for (size_t i = 0; i < a.objects.size(); ++i) {
        EXPECT_EQ(a.objects[i].type, b.objects[i].type);
        if (same_text) {
            EXPECT_EQ(a.objects[i].where.str(), b.objects[i].where.str());
        }
    }
    ASSERT_EQ(a.spheres.size(), b.spheres.size());
    for (size_t i = 0; i < a.spheres.size(); ++i) {
        const std::string what = "sphere " + std::to_string(i);
        expect_same_transform(a.spheres[i].object_to_world, b.spheres[i].object_to_world, what);
        expect_same_color(a.spheres[i].center, b.spheres[i].center, what);
        EXPECT_EQ(a.spheres[i].radius, b.spheres[i].radius) << what;
        EXPECT_EQ(a.spheres[i].material, b.spheres[i].material) << what;
        EXPECT_EQ(a.spheres[i].object, b.spheres[i].object) << what;
    }
    ASSERT_EQ(a.boxes.size(), b.boxes.size());
    for (size_t i = 0; i < a.boxes.size(); ++i) {
        const std::string what = "box " + std::to_string(i);
        expect_same_transform(a.boxes[i].object_to_world, b.boxes[i].object_to_world, what);
        expect_same_color(a.boxes[i].min, b.boxes[i].min, what);
        expect_same_color(a.boxes[i].max, b.boxes[i].max, what);
        EXPECT_EQ(a.boxes[i].material, b.boxes[i].material) << what;
    }
    ASSERT_EQ(a.planes.size(), b.planes.size());
    for (size_t i = 0; i < a.planes.size(); ++i) EXPECT_EQ(a.planes[i].material, b.planes[i].material);
    ASSERT_EQ(a.meshes.size(), b.meshes.size());
    for (size_t i = 0; i < a.meshes.size(); ++i) {
        const std::string what = "mesh " + std::to_string(i);
        EXPECT_EQ(a.meshes[i].positions, b.meshes[i].positions) << what;
        EXPECT_EQ(a.meshes[i].indices, b.meshes[i].indices) << what;
        EXPECT_EQ(a.meshes[i].normals, b.meshes[i].normals) << what;
        EXPECT_EQ(a.meshes[i].material, b.meshes[i].material) << what;
        EXPECT_EQ(a.meshes[i].triangle_materials, b.meshes[i].triangle_materials) << what;
        EXPECT_EQ(a.meshes[i].object, b.meshes[i].object) << what;
    }
    EXPECT_EQ(a.mesh_files, b.mesh_files);
}

TEST(LoadScene, GivesTheSceneValidateSceneGivesForEveryRepositoryScene) {
    int compared = 0, refused = 0;
    for (const char* dir : {"examples", "tests", "bench"}) {
        const std::filesystem::path root = std::filesystem::path(WHITTED_SOURCE_DIR) / dir;
        ASSERT_TRUE(std::filesystem::exists(root)) << root;
        for (const auto& entry : std::filesystem::recursive_directory_iterator(root)) {
            const std::string ext = entry.path().extension().string();
            if (!entry.is_regular_file() || (ext != ".yaml" && ext != ".json")) continue;
            const std::string path = entry.path().string();
            std::optional<Scene> two_pass;
            std::string two_pass_error;
            try {
                two_pass = validate_scene(parse_scene_file(path));
            } catch (const InputError& e) {
                two_pass_error = e.what();
            }
            SCOPED_TRACE(path);
            if (!two_pass) {
                // A bad scene (tests/bad_input): the same message from the one-pass reader.
                ++refused;
                try {
                    (void)load_scene_file(path);
                    ADD_FAILURE() << "load_scene_file accepted what validate_scene refused: " << two_pass_error;
                } catch (const InputError& e) {
                    EXPECT_EQ(std::string(e.what()), two_pass_error);
                }
                continue;
            }
            ++compared;
            expect_same_scene(load_scene_file(path), *two_pass);
        }
    }
    RecordProperty("compared", compared);
    RecordProperty("refused", refused);
    EXPECT_GT(compared, 50);
    EXPECT_GT(refused, 20);
}

const std::vector<std::string> header = {
    "camera: { eye: [0, 0, 5], look_at: [0, 0, 0] }",
    "image: { width: 8, height: 6 }",
};

std::string scene_text(const std::vector<std::string>& body) {
    std::vector<std::string> lines = header;
    lines.insert(lines.end(), body.begin(), body.end());
    return join_lines(lines);
}

TEST(LoadScene, NamedMaterialsMayComeAfterTheObjects) {
    const std::vector<std::string> objects = {
        "objects:",
        "  - { type: sphere, center: [0, 0, 0], radius: 1, material: { kd: 0.25 } }",
        "  - { type: sphere, center: [2, 0, 0], radius: 1, material: red }",
        "  - { type: plane, point: [0, -1, 0], normal: [0, 1, 0], material: grey }",
    };
    const std::vector<std::string> materials = {
        "materials:",
        "  grey: { kd: 0.5 }",
        "  red: { kd: [0.9, 0.1, 0.1] }",
    };
    std::vector<std::string> after = objects, before = materials;
    after.insert(after.end(), materials.begin(), materials.end());
    before.insert(before.end(), objects.begin(), objects.end());
    const Scene scene = load_scene_text(scene_text(after), "after.yaml");
    // Named ones first in file order, then the inline one: Scene::materials' order.
    ASSERT_EQ(scene.materials.size(), 3u);
    EXPECT_EQ(scene.material_names, (std::vector<std::string>{"grey", "red", ""}));
    EXPECT_EQ(scene.spheres[0].material, 2u);
    EXPECT_EQ(scene.materials[2].kd.x, 0.25);
    EXPECT_EQ(scene.spheres[1].material, 1u);
    EXPECT_EQ(scene.materials[1].kd.y, 0.1);
    EXPECT_EQ(scene.planes[0].material, 0u);
    expect_same_scene(scene, validate_scene(parse_scene_text(scene_text(after), "after.yaml")));
    expect_same_scene(scene, load_scene_text(scene_text(before), "before.yaml"), false);
}

TEST(LoadScene, ReportsTheFirstMistakeInFileOrderWhereverTheMaterialsAre) {
    const std::string unknown_then_radius = scene_text({
        "objects:",
        "  - { type: sphere, center: [0, 0, 0], radius: 1, material: chrome }",
        "  - { type: sphere, center: [0, 0, 0], radius: -1, material: grey }",
        "materials:",
        "  grey: { kd: 0.5 }",
    });
    auto e = test::scene_error(unknown_then_radius);
    ASSERT_TRUE(e);
    EXPECT_THAT(e->what(), ::testing::HasSubstr("scene.yaml:4:"));
    EXPECT_THAT(e->what(), ::testing::HasSubstr("unknown material 'chrome'"));

    const std::string radius_then_unknown = scene_text({
        "objects:",
        "  - { type: sphere, center: [0, 0, 0], radius: -1, material: grey }",
        "  - { type: sphere, center: [0, 0, 0], radius: 1, material: chrome }",
        "materials:",
        "  grey: { kd: 0.5 }",
    });
    e = test::scene_error(radius_then_unknown);
    ASSERT_TRUE(e);
    EXPECT_THAT(e->what(), ::testing::HasSubstr("scene.yaml:4:"));
    EXPECT_THAT(e->what(), ::testing::HasSubstr("sphere.radius must be > 0"));

    // A bad named material is reported before any object's mistake, as validation always did.
    const std::string object_then_material = scene_text({
        "objects:",
        "  - { type: sphere, center: [0, 0, 0], radius: -1, material: grey }",
        "materials:",
        "  grey: { kd: 0.5, p: 0 }",
    });
    e = test::scene_error(object_then_material);
    ASSERT_TRUE(e);
    EXPECT_THAT(e->what(), ::testing::HasSubstr("scene.yaml:6:"));
    EXPECT_THAT(e->what(), ::testing::HasSubstr("materials.grey.p"));

    // The image is checked before any object.
    const std::string image_and_object = join_lines({
        "camera: { eye: [0, 0, 5], look_at: [0, 0, 0] }",
        "image: { width: 0, height: 6 }",
        "objects:",
        "  - { type: sphere, center: [0, 0, 0], radius: -1, material: { kd: 1 } }",
    });
    e = test::scene_error(image_and_object);
    ASSERT_TRUE(e);
    EXPECT_THAT(e->what(), ::testing::HasSubstr("image.width must be at least 1"));
}

TEST(LoadScene, HandsEachObjectOnceWhenTheFileIsReadAgainByLibyaml) {
    // The anchor sends the file to libyaml (yaml_tree.h) after the fast scanner has handed over
    // two objects: the reader hands each object to its sink once, in order, and the one-pass
    // reader keeps each once.
    const std::string text = scene_text({
        "materials:",
        "  grey: { kd: 0.5 }",
        "objects:",
        "  - { type: sphere, center: [0, 0, 0], radius: 1, material: grey }",
        "  - { type: sphere, center: [2, 0, 0], radius: 1, material: grey }",
        "  - { type: sphere, center: &c [4, 0, 0], radius: 1, material: grey }",
        "  - { type: sphere, center: *c, radius: 2, material: grey }",
    });
    std::vector<size_t> indices;
    std::vector<double> radii;
    const ObjectSink sink = [&](ObjectDescription&& object, size_t index) {
        indices.push_back(index);
        radii.push_back(std::get<SphereShape>(object.shape).radius.value);
    };
    (void)parse_scene_text(text, "anchors.yaml", &sink);
    EXPECT_THAT(indices, testing::ElementsAre(0u, 1u, 2u, 3u));
    EXPECT_THAT(radii, testing::ElementsAre(1.0, 1.0, 1.0, 2.0));
    const Scene scene = load_scene_text(text, "anchors.yaml");
    EXPECT_EQ(scene.spheres.size(), 4u);
    EXPECT_EQ(scene.objects.size(), 4u);
    EXPECT_EQ(scene.spheres[3].center.x, 4.0);
    expect_same_scene(scene, validate_scene(parse_scene_text(text, "anchors.yaml")));
}

TEST(LoadScene, SettingsComeBackWithoutTheObjects) {
    SceneDescription settings;
    const Scene scene =
        load_scene_text(scene_text({"render: { layers: [diffuse] }", "materials:", "  grey: { kd: 0.5 }",
                                    "objects:", "  - { type: sphere, center: [0, 0, 0], radius: 1, material: grey }"}),
                        "s.yaml", &settings);
    EXPECT_EQ(scene.spheres.size(), 1u);
    EXPECT_TRUE(settings.objects.empty());
    ASSERT_EQ(settings.layers.size(), 1u);
    EXPECT_EQ(settings.layers[0].value, "diffuse");
    EXPECT_EQ(settings.image.width.value, 8);
}

TEST(LoadScene, AnUntransformedSphereCarriesNoTransform) {
    // What keeps a million spheres small: no transform object unless one is given.
    const Scene scene = load_scene_text(
        scene_text(
            {"objects:", "  - { type: sphere, center: [0, 0, 0], radius: 1, material: { kd: 1 } }",
             "  - { type: sphere, center: [0, 0, 0], radius: 1, material: { kd: 1 }, transform: { translate: "
             "[0, 0, 0] } }",
             "  - { type: sphere, center: [0, 0, 0], radius: 1, material: { kd: 1 }, transform: { scale: 2 } }"}),
        "t.yaml");
    ASSERT_EQ(scene.spheres.size(), 3u);
    EXPECT_FALSE(scene.spheres[0].object_to_world);
    EXPECT_FALSE(scene.spheres[1].object_to_world);  // the identity, written out
    ASSERT_TRUE(scene.spheres[2].object_to_world);
    EXPECT_EQ(scene.spheres[2].object_to_world->rows()[0], 2.0);
    EXPECT_LE(sizeof(Sphere), 64u);
}

// render.intersection: exact by default, povray when asked, anything else refused where written.
TEST(LoadScene, IntersectionRulesAreExactUnlessPovrayIsAsked) {
    const std::string sphere = "objects: [{ type: sphere, center: [0, 0, 0], radius: 1, material: { kd: 0.5 } }]";
    EXPECT_EQ(test::scene_from(scene_text({sphere})).intersection, Intersection::exact);
    EXPECT_EQ(test::scene_from(scene_text({"render: { intersection: exact }", sphere})).intersection,
              Intersection::exact);
    EXPECT_EQ(load_scene_text(scene_text({"render: { intersection: povray }", sphere}), "s.yaml").intersection,
              Intersection::povray);
    const auto error = test::scene_error(scene_text({"render: { intersection: POVRay }", sphere}));
    ASSERT_TRUE(error);
    EXPECT_EQ(error->where().line, 3);
    EXPECT_EQ(error->where().column, 25);
    EXPECT_THAT(error->what(), ::testing::HasSubstr("exact"));
    EXPECT_THAT(error->what(), ::testing::HasSubstr("povray"));
}

// A mesh is stored about the centre of its bounds once that lies further out than its half
// extent (mesh_origin): moved anywhere, by any amount, it keeps the very float offsets it has
// about its centre, and a mesh around the origin keeps its world coordinates as floats.
TEST(LoadScene, AMeshKeepsItsFloatsWhereverItIsMoved) {
    const auto mesh_at = [&](const Vec3& shift) {
        char line[400];
        std::snprintf(line, sizeof line,
                      "objects: [{ type: group, transform: [{ translate: [%.17g, %.17g, %.17g] }], objects: [{ type: "
                      "mesh, material: { kd: 0.5 }, triangles: [[0, 1, 2]], vertices: [[2.3, 1.1, 0.7], [3.9, 1.6, "
                      "0.2], [2.9, 2.7, 1.3]] }] }]",
                      shift.x, shift.y, shift.z);
        return test::scene_from(scene_text({line})).meshes.at(0);
    };
    const TriangleMesh here = mesh_at({0, 0, 0});
    EXPECT_EQ(here.origin, Vec3(2.3 + 3.9, 1.1 + 2.7, 0.2 + 1.3) * 0.5);  // the centre of its bounds
    for (const double t : {170.0, 3.7e4, 1.1e6, -2.9e5}) {
        const TriangleMesh moved = mesh_at(Vec3{1, -0.61, 0.37} * t);
        EXPECT_EQ(moved.positions, here.positions) << t;
        EXPECT_NEAR(moved.origin.x, here.origin.x + t, 1e-9 * std::fabs(t)) << t;
    }
    const TriangleMesh around =
        test::scene_from(scene_text({"objects: [{ type: mesh, material: { kd: 0.5 }, triangles: [[0, 1, 2]], vertices: "
                                     "[[-1.3, 0.1, 0.2], [0.9, "
                                     "-0.6, 0.2], [0.3, 1.7, -0.4]] }]"}))
            .meshes.at(0);
    EXPECT_EQ(around.origin, Vec3(0.0));
    EXPECT_EQ(around.positions[0], float(-1.3));
}

}  // namespace

TEST(SceneFormat, TheExtensionFirstThenTheFirstLine) {
    EXPECT_EQ(scene_format("a.xml", "version: 1"), SceneFormat::course_xml);
    EXPECT_EQ(scene_format("a.NFF", "version: 1"), SceneFormat::nff);
    // A YAML or JSON name is YAML whatever the text, as a file of that name is read.
    EXPECT_EQ(scene_format("scene.yaml", "# a comment\nv\nfrom 0 0 1\n"), SceneFormat::yaml);
    EXPECT_EQ(scene_format("scene.JSON", "<scene/>"), SceneFormat::yaml);
    EXPECT_EQ(scene_format("scene.yml", "v\n"), SceneFormat::yaml);
    EXPECT_EQ(scene_format("<stdin>", "# a comment\n#another\nv\nfrom 0 0 1\n"), SceneFormat::nff);
    for (const char* keyword : {"v", "b", "l", "f", "c", "s", "p", "pp"})
        EXPECT_EQ(scene_format("<stdin>", std::string(keyword) + " 1 2 3\n"), SceneFormat::nff) << keyword;
    EXPECT_EQ(scene_format("<stdin>", "\n  <scene>\n"), SceneFormat::course_xml);
    EXPECT_EQ(scene_format("<stdin>", "# comment\nversion: 1\n"), SceneFormat::yaml);
    EXPECT_EQ(scene_format("<stdin>", "{\"version\": 1}"), SceneFormat::yaml);
    EXPECT_EQ(scene_format("<stdin>", "view: 1\n"), SceneFormat::yaml);  // a word, not an NFF keyword
    EXPECT_EQ(scene_format("<stdin>", "# only a comment"), SceneFormat::yaml);
    EXPECT_EQ(scene_format("<stdin>", ""), SceneFormat::yaml);
}

TEST(SettingOverrides, ReplaceTheFilesValuesBeforeTheyAreChecked) {
    const std::string text = test::join_lines({
        "camera: {eye: [0, 0, 5], look_at: [0, 0, 0]}",
        "image: {width: 97, height: 61, samples: 3}",
        "render: {max_depth: 7}",
        "objects: [{type: sphere, center: [0, 0, 0], radius: 1, material: {kd: 0.5}}]",
    });
    SettingOverrides overrides;
    overrides.width = 50;  // alone: height = round(50 · 61 / 97) = round(31.44) = 31
    overrides.max_depth = 2;
    overrides.intersection = Intersection::povray;
    Scene scene = load_scene_text(text, "scene.yaml", nullptr, overrides);
    EXPECT_EQ(scene.width, 50);
    EXPECT_EQ(scene.height, 31);
    EXPECT_EQ(scene.samples, 3);  // not overridden
    EXPECT_EQ(scene.max_depth, 2);
    EXPECT_EQ(scene.intersection, Intersection::povray);
    // The camera follows the new aspect ratio, as for a file that says 50 × 31.
    const Scene written = load_scene_text(
        test::join_lines({"camera: {eye: [0, 0, 5], look_at: [0, 0, 0]}", "image: {width: 50, height: 31}",
                          "objects: [{type: sphere, center: [0, 0, 0], radius: 1, material: {kd: 0.5}}]"}),
        "scene.yaml");
    EXPECT_EQ(scene.camera.up.y, written.camera.up.y);
    EXPECT_EQ(scene.camera.right.x, written.camera.right.x);

    SettingOverrides tall;
    tall.height = 20;  // alone: width = round(20 · 97 / 61) = round(31.80) = 32
    scene = load_scene_text(text, "scene.yaml", nullptr, tall);
    EXPECT_EQ(scene.width, 32);
    EXPECT_EQ(scene.height, 20);

    // The file's limits hold, and the message names the override.
    SettingOverrides huge;
    huge.width = 65536;  // height round(65536 · 61 / 97) = 41213: past 2^28 pixels
    huge.where = "--width";
    const auto error = test::input_error_from([&] { load_scene_text(text, "scene.yaml", nullptr, huge); });
    ASSERT_TRUE(error);
    EXPECT_EQ(error->where().file.str(), "--width");
    EXPECT_NE(std::string(error->what()).find("65536x41213"), std::string::npos) << error->what();
    SettingOverrides deep;
    deep.max_depth = 300;
    EXPECT_TRUE(test::input_error_from([&] { load_scene_text(text, "scene.yaml", nullptr, deep); }));
}

}  // namespace whitted
