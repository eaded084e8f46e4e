// SPDX-License-Identifier: MIT
// `whitted convert X Y.yaml`: what it writes reads back as the same scene. Names may hold any
// character a scene (or a course XML file) allows, and some of them a YAML reader takes for line
// breaks (U+0085, U+2028, U+2029) or refuses unescaped (controls, U+FEFF, U+FFFE).

#include "converters/yaml_writer.h"
#include "scene/description.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

namespace whitted {
namespace {

/// The UTF-8 bytes of one code point.
std::string utf8(uint32_t code) {
    std::string out;
    if (code < 0x80) {
        out += char(code);
    } else if (code < 0x800) {
        out += char(0xC0 | (code >> 6));
        out += char(0x80 | (code & 0x3F));
    } else if (code < 0x10000) {
        out += char(0xE0 | (code >> 12));
        out += char(0x80 | ((code >> 6) & 0x3F));
        out += char(0x80 | (code & 0x3F));
    } else {
        out += char(0xF0 | (code >> 18));
        out += char(0x80 | ((code >> 12) & 0x3F));
        out += char(0x80 | ((code >> 6) & 0x3F));
        out += char(0x80 | (code & 0x3F));
    }
    return out;
}

TEST(YamlWriter, EveryNameReadsBackAsWritten) {
    std::vector<uint32_t> codes = {'"', '\\', '#', ':', ' ', 0x7F, 0xE9, 0x2028, 0x2029, 0xFEFF, 0xFFFE, 0x1F600};
    for (uint32_t c = 1; c < 0x20; ++c) codes.push_back(c);
    for (uint32_t c = 0x80; c <= 0x9F; ++c) codes.push_back(c);
    for (const uint32_t code : codes) {
        const std::string name = "a" + utf8(code) + "b";
        // The scene as a description (as a course XML file or the API would give it), written out
        // and read back.
        SceneDescription scene = parse_scene_text(
            "camera: {eye: [0, 0, 5], look_at: [0, 0, 0]}\nimage: {width: 4, height: 4}\n"
            "materials:\n  placeholder: {kd: 1}\n"
            "objects:\n  - {type: sphere, center: [0, 0, 0], radius: 1, material: placeholder}\n",
            "scene.yaml");
        scene.materials[0].name = name;
        scene.objects[0].material->name = name;
        const std::string text = yaml::scene_to_yaml(scene, "out.yaml");
        try {
            const SceneDescription back = parse_scene_text(text, "out.yaml");
            ASSERT_EQ(back.materials.size(), 1u) << "U+" << std::hex << code;
            EXPECT_EQ(back.materials[0].name, name) << "U+" << std::hex << code;
            EXPECT_EQ(back.objects[0].material->name, name) << "U+" << std::hex << code;
        } catch (const InputError& e) {
            ADD_FAILURE() << "U+" << std::hex << code << ": the written YAML does not read back: " << e.what();
        }
    }
}

}  // namespace
}  // namespace whitted
