// SPDX-License-Identifier: MIT
// Fuzzes what runs, not only what parses: any bytes as a scene file (in the format scene_format
// tells from the first line, as for a scene on standard input), written to a file
// and read as `whitted render` reads it (load_scene_file), then rendered through
// Embree at a few pixels and a shallow depth. The only acceptable refusal is InputError (exit 2
// in `whitted`), whether the reader or the accelerator raises it; a signal, an Embree assertion,
// a sanitizer report or any other exception is a finding. Embree's instruction set is
// $WHITTED_EMBREE_ISA, as for `whitted render` (sse2 changes the packet width and the BVH's node
// width), the machine's widest when unset; scripts/fuzz and the replay tests run both.

#include "fuzz_support.h"
#include "render/accelerator.h"
#include "render/renderer.h"
#include "scene/description.h"
#include "scene/scene.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace whitted;
    const std::string text(reinterpret_cast<const char*>(data), size);
    // In the scratch directory, so relative mesh paths find the fixtures (or nothing).
    const SceneFormat format = scene_format("", text);  // as `whitted render -` tells them apart
    const char* const name = format == SceneFormat::nff          ? "scene.nff"
                             : format == SceneFormat::course_xml ? "scene.xml"
                                                                 : "scene.yaml";
    const std::string path = (fuzz::scratch_directory() / name).string();
    fuzz::write_file(path, text);
    try {
        Scene scene = load_scene_file(path);
        // A few pixels and a shallow tree: what is fuzzed is every shape's intersection, the
        // BVH over the scene's bounds, shadows, mirrors and refraction, not the resolution.
        scene.width = std::min(scene.width, 3);
        scene.height = std::min(scene.height, 3);
        scene.samples = std::min(scene.samples, 2);
        scene.max_depth = std::min(scene.max_depth, 3);
        const Accelerator accelerator(scene, 1);
        RenderJob options;
        options.threads = 1;
        const RenderedTiles result = render(scene, accelerator, options);
        if (result.image.width != scene.width || result.image.height != scene.height) __builtin_trap();
        // Every radiance the lecture's model gives is a number and not negative: its terms are
        // products and sums of non-negative numbers, clamped by max(0, ·). (Not always finite: a
        // colour of 1e258 overflows the float pixel: no colour is bounded, and `whitted render` warns.)
        for (const float value : result.image.rgb)
            if (!(value >= 0)) __builtin_trap();
    } catch (const InputError& e) {
        if (std::string(e.what()).empty()) __builtin_trap();
    }
    return 0;
}
