// SPDX-License-Identifier: MIT
// Fuzzes the scene parser and validator: any bytes as a scene file. The only acceptable way
// to refuse an input is InputError (exit 2 in `whitted`); anything else escaping, a crash or
// a sanitizer report is a finding. Rendering is left to tests/robustness/mutate_scenes.py.

#include "fuzz_support.h"
#include "whitted/scene/description.h"
#include "whitted/scene/scene.h"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace whitted;
    const std::string text(reinterpret_cast<const char*>(data), size);
    // In the scratch directory, so relative mesh paths find the fixtures (or nothing).
    const std::string path = (fuzz::scratch_directory() / "scene.yaml").string();
    try {
        const SceneDescription description = parse_scene_text(text, path);
        const Scene scene = validate_scene(description);
        // The renderer trusts these; a validated scene breaking them is a validator bug.
        if (scene.width < 1 || scene.height < 1 || scene.samples < 1 || scene.max_depth < 1) __builtin_trap();
        for (const TriangleMesh& mesh : scene.meshes) {
            for (const uint32_t index : mesh.indices)
                if (index >= mesh.vertex_count()) __builtin_trap();
            for (const float value : mesh.positions)
                if (!std::isfinite(value)) __builtin_trap();  // Embree needs finite vertices
        }
    } catch (const InputError&) {
        // A refusal with a location: what every bad scene should get.
    }
    return 0;
}
