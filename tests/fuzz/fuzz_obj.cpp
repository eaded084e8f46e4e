// SPDX-License-Identifier: MIT
// Fuzzes the OBJ/MTL loader (tinyobjloader plus our checks). The input is an OBJ file; if it
// contains a line "#MTL", what follows is written as fuzz.mtl beside it (reach it with
// `mtllib fuzz.mtl`). The loaded mesh must keep the invariants validate.cpp relies on.

#include "fuzz_support.h"
#include "whitted/scene/mesh_file.h"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace whitted;
    const std::string input(reinterpret_cast<const char*>(data), size);
    const std::string separator = "\n#MTL\n";
    const size_t split = input.find(separator);
    const auto& dir = fuzz::scratch_directory();
    fuzz::write_file(dir / "fuzz.obj", input.substr(0, split));
    fuzz::write_file(dir / "fuzz.mtl", split == std::string::npos ? "" : input.substr(split + separator.size()));
    try {
        const MeshData mesh = load_obj_mesh((dir / "fuzz.obj").string(), {"scene.yaml", 1, 1});
        const size_t vertices = mesh.positions.size() / 3;
        if (mesh.positions.size() % 3 != 0 || mesh.indices.empty() || mesh.indices.size() % 3 != 0) __builtin_trap();
        if (!mesh.normals.empty() && mesh.normals.size() != mesh.positions.size()) __builtin_trap();
        if (mesh.triangle_material.size() != mesh.indices.size() / 3) __builtin_trap();
        for (const float value : mesh.positions)
            if (!std::isfinite(value)) __builtin_trap();  // Embree needs finite vertices
        for (const float value : mesh.normals)
            if (!std::isfinite(value)) __builtin_trap();
        for (const uint32_t index : mesh.indices)
            if (index >= vertices) __builtin_trap();
        for (const int32_t material : mesh.triangle_material)
            if (material < -1 || (material >= 0 && size_t(material) >= mesh.materials.size())) __builtin_trap();
    } catch (const InputError&) {
    }
    return 0;
}
