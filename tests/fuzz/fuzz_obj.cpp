// SPDX-License-Identifier: MIT
// Fuzzes the OBJ/MTL loader. The input is an OBJ file; if it
// contains a line "#MTL", what follows is written as fuzz.mtl beside it (reach it with
// `mtllib fuzz.mtl`). The loaded mesh must keep the invariants validate.cpp relies on, and
// reading the file as three runs of lines at once must give the same mesh or the same error.

#include "fuzz_support.h"
#include "scene/mesh_file.h"

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
    const std::string path = (dir / "fuzz.obj").string();
    std::string error_in_runs;
    MeshData in_runs;
    try {
        in_runs = load_obj_mesh(path, {"scene.yaml", 1, 1}, 3);
    } catch (const InputError& e) {
        error_in_runs = e.what();
    }
    try {
        const MeshData mesh = load_obj_mesh(path, {"scene.yaml", 1, 1}, 1);
        if (!error_in_runs.empty() || in_runs.positions != mesh.positions || in_runs.normals != mesh.normals ||
            in_runs.indices != mesh.indices || in_runs.triangle_material != mesh.triangle_material)
            __builtin_trap();
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
    } catch (const InputError& e) {
        if (error_in_runs != e.what()) __builtin_trap();
    }
    return 0;
}
