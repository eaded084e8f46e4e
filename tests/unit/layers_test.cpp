// SPDX-License-Identifier: MIT
// Render layers and `explain` (docs/layers.md) inside the library: watching the trace changes
// no radiance; the layers split it completely; the beauty with layers is their float sum; the
// layers are the same for any thread count; explain_pixel gives every pixel of the render
// without layers, bit for bit. Read back from the EXR by other programs: tests/layers.

#include "render/layers.h"
#include "render/accelerator.h"
#include "render/camera.h"
#include "render/explain.h"
#include "render/renderer.h"
#include "scene/scene.h"

#include "test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <stdexcept>

namespace whitted {
namespace {

// Every shape kind, mirrors (max depth 4), a shadowing box, a point and a directional light;
// 41×23, so the last 4×4 packets and tiles are partly filled.
std::string scene_text(int samples) {
    return test::join_lines({
        "camera: {eye: [0.3, 1.5, 6], look_at: [0, 0.2, 0], fov: 55}",
        "image: {width: 41, height: 23, background: [0.1, 0.2, 0.3], samples: " + std::to_string(samples) + "}",
        "render: {max_depth: 4}",
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
        "  - {type: group, objects: [",
        "     {type: triangle, vertices: [[-2, -1, -2], [2, -1, -2], [0, 2, -2.5]], material: matte}]}",
        "  - {type: mesh, material: {kd: 0.3, km: 0.2}, vertices: [[-2, 1.5, -1], [-1, 2.5, -1.5], [0, 1.5, -1],",
        "     [-1, 1, -0.5]], triangles: [[0, 1, 2], [0, 2, 3]]}",
        "  - {type: plane, point: [0, -1, 0], normal: [0, 1, 0], material: floor}",
    });
}

TEST(Layers, ObjectsAreNumberedInFileOrderThroughGroups) {
    const Scene scene = test::scene_from(scene_text(1));
    ASSERT_EQ(scene.objects.size(), 5u);
    EXPECT_EQ(scene.objects[0].type, ObjectType::sphere);
    EXPECT_EQ(scene.objects[2].type, ObjectType::triangle);  // the group's member, not the group
    EXPECT_EQ(scene.objects[4].type, ObjectType::plane);
    EXPECT_EQ(scene.spheres[0].object, 1u);
    EXPECT_EQ(scene.boxes[0].object, 2u);
    EXPECT_EQ(scene.meshes[0].object, 3u);
    EXPECT_EQ(scene.meshes[1].object, 4u);
    EXPECT_EQ(scene.planes[0].object, 5u);
    // Named materials first, in file order; the inline one after them.
    ASSERT_EQ(scene.material_names.size(), 4u);
    EXPECT_EQ(scene.material_names[0], "shiny");
    EXPECT_EQ(scene.material_names[2], "floor");
    EXPECT_EQ(scene.material_names[3], "");
    EXPECT_EQ(scene.meshes[1].material, 3u);
}

TEST(Layers, ParseLayerLists) {
    EXPECT_EQ(parse_layers({"all"}).bits, LayerSet::all().bits);
    EXPECT_TRUE(parse_layers({"none"}).empty());
    const LayerSet some = parse_layers({"diffuse, N", "objectId"});
    EXPECT_TRUE(some.has(Layer::diffuse) && some.has(Layer::N) && some.has(Layer::objectId));
    EXPECT_FALSE(some.has(Layer::specular));
    try {
        parse_layers({"diffuse,speculr"});
        FAIL() << "an unknown layer was accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("unknown render layer 'speculr'"), std::string::npos) << e.what();
    }
}

class LayersPerSamples : public testing::TestWithParam<int> {};

// Every camera ray of the image, traced with and without a LayerRecorder in the same packets:
// the radiance is the same bit for bit, and the layers add up to it (in double, to rounding).
TEST_P(LayersPerSamples, WatchingChangesNothingAndTheLayersAddUp) {
    const Scene scene = test::scene_from(scene_text(GetParam()));
    const Accelerator accelerator(scene, 1);
    const LectureShading shading(scene, accelerator);
    LayerRecorder recorder(scene, Accelerator::packet_size);
    int checked = 0, mirrored = 0;
    for (int j = 0; j < scene.height; ++j)
        for (int i = 0; i < scene.width; ++i)
            for (const CameraPacket& packet : camera_packets(scene, i, j)) {
                const int count = int(packet.rays.size());
                Color plain[Accelerator::packet_size], watched[Accelerator::packet_size];
                RayCounts counts;
                shading.trace_packet(packet.rays.data(), count, 0, plain, counts);
                recorder.reset();
                shading.trace_packet(packet.rays.data(), count, 0, watched, counts, recorder);
                for (int k = 0; k < count; ++k) {
                    ASSERT_EQ(std::memcmp(&plain[k], &watched[k], sizeof(Color)), 0) << i << "," << j;
                    const PathLayers& l = recorder.lane(k);
                    const Color sum = l.ambient + l.diffuse + l.specular + l.mirror + l.transmission + l.background;
                    for (int c = 0; c < 3; ++c)
                        EXPECT_NEAR(sum[c], plain[k][c], 1e-12 * std::max(1.0, plain[k][c])) << i << "," << j;
                    Color lights(0.0);
                    for (const Color& light : l.lights) lights += light;
                    for (int c = 0; c < 3; ++c) EXPECT_NEAR(lights[c], l.diffuse[c] + l.specular[c], 1e-12);
                    mirrored += l.hits > 1 && l.mirror[0] > 0;
                    ++checked;
                }
            }
    EXPECT_GT(checked, 41 * 23);
    EXPECT_GT(mirrored, 50);  // the mirror layer is exercised
}

// With layers, R, G, B is the float sum of the colour layers in a fixed order, for any thread
// count, and within a float rounding of the render without layers.
TEST_P(LayersPerSamples, BeautyIsTheFloatSumOfTheLayersForAnyThreadCount) {
    const Scene scene = test::scene_from(scene_text(GetParam()));
    const Accelerator accelerator(scene, 2);
    RenderJob options;
    options.threads = 1;
    options.layers = LayerSet::all();
    const RenderedTiles one = render(scene, accelerator, options);
    ASSERT_EQ(one.image.layers.size(), 6u + 2u + 8u);  // ambient..background, light1..2, N..hits
    options.threads = 3;
    const RenderedTiles three = render(scene, accelerator, options);
    options.layers = LayerSet();
    const RenderedTiles plain = render(scene, accelerator, options);
    ASSERT_TRUE(plain.image.layers.empty());
    const size_t pixels = size_t(scene.width) * scene.height;
    for (size_t l = 0; l < one.image.layers.size(); ++l)
        EXPECT_EQ(std::memcmp(one.image.layers[l].values.data(), three.image.layers[l].values.data(),
                              one.image.layers[l].values.size() * sizeof(float)),
                  0)
            << one.image.layers[l].name;
    int differ = 0;
    for (size_t p = 0; p < pixels; ++p)
        for (int c = 0; c < 3; ++c) {
            float sum = 0.0f;
            for (int l = 0; l < 6; ++l) sum += one.image.layers[l].values[3 * p + c];
            ASSERT_EQ(sum, one.image.rgb[3 * p + c]) << "pixel " << p;
            const float without = plain.image.rgb[3 * p + c];
            EXPECT_LE(std::fabs(sum - without), 4e-7f * std::max(1.0f, without));
            differ += sum != without;
        }
    RecordProperty("channels_differing_from_the_render_without_layers", differ);
}

// explain_pixel traces what render() traced: its float pixel is the render's, for every pixel.
TEST_P(LayersPerSamples, ExplainGivesEveryPixelOfTheRender) {
    const Scene scene = test::scene_from(scene_text(GetParam()));
    const Accelerator accelerator(scene, 2);
    RenderJob options;
    options.threads = 2;
    const RenderedTiles plain = render(scene, accelerator, options);
    options.layers = LayerSet::all();
    const RenderedTiles layered = render(scene, accelerator, options);
    for (int j = 0; j < scene.height; ++j)
        for (int i = 0; i < scene.width; ++i) {
            const PixelExplanation e = explain_pixel(scene, accelerator, i, j);
            ASSERT_EQ(int(e.samples.size()), scene.samples * scene.samples);
            for (int c = 0; c < 3; ++c) {
                ASSERT_EQ(e.rgb[c], plain.image.pixel(i, j)[c]) << i << "," << j;
                ASSERT_EQ(e.layer_beauty[c], layered.image.pixel(i, j)[c]) << i << "," << j;
            }
        }
}

INSTANTIATE_TEST_SUITE_P(Samples, LayersPerSamples, testing::Values(1, 3));

// A glass ball: what its refracted rays bring back is the transmission layer, what its mirror
// rays bring back the mirror layer, and the colour layers still add up to the beauty.
TEST(Layers, RefractedRaysFillTheTransmissionLayer) {
    const Scene scene = test::scene_from(
        "camera: {eye: [0, 1, 5], look_at: [0, 0.5, 0], fov: 40}\n"
        "image: {width: 24, height: 18}\n"
        "lights: [{type: point, position: [2, 5, 4]}]\n"
        "objects:\n"
        "  - {type: plane, point: [0, 0, 0], normal: [0, 1, 0], material: {ka: 0.1, kd: 0.8}}\n"
        "  - {type: sphere, center: [0, 0.6, 0], radius: 0.6, material: {ks: 0.3, p: 20, km: 0.1, kt: 0.8, ior: "
        "1.5}}\n");
    const Accelerator accelerator(scene, 2);
    RenderJob options;
    options.layers = LayerSet::all();
    const RenderedTiles result = render(scene, accelerator, options);
    ASSERT_EQ(result.image.layers[4].name, "transmission");
    const size_t pixels = size_t(scene.width) * scene.height;
    double transmitted = 0, mirrored = 0;
    for (size_t p = 0; p < pixels; ++p)
        for (int c = 0; c < 3; ++c) {
            float sum = 0.0f;
            for (int l = 0; l < 6; ++l) sum += result.image.layers[size_t(l)].values[3 * p + c];
            ASSERT_EQ(sum, result.image.rgb[3 * p + c]) << "pixel " << p;
            transmitted += double(result.image.layers[4].values[3 * p + c]);
            mirrored += double(result.image.layers[3].values[3 * p + c]);
        }
    EXPECT_GT(transmitted, 2 * mirrored);  // kt 0.8 against km 0.1
    EXPECT_GT(mirrored, 0);
}

}  // namespace
}  // namespace whitted
