// SPDX-License-Identifier: MIT
// Fuzzes the scene parser and validator: any bytes as a scene file. The only acceptable way
// to refuse an input is InputError (exit 2 in `whitted`); anything else escaping, a crash or
// a sanitizer report is a finding. The one-pass reader `whitted render` uses (load_scene_text)
// must agree: the same scene (counts and materials) or the same message. Rendering is left to
// tests/robustness/mutate_scenes.py.

#include "fuzz_support.h"
#include "scene/description.h"
#include "scene/scene.h"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace whitted;
    const std::string text(reinterpret_cast<const char*>(data), size);
    // In the scratch directory, so relative mesh paths find the fixtures (or nothing).
    const std::string path = (fuzz::scratch_directory() / "scene.yaml").string();
    // What the one-pass reader says: "" for a scene, else the message.
    std::string one_pass_error;
    Scene one_pass;
    try {
        one_pass = load_scene_text(text, path);
    } catch (const InputError& e) {
        one_pass_error = e.what();
        if (one_pass_error.empty()) __builtin_trap();
    }
    try {
        const SceneDescription description = parse_scene_text(text, path);
        const Scene scene = validate_scene(description);
        if (!one_pass_error.empty()) __builtin_trap();  // refused by one reader only
        if (scene.spheres.size() != one_pass.spheres.size() || scene.meshes.size() != one_pass.meshes.size() ||
            scene.objects.size() != one_pass.objects.size() || scene.material_names != one_pass.material_names ||
            scene.instances.size() != one_pass.instances.size())
            __builtin_trap();
        for (size_t i = 0; i < scene.spheres.size(); ++i)
            if (scene.spheres[i].material != one_pass.spheres[i].material) __builtin_trap();
        // The renderer trusts these; a validated scene breaking them is a validator bug.
        if (scene.width < 1 || scene.height < 1 || scene.samples < 1 || scene.max_depth < 1) __builtin_trap();
        for (const TriangleMesh& mesh : scene.meshes) {
            for (const uint32_t index : mesh.indices)
                if (index >= mesh.vertex_count()) __builtin_trap();
            for (const float value : mesh.positions)
                if (!std::isfinite(value)) __builtin_trap();  // Embree needs finite vertices
        }
    } catch (const InputError& e) {
        // A refusal with a location: what every bad scene should get, from both readers alike.
        if (one_pass_error != e.what()) __builtin_trap();
    }
    return 0;
}
